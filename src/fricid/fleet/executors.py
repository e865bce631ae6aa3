"""Where the joints run: in this process, in a local process pool, or on a Dask cluster.

Every executor has one method, ``run(fn, items)``, yielding ``(index, result)`` as results
arrive, in any order; ``result`` is the exception instead when the executor itself could not
run an item (a worker process that died more often than the retries allow). The results do
not depend on the executor: each item carries its own seed, and :func:`.job.run_job` pins
BLAS to one thread.

- :class:`SerialExecutor`: one item after the other, in this process.
- :class:`ProcessExecutor`: a local process pool (``spawn``); a worker that dies (killed, out
  of memory) breaks the pool, which is rebuilt and its unfinished items resubmitted, each at
  most ``retries`` more times. The workers die with the driver: an interrupted ``run``
  (Ctrl-C, or SIGTERM, which the CLI turns into an exception) terminates them before it
  returns, and a driver killed outright (SIGKILL) takes them along (:func:`_worker_init`).
- :class:`DaskExecutor` (:mod:`._dask`): a Dask ``LocalCluster`` on loopback, or an existing
  scheduler; Dask reschedules the tasks of a worker that dies.
"""

from __future__ import annotations

import contextlib
import logging
import multiprocessing
import os
import signal
import sys
import threading
import time
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from typing import Any, Protocol, TypeVar

from ..errors import ConfigError

__all__ = ["Executor", "ProcessExecutor", "SerialExecutor", "make_executor"]

T = TypeVar("T")

logger = logging.getLogger(__name__)

#: ``prctl(2)`` option: the signal a process gets when its parent dies (linux/prctl.h).
_PR_SET_PDEATHSIG = 1

#: How often a worker's watchdog checks that its driver is alive [s].
_WATCHDOG_PERIOD = 0.5

#: How long a worker may take to exit after SIGTERM before it gets SIGKILL [s].
_TERMINATE_GRACE = 2.0


def _die_with_parent_linux() -> bool:
    """Ask Linux to SIGKILL this process when its parent dies; True if it took."""
    if not sys.platform.startswith("linux"):
        return False
    try:
        import ctypes

        libc = ctypes.CDLL(None, use_errno=True)
        return libc.prctl(_PR_SET_PDEATHSIG, int(signal.SIGKILL), 0, 0, 0) == 0
    except (OSError, AttributeError):  # pragma: no cover - no prctl in this libc
        return False


def _watchdog(parent: int) -> None:
    while os.getppid() == parent:
        time.sleep(_WATCHDOG_PERIOD)
    os._exit(1)  # the driver is gone: nobody reads our results


def _worker_init(parent: int, pdeathsig: bool) -> None:
    """Initializer of every pool worker: it dies with the driver ``parent``.

    * SIGINT is ignored: Ctrl-C in a terminal reaches the whole process group, and the
      driver alone decides (it terminates the workers and reports in one line). The driver
      started this worker with SIGINT blocked, so a Ctrl-C during its start-up is dropped
      here too, instead of printing a traceback.
    * ``pdeathsig``: on Linux, ``prctl(PR_SET_PDEATHSIG, SIGKILL)`` (only when the driver's
      main thread spawned the worker: the signal follows the spawning thread, not the
      process).
    * A watchdog thread exits the worker once its parent is gone (every platform; a worker
      busy in compiled code that holds the GIL is covered by the prctl alone).
    """
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    if hasattr(signal, "pthread_sigmask"):
        signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})
    if pdeathsig:
        _die_with_parent_linux()
    if os.getppid() != parent:  # the driver died before the prctl took
        os._exit(1)
    threading.Thread(target=_watchdog, args=(parent,), name="fricid-watchdog", daemon=True).start()


@contextlib.contextmanager
def _sigint_blocked() -> Iterator[None]:
    """Block SIGINT in this thread while workers are spawned (they inherit the mask); a
    Ctrl-C that arrives meanwhile is delivered when the block ends."""
    if not hasattr(signal, "pthread_sigmask"):  # pragma: no cover - not POSIX
        yield
        return
    old = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, old)


