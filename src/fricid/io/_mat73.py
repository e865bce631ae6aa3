"""MATLAB v7.3 (HDF5) files seen through ``h5py``, checked before anything is read.

An HDF5 file can point elsewhere (an external link to another file, a dataset whose data
lives in other files, a link that leads nowhere) and declare datasets of any size in a few
kilobytes (a chunked, compressed dataset of 74.5 GiB that was never written). The helpers
here refuse links and storage outside the file, name a variable's MATLAB class from its
attributes and type (``MATLAB_class``, ``MATLAB_sparse``, ``MATLAB_empty``, compound complex
types, object references of cells) and check a dataset's declared size, and its chunks',
against a cap before reading it. Every failure is one :class:`~fricid.errors.DataError`
naming the file and the variable.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import DataError
from ._files import size_text

__all__ = ["h5_attribute", "h5_child", "h5_kind", "h5_values"]

#: What h5py raises on a damaged file or object.
_ERRORS = (OSError, KeyError, RuntimeError, ValueError, TypeError)


def _one_line(exc: BaseException) -> str:
    return " ".join(str(exc).split())[:300] or type(exc).__name__


def h5_child(node: Any, part: str, name: str, path: Path) -> Any:
    """``node[part]``: a v7.3 link to another file, or one that leads nowhere, refused."""
    import h5py

    try:
        link = node.get(part, getlink=True)
    except _ERRORS as exc:
        raise DataError(f"cannot open '{name}': {_one_line(exc)}", file=path, column=name) from None
    if isinstance(link, h5py.ExternalLink):
        raise DataError(
            f"'{name}' is a link to another file ('{link.filename}'); fricid reads only the "
            "file given",
            file=path,
            column=name,
        )
    try:
        return node[part]
    except _ERRORS as exc:
        what = "a link that leads nowhere" if isinstance(link, h5py.SoftLink) else "unreadable"
        raise DataError(f"'{name}' is {what} ({_one_line(exc)})", file=path, column=name) from None


def h5_attribute(node: Any, key: str) -> str | None:
    """A MATLAB attribute of a v7.3 object as text (``MATLAB_class``), or None."""
    try:
        value = node.attrs.get(key)
    except _ERRORS:
        return None
    if value is None:
        return None
    if isinstance(value, bytes):
        return value.decode("latin-1")
    if isinstance(value, np.ndarray) and value.size == 1:
        value = value.reshape(-1)[0]
    return value.decode("latin-1") if isinstance(value, bytes) else str(value)


def h5_kind(node: Any) -> str:
    """The MATLAB class of a v7.3 group or dataset: ``struct``, ``double``, ``logical``,
    ``complex double``, ``cell``, ``sparse``, ``char``..., from its attributes and type."""
    import h5py

    if isinstance(node, h5py.Group):
        if h5_attribute(node, "MATLAB_sparse") is not None:
            return "sparse"
        cls = h5_attribute(node, "MATLAB_class")
        return "struct" if cls in (None, "struct") else cls
    if not isinstance(node, h5py.Dataset):
        return f"HDF5 {type(node).__name__} (no data)"
    cls = h5_attribute(node, "MATLAB_class")
    try:
        dtype = node.dtype
    except _ERRORS:
        return "unreadable dataset"
    if h5py.check_dtype(ref=dtype) is not None:
        return "cell" if cls in (None, "cell") else cls
    if dtype.kind == "c" or (dtype.names and {"real", "imag"} <= set(dtype.names)):
        return f"complex {cls or 'double'}"
    if cls == "logical" or dtype.kind == "b" or h5py.check_dtype(enum=dtype) is not None:
        return "logical"
    if cls is not None:
        return cls
    return "double" if dtype.kind in "iuf" else f"HDF5 type {dtype}"


def h5_values(node: Any, name: str, path: Path, cap: int) -> np.ndarray:
    """The values of a v7.3 dataset as float64 (transposed: MATLAB stores column-major), its
    storage and declared size checked against ``cap`` [bytes] before anything is read."""
    try:
        external, virtual = node.external, node.is_virtual
        shape, chunks, itemsize = node.shape, node.chunks, node.dtype.itemsize
    except _ERRORS as exc:
        raise DataError(f"cannot read '{name}': {_one_line(exc)}", file=path, column=name) from None
    if external or virtual:
        raise DataError(
            f"'{name}' keeps its data in other files (HDF5 "
            + ("external storage" if external else "virtual dataset")
            + "); fricid reads only the file given",
            file=path,
            column=name,
        )
    if h5_attribute(node, "MATLAB_empty") not in (None, "0", "False"):
        raise DataError(f"'{name}' is empty", file=path, column=name)
    if shape is None:
        raise DataError(f"'{name}' holds no array", file=path, column=name)
    size = math.prod(shape) * max(itemsize, 8)
    chunk = math.prod(chunks) * itemsize if chunks else 0
    if max(size, chunk) > cap:
        what = f"{'x'.join(map(str, shape))} values" if size >= chunk else "chunks"
        raise DataError(
            f"variable '{name}' declares {what} of {size_text(max(size, chunk))}, more than "
            f"the {size_text(cap)} fricid reads from a MATLAB file",
            file=path,
            column=name,
        )
    try:
        return np.asarray(node[()], dtype=float).T  # stored transposed (column-major)
    except _ERRORS as exc:
        raise DataError(f"cannot read '{name}': {_one_line(exc)}", file=path, column=name) from None
