"""One BLAS thread while a least-squares computation runs.

The least-squares paths (scipy's ``least_squares``, variable projection, profile intervals, the
validation and selection loops over them) do many small SVDs and QR factorisations. On matrices
of tens to hundreds of rows OpenBLAS's thread pool only costs: its threads spin, wake and
synchronise for each call, and on a loaded or shared machine (a fleet of processes, a CI runner)
they oversubscribe the cores. :func:`one_blas_thread` limits BLAS to one thread for the time a
computation runs and restores the previous limits afterwards.

Nested uses share one limit: the outermost use on a thread sets it and restores it on leaving,
so wrapping every entry point (an outer ``fit`` calling ``minimize`` calling the solver) costs
one limit, not one per level. Each thread's outermost use sets the limit and restores it on that
thread, as ``threadpool_limits`` does on the other paths (OpenBLAS does not reliably take a
restore made from a thread other than the one that set the limit).

threadpoolctl is imported, and its controller built, on first use only (not at ``import
fricid``), after scipy's linear algebra is loaded, so it sees both numpy's and scipy's OpenBLAS.
"""

from __future__ import annotations

import functools
import threading
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any, TypeVar

__all__ = ["blas_threads", "one_blas_thread", "single_blas_thread"]

F = TypeVar("F", bound=Callable[..., Any])

_lock = threading.Lock()
_local = threading.local()  # depth and limiter of this thread's outermost use
_controller: Any = None


def _get_controller() -> Any:
    """The process's threadpoolctl controller, built once (after scipy.linalg is loaded)."""
    global _controller
    with _lock:
        if _controller is None:
            import scipy.linalg  # noqa: F401  (loads scipy's own OpenBLAS before the scan)
            from threadpoolctl import ThreadpoolController

            _controller = ThreadpoolController()
    return _controller


@contextmanager
def one_blas_thread() -> Iterator[None]:
    """Limit BLAS to one thread inside the ``with`` block (re-entrant).

    Examples
    --------
    >>> from fricid.optim import one_blas_thread, blas_threads
    >>> with one_blas_thread():
    ...     blas_threads() in (None, 1)
    True
    """
    depth = getattr(_local, "depth", 0)
    if depth == 0:
        _local.limiter = _get_controller().limit(limits=1, user_api="blas")
    _local.depth = depth + 1
    try:
        yield
    finally:
        _local.depth = depth
        if depth == 0:
            limiter, _local.limiter = _local.limiter, None
            limiter.restore_original_limits()


def single_blas_thread(func: F) -> F:
    """Decorator: run ``func`` inside :func:`one_blas_thread`."""

    @functools.wraps(func)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        with one_blas_thread():
            return func(*args, **kwargs)

    return wrapper  # type: ignore[return-value]


def blas_threads() -> int | None:
    """The largest number of threads any loaded BLAS may use now (None if none is found)."""
    from threadpoolctl import threadpool_info

    counts = [i["num_threads"] for i in threadpool_info() if i.get("user_api") == "blas"]
    return max(counts) if counts else None
