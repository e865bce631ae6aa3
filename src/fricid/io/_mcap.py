"""A structural check of MCAP files before a bag library reads them.

The MCAP reader of rosbags reads every record with ``file.read(length)``, the length taken
from the file: a corrupt length field (``2**40``) makes it allocate that many bytes first,
and the read ends in :class:`MemoryError` instead of an error naming the file. Readers never
allocate from a length they have not checked, so :func:`check_mcap` walks the record
structure (opcode, uint64 length, as the MCAP specification lays it out) and checks every
length and offset that a reader allocates from against the file's size, reading nothing
larger than a record header at a time.
"""

from __future__ import annotations

import os
import struct
from pathlib import Path
from typing import BinaryIO

from ..errors import DataError

__all__ = ["MAX_CHUNK_BYTES", "check_mcap"]

MAGIC = b"\x89MCAP0\r\n"

#: Largest uncompressed chunk accepted [bytes]; writers use chunks of a few MiB.
MAX_CHUNK_BYTES = 1 << 30

_FOOTER, _CHUNK, _CHUNK_INDEX = 0x02, 0x06, 0x08


class _Bad(Exception):
    """A structural defect, at a byte offset."""

    def __init__(self, message: str, offset: int) -> None:
        super().__init__(message)
        self.offset = offset


def _unpack(fmt: str, data: bytes, at: int, offset: int) -> tuple[int, ...]:
    if at + struct.calcsize(fmt) > len(data):
        raise _Bad("record too short for its fields", offset)
    return struct.unpack_from(fmt, data, at)


def _read(fh: BinaryIO, n: int, offset: int) -> bytes:
    data = fh.read(n)
    if len(data) != n:
        raise _Bad(f"truncated: expected {n} bytes", offset)
    return data


def _check_chunk(fh: BinaryIO, start: int, length: int) -> None:
    """A Chunk record: its compression name and records must lie inside the record."""
    head = _read(fh, min(length, 32), start)
    uncompressed, name_len = _unpack("<16xQ4xI", head, 0, start)
    if 28 + 4 + name_len + 8 > length:
        raise _Bad("chunk compression name runs past the record", start)
    fh.seek(start + 9 + 32 + name_len)
    compression = _read(fh, name_len, start)
    (size,) = _unpack("<Q", _read(fh, 8, start), 0, start)
    if 32 + name_len + 8 + size > length:
        raise _Bad(f"chunk data of {size} bytes runs past the record ({length} bytes)", start)
    if uncompressed > MAX_CHUNK_BYTES or (compression == b"" and uncompressed != size):
        raise _Bad(f"implausible uncompressed chunk size {uncompressed}", start)


def _check_chunk_index(data: bytes, file_size: int, offset: int) -> None:
    """A ChunkIndex record: the chunk it points to must lie inside the file."""
    chunk_start, chunk_length, map_len = _unpack("<16xQQI", data, 0, offset)
    at = 36 + map_len + 8
    (name_len,) = _unpack("<I", data, at, offset)
    compressed, uncompressed = _unpack("<QQ", data, at + 4 + name_len, offset)
    if chunk_start + chunk_length > file_size or compressed > chunk_length:
        raise _Bad("chunk index points past the end of the file", offset)
    if uncompressed > MAX_CHUNK_BYTES:
        raise _Bad(f"implausible uncompressed chunk size {uncompressed}", offset)


def _walk(fh: BinaryIO, size: int) -> None:
    if _read(fh, 8, 0) != MAGIC:
        return  # not MCAP: the bag library says so in its own words
    pos = 8
    starts = {0}  # 0: no summary section
    while True:
        if pos + 9 > size:
            raise _Bad("truncated: no footer record", pos)
        starts.add(pos)
        op, length = struct.unpack("<BQ", _read(fh, 9, pos))
        if length > size - pos - 9:
            raise _Bad(f"record length {length} runs past the end of the file", pos)
        if op == _CHUNK:
            _check_chunk(fh, pos, length)
        elif op in (_CHUNK_INDEX, _FOOTER):
            data = _read(fh, length, pos)  # bounded by the file size, checked above
            if op == _FOOTER:
                summary, offsets = _unpack("<QQ", data, 0, pos)
                if summary not in starts or offsets not in starts:
                    raise _Bad("footer points outside the file's records", pos)
                return
            _check_chunk_index(data, size, pos)
        pos += 9 + length
        fh.seek(pos)


def check_mcap(path: str | os.PathLike[str]) -> None:
    """Raise :class:`DataError` naming ``path`` if its MCAP structure is corrupt.

    Every record length must fit in the file, a chunk's compressed data in its record, a
    chunk index must point inside the file and an uncompressed chunk size must not exceed
    :data:`MAX_CHUNK_BYTES`. A file without the MCAP magic is left to the bag library.
    """
    path = Path(path)
    size = path.stat().st_size
    try:
        with open(path, "rb") as fh:
            _walk(fh, size)
    except _Bad as bad:
        raise DataError(
            f"unreadable or truncated bag (MCAP record at byte {bad.offset}: {bad}); a "
            "recording that was cut off can often be repaired with `ros2 bag reindex`",
            file=path,
        ) from None
