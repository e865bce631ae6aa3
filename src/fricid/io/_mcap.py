"""A structural and integrity check of MCAP files before a bag library reads them.

The MCAP reader of rosbags reads every record with ``file.read(length)``, the length taken
from the file: a corrupt length field (``2**40``) makes it allocate that many bytes first,
and the read ends in :class:`MemoryError` instead of an error naming the file. Readers never
allocate from a length they have not checked, so :func:`check_mcap` walks the record
structure (opcode, uint64 length, as the MCAP specification lays it out) and checks every
length and offset that a reader allocates from against the file's size, reading nothing
larger than a record header (or a block of :data:`BLOCK` bytes) at a time.

It verifies the checksums the format has, where the writer filled them in (a zero means
"not computed", as in files written by rosbags): each chunk's CRC-32 of its uncompressed
records (written by default by the MCAP library's writer, ``McapWriterOptions``), inflating the
chunk a block at a time so that it cannot inflate past its declared size; the data
section's CRC-32 (Data End record); the summary section's CRC-32 (Footer record). A
mismatch is one error naming the file and the record: the values read would not be the
values recorded.
"""

from __future__ import annotations

import os
import struct
import zlib
from pathlib import Path
from typing import Any, BinaryIO

from ..errors import DataError
from ._files import check_input

__all__ = ["BLOCK", "MAX_CHUNK_BYTES", "check_mcap"]

MAGIC = b"\x89MCAP0\r\n"

#: Largest uncompressed chunk accepted [bytes]; writers use chunks of a few MiB.
MAX_CHUNK_BYTES = 1 << 30

#: Bytes read (and inflated) at a time when verifying a checksum.
BLOCK = 1 << 16

_FOOTER, _CHUNK, _CHUNK_INDEX, _DATA_END = 0x02, 0x06, 0x08, 0x0F


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
    """A Chunk record: its compression name and records must lie inside the record, and its
    records match their CRC-32 when the writer computed one."""
    head = _read(fh, min(length, 32), start)
    uncompressed, crc, name_len = _unpack("<16xQII", head, 0, start)
    if 28 + 4 + name_len + 8 > length:
        raise _Bad("chunk compression name runs past the record", start)
    fh.seek(start + 9 + 32)  # the compression name, after the fixed fields
    compression = _read(fh, name_len, start)
    (size,) = _unpack("<Q", _read(fh, 8, start), 0, start)
    if 32 + name_len + 8 + size > length:
        raise _Bad(f"chunk data of {size} bytes runs past the record ({length} bytes)", start)
    if uncompressed > MAX_CHUNK_BYTES or (compression == b"" and uncompressed != size):
        raise _Bad(f"implausible uncompressed chunk size {uncompressed}", start)
    if crc and compression in (b"", b"zstd", b"lz4"):
        try:
            got = _chunk_crc(fh, size, compression.decode(), uncompressed, start)
        except ImportError:  # no streaming decompressor here: the bag library checks the CRC
            return
        if got != crc:
            raise _Bad(
                f"chunk checksum mismatch (CRC-32 0x{got:08x}, recorded 0x{crc:08x}): its "
                "messages are damaged",
                start,
            )


def _decompressor(compression: str) -> tuple[Any, tuple[type[Exception], ...]]:
    """A streaming decompressor of ``zstd`` or ``lz4`` frames, and the errors it raises."""
    if compression == "zstd":
        try:
            from compression import zstd  # type: ignore[import-not-found]
        except ImportError:
            from backports import zstd  # type: ignore[import-not-found,no-redef]
        return zstd.ZstdDecompressor(), (zstd.ZstdError, ValueError, EOFError)
    import lz4.frame  # type: ignore[import-untyped]

    return lz4.frame.LZ4FrameDecompressor(), (RuntimeError, ValueError, EOFError)


def _chunk_crc(fh: BinaryIO, size: int, compression: str, expected: int, start: int) -> int:
    """CRC-32 of a chunk's records, inflated a block at a time, never past ``expected``."""
    left, crc, produced = size, 0, 0
    if not compression:
        while left:
            data = _read(fh, min(BLOCK, left), start)
            left -= len(data)
            crc = zlib.crc32(data, crc)
        return crc
    (d, errors), data, idle = _decompressor(compression), b"", 0
    while True:
        if d.eof:
            data = d.unused_data
            if not data and not left:
                break
            d = _decompressor(compression)[0]  # the next frame
        elif d.needs_input:
            if not left:
                raise _Bad("chunk data ends inside a compressed frame", start)
            data = _read(fh, min(BLOCK, left), start)
            left -= len(data)
        try:
            out = d.decompress(data, BLOCK)
        except errors as exc:
            raise _Bad(f"corrupt {compression} chunk data ({exc})", start) from None
        idle = 0 if (out or data) else idle + 1
        if idle > 2:
            raise _Bad(f"corrupt {compression} chunk data (no progress)", start)
        data = b""
        produced += len(out)
        if produced > expected:
            raise _Bad(f"chunk inflates past its declared {expected} bytes", start)
        crc = zlib.crc32(out, crc)
    if produced != expected:
        raise _Bad(f"chunk inflates to {produced} bytes, {expected} declared", start)
    return crc


def _range_crc(fh: BinaryIO, start: int, stop: int, offset: int) -> int:
    """CRC-32 of the file's bytes ``[start, stop)``."""
    fh.seek(start)
    crc = 0
    while start < stop:
        data = _read(fh, min(BLOCK, stop - start), offset)
        start += len(data)
        crc = zlib.crc32(data, crc)
    return crc


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
        elif op == _DATA_END:
            (crc,) = _unpack("<I", _read(fh, min(length, 4), pos), 0, pos)
            if crc and _range_crc(fh, 0, pos, pos) != crc:
                raise _Bad("data section checksum mismatch (CRC-32 of its records)", pos)
        elif op in (_CHUNK_INDEX, _FOOTER):
            data = _read(fh, length, pos)  # bounded by the file size, checked above
            if op == _FOOTER:
                summary, offsets, crc = _unpack("<QQI", data, 0, pos)
                if summary not in starts or offsets not in starts:
                    raise _Bad("footer points outside the file's records", pos)
                if crc and _range_crc(fh, summary or pos, pos + 25, pos) != crc:
                    raise _Bad("summary checksum mismatch (CRC-32 of the index records)", pos)
                return
            _check_chunk_index(data, size, pos)
        pos += 9 + length
        fh.seek(pos)


def check_mcap(path: str | os.PathLike[str]) -> None:
    """Raise :class:`DataError` naming ``path`` if its MCAP structure is corrupt.

    Every record length must fit in the file, a chunk's compressed data in its record, a
    chunk index must point inside the file and an uncompressed chunk size must not exceed
    :data:`MAX_CHUNK_BYTES`; a chunk must inflate to its declared size; the CRC-32 of each
    chunk, of the data section and of the summary must match where they were written (not
    zero). A file without the MCAP magic is left to the bag library.
    """
    path = Path(path)
    size = check_input(path, what="MCAP file").st_size
    try:
        with open(path, "rb") as fh:
            _walk(fh, size)
    except _Bad as bad:
        raise DataError(
            f"unreadable or truncated bag (MCAP record at byte {bad.offset}: {bad}); a "
            "recording that was cut off can often be repaired with `ros2 bag reindex`",
            file=path,
        ) from None
