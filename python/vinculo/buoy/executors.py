"""Where parallel runs execute: local worker processes, or an existing Dask distributed cluster.

Local processes start by fork on Linux (no ``__main__`` guard needed in user scripts) and by spawn
elsewhere. A Dask cluster is reached by its scheduler's address; its executor returns standard
:class:`concurrent.futures.Future` objects, so callers treat both alike.
"""

from __future__ import annotations

import contextlib
import multiprocessing
import sys
from collections.abc import Iterator
from concurrent.futures import Executor, ProcessPoolExecutor

from vinculo.errors import SchedulerError

__all__ = ["open_executor"]


@contextlib.contextmanager
def open_executor(
    workers: int, scheduler: str | None, timeout: float = 10.0
) -> Iterator[tuple[Executor | None, str]]:
    """Local worker processes, or a Dask cluster's executor, as a context manager.

    Arguments:
        workers: local processes; 1 yields None (run in this process).
        scheduler: address of a Dask distributed scheduler, or None for local processes.
        timeout: seconds to wait for the scheduler.

    Yields:
        ``(executor or None, description)``; the executor's futures are
        :class:`concurrent.futures.Future` in both cases.

    Raises:
        SchedulerError: the scheduler cannot be reached, or distributed is not installed.
    """
    if scheduler is not None:
        try:
            from distributed import Client
        except ImportError:
            raise SchedulerError(
                "running on a Dask cluster needs the distributed package: pip install "
                "'vinculo[dask]'",
                address=scheduler,
            ) from None
        try:
            client = Client(scheduler, timeout=f"{timeout}s")
        except (OSError, TimeoutError, ValueError) as e:
            raise SchedulerError(
                f"cannot reach the Dask scheduler at {scheduler!r}: {e}; check the address "
                f"(e.g. tcp://host:8786) and that the scheduler is running",
                address=scheduler,
            ) from None
        try:
            yield client.get_executor(pure=False), f"dask {scheduler}"
        finally:
            client.close()
        return
    if workers == 1:
        yield None, "1 process"
        return
    method = "fork" if sys.platform.startswith("linux") else "spawn"
    pool = ProcessPoolExecutor(max_workers=workers, mp_context=multiprocessing.get_context(method))
    try:
        yield pool, f"{workers} local processes"
    except BaseException:
        # Interrupted (Ctrl-C) or failed: stop the runs under way and drop the queued ones
        # instead of waiting for them (a Ctrl-C may reach this process only, not its workers).
        for process in list((getattr(pool, "_processes", None) or {}).values()):
            process.terminate()
        pool.shutdown(wait=True, cancel_futures=True)
        raise
    pool.shutdown(wait=True)
