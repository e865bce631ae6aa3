"""A structural check of MATLAB v5/v7 ``.mat`` files before scipy reads them.

:func:`scipy.io.loadmat` allocates from what a file declares: an array of the dimensions in
its header, an object array of as many cells, a buffer of a data element's byte count, and it
inflates a compressed element whole. A file of a few megabytes can so declare gigabytes
(a 3.9 GB array of zeros compresses to 4 MB). :func:`check_v5` walks the file's structure as
the MAT-file format lays it out (a 128-byte header, then data elements: a tag of type and
byte count, ``miMATRIX`` arrays with their flags, dimensions, name and parts, ``miCOMPRESSED``
elements holding one zlib-compressed array) and checks, before anything is allocated:

* every element fits in its container, every array's data holds exactly its dimensions;
* no array declares more than the cap, and all of them together no more than the cap;
* compressed elements inflate, a block at a time (:meth:`zlib.Decompress.decompress` with
  ``max_length``), to no more than the cap in all;
* at most :data:`MAX_ARRAYS` arrays (cells and struct fields included), nested at most
  :data:`MAX_DEPTH` deep.

It reads nothing larger than a few kilobytes at a time and keeps nothing of the data.
"""

from __future__ import annotations

import math
import struct
import zlib
from dataclasses import dataclass, field
from typing import BinaryIO, Protocol

from ._files import size_text

__all__ = ["MAX_ARRAYS", "MAX_DEPTH", "V5Bad", "V5TooBig", "check_v5", "v5_header_problem"]

#: Most arrays in one file, cells and struct fields included.
MAX_ARRAYS = 100_000
#: Deepest nesting of cells, structs and objects.
MAX_DEPTH = 32

_MATRIX, _COMPRESSED = 14, 15
_INT8, _INT32, _UINT32, _UTF8 = 1, 5, 6, 16
#: Bytes per value of each data type (miINT8 ... miUTF32).
_MI_BYTES = {1: 1, 2: 1, 3: 2, 4: 2, 5: 4, 6: 4, 7: 4, 9: 8, 12: 8, 13: 8, 16: 1, 17: 2, 18: 4}
_NUMERIC_MI = {1, 2, 3, 4, 5, 6, 7, 9, 12, 13}
_CHAR_MI = {1, 2, 4, 16, 17, 18}
#: Bytes per value of each numeric array class (mxDOUBLE ... mxUINT64).
_CLASS_BYTES = {6: 8, 7: 4, 8: 1, 9: 1, 10: 2, 11: 2, 12: 4, 13: 4, 14: 8, 15: 8}
_CLASS_NAMES = {
    1: "cell",
    2: "struct",
    3: "object",
    4: "char",
    5: "sparse",
    6: "double",
    7: "single",
    8: "int8",
    9: "uint8",
    10: "int16",
    11: "uint16",
    12: "int32",
    13: "uint32",
    14: "int64",
    15: "uint64",
    16: "function handle",
    17: "opaque object",
}
_SMALL_READ = 1 << 20  # the largest element read into memory (names, field names)
_BLOCK = 1 << 16  # compressed bytes fed to zlib at a time


class V5Bad(Exception):
    """A structural defect of a v5 file, in a variable (``where``) when known."""

    def __init__(self, message: str, where: str | None = None) -> None:
        super().__init__(message)
        self.where = where


class V5TooBig(V5Bad):
    """An array, or the file's data, larger than the cap."""


class _Source(Protocol):
    def read(self, n: int) -> bytes: ...
    def skip(self, n: int) -> None: ...


