"""Where parallel runs execute: local worker processes, or an existing Dask distributed cluster.

Local processes start by fork on Linux (no ``__main__`` guard needed in user scripts) and by spawn
elsewhere. Each worker watches the process that started it: on Linux the kernel kills the worker
when that process dies (``prctl(PR_SET_PDEATHSIG)``), elsewhere a thread in the worker polls the
parent's id, so no worker outlives a parent killed by SIGKILL. Workers ignore SIGINT: a Ctrl-C
reaches the parent, which stops them (:func:`open_executor`) and keeps what had finished.

A Dask cluster is reached by its scheduler's address; its executor returns standard
:class:`concurrent.futures.Future` objects, so callers treat both alike.
"""

from __future__ import annotations

import contextlib
import ctypes
import multiprocessing
import os
import signal
import sys
import threading
import time
from collections.abc import Iterator
from concurrent.futures import Executor, ProcessPoolExecutor

from vinculo.errors import SchedulerError

__all__ = ["open_executor", "watch_parent"]

#: ``PR_SET_PDEATHSIG`` of ``<linux/prctl.h>``: the signal a process gets when its parent dies.
_PR_SET_PDEATHSIG = 1
#: Seconds between two looks at the parent's id where the kernel cannot watch it.
_PARENT_POLL = 1.0


def watch_parent(parent: int) -> None:
    """Make this worker process end when ``parent`` dies, and ignore Ctrl-C (SIGINT).

    The initializer of every local worker. On Linux the kernel sends SIGKILL to the worker
    when the parent exits (``prctl(PR_SET_PDEATHSIG, SIGKILL)``); elsewhere a daemon thread
    checks the parent's id every second and exits the worker when it changed. A parent that
    died before this call is noticed at once.

    Arguments:
        parent: the process id of the parent (``os.getpid()`` where the pool was made).
    """
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    watched = False
    if sys.platform.startswith("linux"):
        try:
            libc = ctypes.CDLL(None, use_errno=True)
            watched = libc.prctl(_PR_SET_PDEATHSIG, int(signal.SIGKILL), 0, 0, 0) == 0
        except (OSError, AttributeError):  # pragma: no cover - a libc without prctl
            watched = False
    if os.getppid() != parent:  # the parent died before the watch began
        os._exit(1)
    if watched:
        return

    def poll() -> None:  # pragma: no cover - only where prctl is missing
        while True:
            time.sleep(_PARENT_POLL)
            if os.getppid() != parent:
                os._exit(1)

    threading.Thread(target=poll, name="vinculo-watch-parent", daemon=True).start()


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
    pool = ProcessPoolExecutor(
        max_workers=workers,
        mp_context=multiprocessing.get_context(method),
        initializer=watch_parent,
        initargs=(os.getpid(),),
    )
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