def _tear_down(pool: ProcessPoolExecutor) -> None:
    """Stop ``pool`` now: cancel what has not started, terminate the workers (SIGTERM,
    then SIGKILL after a grace period) and wait for them, so none outlives the driver."""
    # concurrent.futures has no public way to stop running workers before Python 3.14
    # (``terminate_workers``); its ``_processes`` map {pid: Process} is stable since 3.2.
    processes = list((getattr(pool, "_processes", None) or {}).values())
    pool.shutdown(wait=False, cancel_futures=True)
    for proc in processes:
        with contextlib.suppress(Exception):
            proc.terminate()
    deadline = time.monotonic() + _TERMINATE_GRACE
    for proc in processes:
        with contextlib.suppress(Exception):
            proc.join(max(0.0, deadline - time.monotonic()))
            if proc.is_alive():
                proc.kill()
                proc.join(1.0)
    # With its workers gone, the pool's manager thread winds down; wait for it, or it races
    # the interpreter's exit hook (``OSError: Bad file descriptor`` printed at exit).
    manager = getattr(pool, "_executor_manager_thread", None)
    if manager is not None and manager is not threading.current_thread():
        manager.join(_TERMINATE_GRACE)


class Executor(Protocol):
    """Runs ``fn`` over ``items``; see the module docstring."""

    name: str
    workers: int

    def run(
        self, fn: Callable[[Any], T], items: Sequence[Any]
    ) -> Iterator[tuple[int, T | BaseException]]: ...

    def close(self) -> None: ...


class SerialExecutor:
    """Runs the items one after the other in this process."""

    name = "serial"
    workers = 1

    def run(
        self, fn: Callable[[Any], T], items: Sequence[Any]
    ) -> Iterator[tuple[int, T | BaseException]]:
        for i, item in enumerate(items):
            yield i, fn(item)

    def close(self) -> None:
        """Nothing to release."""

    def __enter__(self) -> SerialExecutor:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


class ProcessExecutor:
    """A local pool of ``workers`` processes (default: every core).

    Parameters
    ----------
    workers : number of processes.
    retries : how many more times an item is submitted after the pool broke under it.

    Notes
    -----
    When a worker process dies, ``concurrent.futures`` fails every unfinished item of the
    pool without saying which one was running there; all are resubmitted to a new pool and
    each is charged one attempt. A joint that kills its worker every time is reported after
    ``retries`` resubmissions, and may use up the attempts of joints that were unfinished at
    the same moments; Dask (:class:`DaskExecutor`) tracks failures per task instead.
    """

    name = "processes"

    def __init__(self, workers: int | None = None, retries: int = 3) -> None:
        n = (os.cpu_count() or 1) if workers is None else int(workers)
        if n < 1:
            raise ConfigError(f"workers must be at least 1, got {workers!r}")
        self.workers = n
        self.retries = int(retries)
        self._context = multiprocessing.get_context("spawn")

    def run(
        self, fn: Callable[[Any], T], items: Sequence[Any]
    ) -> Iterator[tuple[int, T | BaseException]]:
        attempts = [0] * len(items)
        pending = list(range(len(items)))
        main = threading.current_thread() is threading.main_thread()
        while pending:
            pool = ProcessPoolExecutor(
                self.workers,
                mp_context=self._context,
                initializer=_worker_init,
                initargs=(os.getpid(), main),
            )
            resubmit: list[int] = []
            try:
                with _sigint_blocked():  # the workers are spawned by these submits
                    futures: dict[Future, int] = {pool.submit(fn, items[i]): i for i in pending}
                pending = []
                while futures:
                    done, _ = wait(futures, return_when=FIRST_COMPLETED)
                    for fut in done:
                        i = futures.pop(fut)
                        try:
                            result: Any = fut.result()
                        except BrokenProcessPool as exc:
                            attempts[i] += 1
                            if attempts[i] <= self.retries:
                                resubmit.append(i)
                                continue
                            result = exc
                        except Exception as exc:  # the item's own error, reported for it
                            result = exc
                        yield i, result
            except BaseException:  # interrupted, or the consumer stopped: stop the workers
                _tear_down(pool)
                raise
            pool.shutdown(wait=True)
            pending = sorted(resubmit)

    def close(self) -> None:
        """Nothing to release (each ``run`` owns its pool)."""

    def __enter__(self) -> ProcessExecutor:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def make_executor(workers: int | None = None, cluster: str | None = None) -> Any:
    """The executor for the CLI's ``--workers`` and ``--cluster``.

    Parameters
    ----------
    workers : local processes (default: every core); 1 runs serially in this process.
    cluster : ``"local:N"`` (a Dask ``LocalCluster`` of N worker processes on loopback) or
        ``"tcp://HOST:PORT"`` (an existing Dask scheduler; its workers must see the logs at
        the manifest's paths and have fricid installed).
    """
    if cluster is not None:
        if workers is not None:
            raise ConfigError("give --workers or --cluster, not both")
        from ._dask import DaskExecutor

        return DaskExecutor.from_spec(cluster)
    if workers is not None and int(workers) == 1:
        return SerialExecutor()
    return ProcessExecutor(workers)