@dataclass
class _Budget:
    """What the walk has met so far, against the caps."""

    cap: int
    inflated: int = 0
    declared: int = 0
    arrays: int = 0
    names: list[str] = field(default_factory=list)
    kinds: dict[str, str] = field(default_factory=dict)
    current: str | None = None  # the variable being walked, for messages

    def inflate(self, n: int) -> None:
        self.inflated += n
        if self.inflated > self.cap:
            raise V5TooBig(
                f"data inflating to more than {size_text(self.cap)} (a decompression bomb?)",
                self.current,
            )

    def declare(self, n: int, what: str, where: str | None) -> None:
        if n > self.cap:
            raise V5TooBig(
                f"declares {what} ({size_text(n)}), more than {size_text(self.cap)}", where
            )
        self.declared += n
        if self.declared > self.cap:
            raise V5TooBig(f"the file's arrays total more than {size_text(self.cap)}", where)

    def count(self, n: int, where: str | None) -> None:
        self.arrays += n
        if self.arrays > MAX_ARRAYS:
            raise V5Bad(f"more than {MAX_ARRAYS} arrays (cells and struct fields)", where)


class _Region:
    """Uncompressed bytes of the file, read in order."""

    def __init__(self, fh: BinaryIO, start: int, end: int) -> None:
        self.fh, self.pos, self.end = fh, start, end
        fh.seek(start)

    def read(self, n: int) -> bytes:
        if self.pos + n > self.end:
            raise V5Bad("truncated: an element runs past the end of the file")
        data = self.fh.read(n)
        if len(data) != n:
            raise V5Bad("truncated: the file ends inside an element")
        self.pos += n
        return data

    def skip(self, n: int) -> None:
        if self.pos + n > self.end:
            raise V5Bad("truncated: an element runs past the end of the file")
        self.pos += n
        self.fh.seek(self.pos)


class _Inflated:
    """The inflated bytes of an ``miCOMPRESSED`` element, inflated a block at a time."""

    def __init__(self, fh: BinaryIO, start: int, length: int, budget: _Budget) -> None:
        self.fh, self.left, self.budget = fh, length, budget
        self.d = zlib.decompressobj()
        self.tail = b""
        self.buf = bytearray()
        fh.seek(start)

    def _more(self, want: int) -> int:
        """Inflate up to ``want`` more bytes into the buffer; 0 at the end of the stream."""
        while True:
            if self.tail:
                data, self.tail = self.tail, b""
            elif self.left > 0 and not self.d.eof:
                data = self.fh.read(min(_BLOCK, self.left))
                if not data:
                    raise V5Bad("truncated: the file ends inside a compressed element")
                self.left -= len(data)
            else:
                return 0
            try:
                out = self.d.decompress(data, want)
            except zlib.error as exc:
                raise V5Bad(f"corrupt compressed data ({exc})", self.budget.current) from None
            self.tail = self.d.unconsumed_tail
            if out:
                self.budget.inflate(len(out))
                self.buf += out
                return len(out)

    def read(self, n: int) -> bytes:
        while len(self.buf) < n:
            if not self._more(max(n - len(self.buf), _BLOCK)):
                raise V5Bad("a compressed element ends inside an array", self.budget.current)
        data = bytes(self.buf[:n])
        del self.buf[:n]
        return data

    def skip(self, n: int) -> None:
        while n > 0:
            if not self.buf and not self._more(min(n, 1 << 20)):
                raise V5Bad("a compressed element ends inside an array", self.budget.current)
            k = min(n, len(self.buf))
            del self.buf[:k]
            n -= k

    def finish(self) -> None:
        """Inflate what is left (bounded by the budget): it must be nothing, and the end."""
        extra = len(self.buf)
        while self._more(1 << 20):
            extra += len(self.buf)
            self.buf.clear()
        if extra:
            where = self.budget.current
            raise V5Bad(f"{extra} bytes after the array in its compressed element", where)
        if not self.d.eof:
            raise V5Bad("truncated compressed element (no end of stream)", self.budget.current)


