"""Where the joints run: in this process, in a local process pool, or on a Dask cluster.

Every executor has one method, ``run(fn, items)``, yielding ``(index, result)`` as results
arrive, in any order; ``result`` is the exception instead when the executor itself could not
run an item (a worker process that died more often than the retries allow). The results do
not depend on the executor: each item carries its own seed, and :func:`.job.run_job` pins
BLAS to one thread.

- :class:`SerialExecutor`: one item after the other, in this process.
- :class:`ProcessExecutor`: a local process pool (``spawn``); a worker that dies (killed, out
  of memory) breaks the pool, which is rebuilt and its unfinished items resubmitted, each at
  most ``retries`` more times.
- :class:`DaskExecutor` (:mod:`._dask`): a Dask ``LocalCluster`` on loopback, or an existing
  scheduler; Dask reschedules the tasks of a worker that dies.
"""

from __future__ import annotations

import multiprocessing
import os
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from typing import Any, Protocol, TypeVar

from ..errors import ConfigError

__all__ = ["Executor", "ProcessExecutor", "SerialExecutor", "make_executor"]

T = TypeVar("T")


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
        while pending:
            pool = ProcessPoolExecutor(self.workers, mp_context=self._context)
            resubmit: list[int] = []
            try:
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
            except BaseException:  # interrupted, or the consumer stopped: do not wait
                pool.shutdown(wait=False, cancel_futures=True)
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
