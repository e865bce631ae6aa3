"""numba's compilers with the on-disk cache where a cache directory is writable, in memory
where none is.

Every compiled kernel of fricid is decorated through :func:`njit` or :func:`cfunc` here, with
numba's own signature and options. With ``cache=True`` numba looks for a cache directory when
the function is decorated (``NUMBA_CACHE_DIR``, the ``__pycache__`` beside the module, the
user's cache folder) and raises ``RuntimeError: cannot cache function ...: no locator
available`` when none is writable: a read-only install with an unwritable home directory. The
function is then compiled without the cache (in memory, again in each process: slower to
start, the same code), and one debug line on the ``fricid`` logger says so.

Imports numba: import this module only where a kernel is compiled.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from typing import Any

import numba

__all__ = ["cfunc", "njit"]

_log = logging.getLogger("fricid")


def _compile(make: Callable[..., Any], func: Callable, options: dict[str, Any]) -> Any:
    """``make(**options)(func)``, again with ``cache=False`` when numba finds no cache
    directory for it."""
    try:
        return make(**options)(func)
    except RuntimeError as exc:
        if not options.get("cache") or "cannot cache" not in str(exc):
            raise
    _log.debug("numba: no writable cache directory for %s; compiled in memory", func.__name__)
    return make(**{**options, "cache": False})(func)


def njit(func: Callable | None = None, /, **options: Any) -> Any:
    """:func:`numba.njit` (used bare or with options); ``cache=True`` falls back to an
    in-memory compile when no cache directory is writable (module notes)."""

    def decorate(f: Callable) -> Any:
        return _compile(numba.njit, f, options)

    return decorate if func is None else decorate(func)


def cfunc(sig: Any, **options: Any) -> Callable[[Callable], Any]:
    """:func:`numba.cfunc` for the signature ``sig``, with :func:`njit`'s cache fallback."""

    def decorate(f: Callable) -> Any:
        return _compile(lambda **o: numba.cfunc(sig, **o), f, options)

    return decorate