@dataclass
class _Walk:
    """One walk of a file: its byte order and budget."""

    order: str
    budget: _Budget

    def tag(
        self, src: _Source, limit: int, where: str | None
    ) -> tuple[int, int, bytes | None, int]:
        """An element's tag: ``(type, bytes, inline data or None, bytes used with padding)``."""
        if limit < 8:
            raise V5Bad(f"an element's tag runs past its container ({limit} bytes left)", where)
        first, second = struct.unpack(self.order + "II", src.read(8))
        if first >> 16:  # the small data element format: up to 4 bytes inside the tag
            mdtype, nbytes = first & 0xFFFF, first >> 16
            if nbytes > 4:
                raise V5Bad(f"a small data element of {nbytes} bytes (at most 4)", where)
            inline = struct.pack(self.order + "I", second)[:nbytes]
            return mdtype, nbytes, inline, 8
        padded = second + (-second % 8)
        if padded > limit - 8:
            raise V5Bad(
                f"an element of {second} bytes runs past its container ({limit - 8} bytes left)",
                where,
            )
        return first, second, None, 8 + padded

    def small(
        self, src: _Source, limit: int, where: str | None, types: set[int], what: str
    ) -> tuple[int, bytes, int]:
        """An element read whole (flags, dimensions, names): ``(type, data, bytes used)``."""
        mdtype, nbytes, inline, used = self.tag(src, limit, where)
        if mdtype not in types:
            raise V5Bad(f"{what} of data type {mdtype}", where)
        if inline is not None:
            return mdtype, inline, used
        if nbytes > _SMALL_READ:
            raise V5Bad(f"{what} of {nbytes} bytes", where)
        data = src.read(nbytes)
        src.skip(used - 8 - nbytes)
        return mdtype, data, used

    def skip(self, src: _Source, limit: int, where: str | None) -> tuple[int, int, int]:
        """An element skipped: ``(type, bytes, bytes used)``."""
        mdtype, nbytes, inline, used = self.tag(src, limit, where)
        if inline is None:
            src.skip(used - 8)
        return mdtype, nbytes, used

    def values(
        self, src: _Source, limit: int, where: str | None, count: int, types: set[int], what: str
    ) -> int:
        """A data element of ``count`` values skipped, its type and size checked; bytes used."""
        mdtype, nbytes, used = self.skip(src, limit, where)
        if mdtype not in types:
            raise V5Bad(f"{what} of data type {mdtype}", where)
        if nbytes != count * _MI_BYTES[mdtype]:
            raise V5Bad(
                f"{what} of {nbytes} bytes, for {count} values of {_MI_BYTES[mdtype]} bytes",
                where,
            )
        return used

    def matrix(self, src: _Source, nbytes: int, where: str | None, depth: int, top: bool) -> str:
        """Walk one ``miMATRIX`` of ``nbytes`` (after its tag); return its name."""
        self.budget.count(1, where)
        if nbytes == 0:
            return ""  # an empty matrix
        if depth > MAX_DEPTH:
            raise V5Bad(f"arrays nested more than {MAX_DEPTH} deep", where)
        left = nbytes
        _, flags_data, used = self.small(src, left, where, {_UINT32}, "array flags")
        left -= used
        if len(flags_data) != 8:
            raise V5Bad(f"array flags of {len(flags_data)} bytes (8 expected)", where)
        flags, _nzmax = struct.unpack(self.order + "II", flags_data)
        cls, is_complex = flags & 0xFF, bool(flags >> 11 & 1)
        kind = _CLASS_NAMES.get(cls, f"class {cls}")
        if flags >> 9 & 1:
            kind = "logical" if cls in _CLASS_BYTES else f"logical {kind}"
        if is_complex:
            kind = f"complex {kind}"
        if cls == 17:  # opaque: name, type system, class name, then one array
            name = ""
            for k in range(3):
                _, text, used = self.small(src, left, where, {_INT8, _UTF8}, "an object's name")
                left -= used
                name = text.decode("latin-1") if k == 0 else name
            where = self.named(name, where, top)
            self.budget.kinds.setdefault(where or "", kind)
            left -= self.child(src, left, where, depth)
            self.rest(src, left, where, top)
            return name
        _, dims_data, used = self.small(src, left, where, {_INT32, _UINT32}, "dimensions")
        left -= used
        if len(dims_data) % 4 or not 1 <= len(dims_data) // 4 <= 32:
            raise V5Bad(f"dimensions of {len(dims_data)} bytes", where)
        dims = struct.unpack(f"{self.order}{len(dims_data) // 4}i", dims_data)
        if min(dims) < 0:
            raise V5Bad(f"negative dimensions {dims}", where)
        _, name_data, used = self.small(src, left, where, {_INT8, _UTF8}, "a name")
        left -= used
        name = name_data.split(b"\0")[0].decode("latin-1")
        where = self.named(name, where, top)
        self.budget.kinds.setdefault(where or "", kind)
        n = math.prod(dims)
        shape = "x".join(str(d) for d in dims)
        if cls in _CLASS_BYTES:
            parts = 2 if is_complex else 1
            self.budget.declare(n * _CLASS_BYTES[cls] * parts, f"{shape} {kind} values", where)
            for part in ("real part", "imaginary part")[:parts]:
                left -= self.values(src, left, where, n, _NUMERIC_MI, f"a {part}")
        elif cls == 4:  # char: one data element, held as 4-byte characters
            self.budget.declare(n * 4, f"{shape} characters", where)
            mdtype, _, used = self.skip(src, left, where)
            if mdtype not in _CHAR_MI:
                raise V5Bad(f"characters of data type {mdtype}", where)
            left -= used
        elif cls == 5:  # sparse: row indices, column pointers, values (and imaginary parts)
            if len(dims) != 2:
                raise V5Bad(f"a sparse matrix of {len(dims)} dimensions", where)
            self.budget.declare(8 * (dims[1] + 1), f"a sparse {shape} matrix", where)
            for _ in range(4 if is_complex else 3):
                _, nb, used = self.skip(src, left, where)
                self.budget.declare(2 * nb, "sparse data", where)
                left -= used
        elif cls == 1:  # cell: one array per cell
            self.budget.declare(n * 8, f"{shape} cells", where)
            if n * 8 > left:
                raise V5Bad(f"{shape} cells in {left} bytes", where)
            for i in range(n):
                left -= self.child(src, left, f"{where}{{{i + 1}}}", depth)
        elif cls in (2, 3):  # struct, object: fields of every element
            if cls == 3:
                _, _, used = self.small(src, left, where, {_INT8, _UTF8}, "a class name")
                left -= used
            _, len_data, used = self.small(src, left, where, {_INT32, _UINT32}, "a name length")
            left -= used
            (length,) = struct.unpack(self.order + "i", len_data[:4].ljust(4, b"\0"))
            if len(len_data) != 4 or length <= 0:
                raise V5Bad(f"field names of length {length}", where)
            _, names_data, used = self.small(src, left, where, {_INT8, _UTF8}, "field names")
            left -= used
            fields = [
                names_data[i : i + length].split(b"\0")[0].decode("latin-1")
                for i in range(0, len(names_data) - length + 1, length)
            ]
            self.budget.declare(n * max(len(fields), 1) * 8, f"a {shape} struct", where)
            self.budget.count(n, where)
            if n * len(fields) * 8 > left:
                raise V5Bad(f"a {shape} struct of {len(fields)} fields in {left} bytes", where)
            for i in range(n):
                at = where if n == 1 else f"{where}({i + 1})"
                for name_ in fields:
                    left -= self.child(src, left, f"{at}.{name_}", depth)
        elif cls == 16:  # function handle: one array
            left -= self.child(src, left, where, depth)
        else:
            raise V5Bad(f"unknown array class {cls}", where)
        self.rest(src, left, where, top)
        return name

    def named(self, name: str, where: str | None, top: bool) -> str | None:
        """Where the walk is: a top-level array by its name (in the budget, for messages)."""
        if not top:
            return where
        self.budget.current = name
        return name

    def child(self, src: _Source, limit: int, where: str | None, depth: int) -> int:
        """A nested ``miMATRIX`` walked; bytes used."""
        mdtype, nbytes, inline, used = self.tag(src, limit, where)
        if mdtype != _MATRIX or inline is not None:
            raise V5Bad(f"an element of data type {mdtype} where an array belongs", where)
        self.matrix(src, nbytes, where, depth + 1, top=False)
        src.skip(used - 8 - nbytes)
        return used

    def rest(self, src: _Source, left: int, where: str | None, top: bool) -> None:
        """Bytes left in an array after its parts: skipped at the top level (as readers do),
        refused inside (a reader would read them as the next array)."""
        if left and not top:
            raise V5Bad(f"{left} stray bytes inside an array", where)
        src.skip(left)


