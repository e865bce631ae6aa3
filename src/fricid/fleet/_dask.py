"""The Dask executor: a ``LocalCluster`` on loopback, or an existing scheduler.

fricid writes no scheduler of its own: each joint is one Dask task (``Client.map``), results
are collected with ``as_completed``, and a worker that dies has its tasks rescheduled by the
Dask scheduler (up to its ``allowed-failures``, then the task fails with ``KilledWorker``,
which the fleet reports for that joint).
"""

from __future__ import annotations

import logging
import uuid
from collections.abc import Callable, Iterator, Sequence
from typing import Any, TypeVar

from ..errors import ConfigError

__all__ = ["DaskExecutor"]

logger = logging.getLogger(__name__)

T = TypeVar("T")

#: Where a LocalCluster listens: loopback only (scheduler, nannies and workers).
LOOPBACK = "127.0.0.1"


async def _quiet_shutdown() -> None:
    """Run on each worker of a cluster being torn down after an interrupt: its heartbeats
    to the closing scheduler fail, and each failure would log a traceback. (A coroutine:
    ``Client.run(..., wait=False)`` takes only those.)"""
    logging.getLogger("distributed").setLevel(logging.CRITICAL)


class DaskExecutor:
    """Runs the items as Dask tasks on ``client``'s cluster.

    Use :meth:`local` or :meth:`from_spec` to make one; use it as a context manager (or call
    :meth:`close`) to release the client and a cluster it started.

    Parameters
    ----------
    client : distributed.Client
        A connected client.
    cluster : distributed.SpecCluster or None
        A cluster this executor started and closes with itself, if any.
    """

    name = "dask"

    def __init__(self, client: Any, cluster: Any = None) -> None:
        self.client = client
        self.cluster = cluster

    @classmethod
    def local(cls, n_workers: int) -> DaskExecutor:
        """Start a ``LocalCluster`` of ``n_workers`` single-threaded worker processes, every
        one listening on 127.0.0.1 only, without dashboards."""
        from distributed import Client, LocalCluster

        if n_workers < 1:
            raise ConfigError(f"a local cluster needs at least 1 worker, got {n_workers}")
        cluster = LocalCluster(
            n_workers=n_workers,
            threads_per_worker=1,
            processes=True,
            host=LOOPBACK,
            protocol="tcp://",
            dashboard_address=None,
            worker_dashboard_address=None,
            silence_logs=logging.ERROR,
        )
        try:
            client = Client(cluster)
        except BaseException:
            cluster.close()
            raise
        return cls(client, cluster)

    @classmethod
    def connect(cls, address: str, timeout: float = 15.0) -> DaskExecutor:
        """Connect to an existing scheduler at ``address`` (``tcp://HOST:PORT``)."""
        from distributed import Client

        try:
            client = Client(address, timeout=timeout)
        except (OSError, TimeoutError) as exc:
            raise ConfigError(f"cannot reach the Dask scheduler at {address}: {exc}") from None
        return cls(client)

    @classmethod
    def from_spec(cls, spec: str) -> DaskExecutor:
        """``"local:N"`` -> :meth:`local`; ``"tcp://HOST:PORT"`` -> :meth:`connect`."""
        text = spec.strip()
        if text.startswith("local:"):
            try:
                n = int(text.split(":", 1)[1])
            except ValueError:
                n = 0
            if n < 1:
                raise ConfigError(f"--cluster local:N needs a worker count N >= 1, got '{spec}'")
            return cls.local(n)
        if text.startswith("tcp://") and len(text) > len("tcp://"):
            return cls.connect(text)
        raise ConfigError(
            f"--cluster takes local:N (a local Dask cluster of N workers) or tcp://HOST:PORT "
            f"(an existing Dask scheduler); got '{spec}'"
        )

    @property
    def workers(self) -> int:
        """Workers connected now."""
        return len(self.client.scheduler_info().get("workers", {}))

    def run(
        self, fn: Callable[[Any], T], items: Sequence[Any]
    ) -> Iterator[tuple[int, T | BaseException]]:
        """Submit every item as a task; yield ``(index, result)`` as tasks finish."""
        from distributed import as_completed

        if not items:
            return
        token = uuid.uuid4().hex[:12]
        keys = [f"fricid-fleet-{token}-{i}" for i in range(len(items))]
        futures = self.client.map(fn, list(items), key=keys)
        index = {fut.key: i for i, fut in enumerate(futures)}
        try:
            for fut in as_completed(futures):
                try:
                    result: Any = fut.result()
                except Exception as exc:  # KilledWorker and the like, reported for the item
                    result = exc
                fut.release()
                yield index[fut.key], result
        except BaseException:  # interrupted: stop the tasks, quietly (the caller closes)
            if self.cluster is not None:  # only a cluster we started: not a shared one
                try:
                    self.client.run(_quiet_shutdown, wait=False)
                    logging.getLogger("distributed").setLevel(logging.CRITICAL)
                except Exception as exc:  # the cluster may be gone already
                    logger.debug("could not quieten the Dask workers: %s", exc)
            self.client.cancel(futures)
            raise

    def close(self) -> None:
        """Close the client, and the cluster if this executor started it."""
        self.client.close()
        if self.cluster is not None:
            self.cluster.close()

    def __enter__(self) -> DaskExecutor:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