def v5_header_problem(head: bytes) -> str | None:
    """Why the first 128 bytes of a file are not a MATLAB v5/v7 header, or None."""
    if not head:
        return "an empty file, not a MATLAB file"
    if len(head) < 128:
        return f"{len(head)} bytes, too short for a MATLAB file (its header has 128)"
    if head[126:128] not in (b"IM", b"MI") or 0 in head[:4]:
        return (
            "not a MATLAB file: no MATLAB v5/v7 header (a text file, a MATLAB v4 file or "
            "another format; save it with save -v7 or -v7.3)"
        )
    order = "<" if head[126:128] == b"IM" else ">"
    (version,) = struct.unpack(order + "H", head[124:126])
    if version != 0x0100:
        return f"unsupported MATLAB file version 0x{version:04x}"
    return None


def check_v5(fh: BinaryIO, size: int, cap: int) -> tuple[list[str], dict[str, str]]:
    """Walk a v5/v7 MAT-file (see the module notes).

    Parameters
    ----------
    fh : binary file
        The file, open for reading.
    size : int
        Its size [bytes].
    cap : int
        The largest array, inflated data and declared data in all [bytes].

    Returns
    -------
    names : list of str
        The names of its variables, in order.
    kinds : dict of str to str
        Each array's MATLAB class by its place (``a``, ``a.b`` for a struct's field,
        ``a{2}`` for a cell): ``double``, ``int16``, ``logical``, ``complex double``,
        ``char``, ``cell``, ``struct``, ``sparse``, ``object``...

    Raises
    ------
    V5Bad
        A structural defect (:class:`V5TooBig`: over a cap), naming the variable when known.
    """
    fh.seek(0)
    head = fh.read(128)
    problem = v5_header_problem(head)
    if problem:
        raise V5Bad(problem)
    walk = _Walk("<" if head[126:128] == b"IM" else ">", _Budget(cap))
    pos = 128
    while pos < size:
        try:
            name, used = _element(walk, fh, pos, size)
        except V5Bad as bad:
            if bad.where is None:
                raise V5Bad(f"{bad} (the element at byte {pos})") from None
            raise
        if name in walk.budget.names:
            raise V5Bad("a second variable of the same name", name)
        walk.budget.names.append(name)
        pos += used
    return walk.budget.names, walk.budget.kinds


def _at(fh: BinaryIO, pos: int, n: int) -> bytes:
    fh.seek(pos)
    return fh.read(n)


def _element(walk: _Walk, fh: BinaryIO, pos: int, size: int) -> tuple[str, int]:
    """Walk the top-level element at byte ``pos``: its variable's name, its bytes."""
    if size - pos < 8:
        raise V5Bad(f"truncated: {size - pos} stray bytes at the end of the file")
    mdtype, nbytes = struct.unpack(walk.order + "II", _at(fh, pos, 8))
    if nbytes == 0 or nbytes > size - pos - 8:
        raise V5Bad(f"truncated: an element of {nbytes} bytes where {size - pos - 8} remain")
    walk.budget.current = None
    if mdtype == _COMPRESSED:
        src = _Inflated(fh, pos + 8, nbytes, walk.budget)
        inner, inner_bytes = struct.unpack(walk.order + "II", src.read(8))
        if inner != _MATRIX or inner_bytes == 0:
            raise V5Bad(f"a compressed element holding data type {inner}, not an array")
        name = walk.matrix(src, inner_bytes, None, 0, top=True)
        src.finish()
        return name, 8 + nbytes
    if mdtype == _MATRIX:
        walk.budget.inflate(nbytes)  # uncompressed data counts the same
        region = _Region(fh, pos + 8, pos + 8 + nbytes)
        return walk.matrix(region, nbytes, None, 0, top=True), 8 + nbytes
    raise V5Bad(f"an element of data type {mdtype}, not an array")
