"""Killing or interrupting the study commands: no worker outlives them, and Ctrl-C keeps results.

Each test runs the real command line in a subprocess, finds its worker processes in ``/proc``
(the processes whose parent is the command), signals the command, and checks the facts the
operating system reports: which processes still exist, the exit status and the files written.
"""

from __future__ import annotations

import csv
import os
import re
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

pytestmark = pytest.mark.skipif(
    not sys.platform.startswith("linux"), reason="reads the process table from /proc"
)

# Runs of a few seconds each (300 settling periods), so that the signal lands mid-sweep.
LONG_RUNS = ["--settle-periods", "300", "--fit-periods", "2", "--dt", "0.005"]


def _children(pid: int) -> set[int]:
    """The live (not zombie) processes whose parent is ``pid``."""
    found = set()
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            stat = (entry / "stat").read_text()
        except OSError:
            continue
        # "pid (name) state ppid ...": the name may hold spaces, so split after its ")".
        state, ppid = stat.rsplit(")", 1)[1].split()[:2]
        if int(ppid) == pid and state != "Z":
            found.add(int(entry.name))
    return found


def _alive(pid: int) -> bool:
    """Whether ``pid`` exists and is not a zombie (a zombie has ended; it waits to be reaped)."""
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return False
    return stat.rsplit(")", 1)[1].split()[0] != "Z"


class _Command:
    """The command line in a subprocess (its own session, like a job in a terminal), with its
    standard error collected as it comes."""

    def __init__(self, arguments: list[str], cwd: Path) -> None:
        # A job in a terminal starts with Ctrl-C's default action; a test run started in the
        # background by a non-interactive shell ignores SIGINT, and its children would inherit
        # that (an ignored signal stays ignored across exec; a handled one is reset to the
        # default), so the command is started while this process handles SIGINT.
        previous = signal.signal(signal.SIGINT, signal.default_int_handler)
        try:
            self.process = subprocess.Popen(
                [sys.executable, "-m", "vinculo", *arguments],
                cwd=cwd,
                stdout=subprocess.PIPE,
                stderr=subprocess.PIPE,
                start_new_session=True,
            )
        finally:
            signal.signal(signal.SIGINT, previous)
        self.err = b""
        self.out = b""
        self._readers = [
            threading.Thread(target=self._read, args=(self.process.stderr, "err"), daemon=True),
            threading.Thread(target=self._read, args=(self.process.stdout, "out"), daemon=True),
        ]
        for reader in self._readers:
            reader.start()

    def _read(self, stream, name: str) -> None:
        for chunk in iter(lambda: os.read(stream.fileno(), 4096), b""):
            setattr(self, name, getattr(self, name) + chunk)

    def wait_for(self, condition, what: str, timeout: float = 120.0) -> None:
        deadline = time.monotonic() + timeout
        while not condition():
            if self.process.poll() is not None:
                self.finish()
                pytest.fail(f"the command ended before {what}: {self.err.decode()[-2000:]}")
            if time.monotonic() > deadline:
                self.process.kill()
                self.finish()
                pytest.fail(f"no {what} within {timeout} s: {self.err.decode()[-2000:]}")
            time.sleep(0.05)

    def finish(self, timeout: float = 60.0) -> int:
        code = self.process.wait(timeout)
        for reader in self._readers:
            reader.join(timeout)
        self.process.stdout.close()
        self.process.stderr.close()
        return code


def _gone_within(pids: set[int], timeout: float) -> set[int]:
    """The processes of ``pids`` still alive after ``timeout`` seconds (polling)."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        alive = {p for p in pids if _alive(p)}
        if not alive:
            return set()
        time.sleep(0.1)
    return {p for p in pids if _alive(p)}


@pytest.mark.parametrize(
    "arguments",
    [
        ["buoy", "--models", "particle", "--count", "3", "--no-progress"],
        ["buoy", "sweep", "-p", "frequency=0.6,0.7,0.8,0.9", "--no-progress"],
    ],
    ids=["buoy", "buoy sweep"],
)
def test_sigkill_of_the_command_leaves_no_worker(tmp_path, arguments):
    command = _Command([*arguments, "--workers", "2", "--output", "out", *LONG_RUNS], tmp_path)
    pid = command.process.pid
    command.wait_for(lambda: len(_children(pid)) >= 2, "two worker processes")
    workers = _children(pid)
    os.kill(pid, signal.SIGKILL)
    command.finish()
    # The kernel kills each worker when its parent dies (PR_SET_PDEATHSIG); before the fix
    # they ran on for minutes. 10 s leaves room for a loaded machine.
    assert _gone_within(workers, 10.0) == set()


def test_ctrl_c_of_buoy_writes_the_finished_runs_and_exits_130(tmp_path):
    command = _Command(
        ["buoy", "--models", "particle", "--count", "5", "--workers", "2", "--output", "out",
         *LONG_RUNS],
        tmp_path,
    )
    pid = command.process.pid
    # The progress bar shows "1/N runs" once the first run has finished.
    command.wait_for(lambda: re.search(rb" 1/\d+ runs", command.err), "finished run")
    total = int(re.search(rb" 1/(\d+) runs", command.err).group(1))
    workers = _children(pid)
    os.killpg(pid, signal.SIGINT)  # what Ctrl-C in a terminal does: the whole foreground group
    assert command.finish() == 130
    assert _gone_within(workers, 10.0) == set()
    message = command.err.decode().split("\n")
    tail = [line for line in message if line.strip()][-1]
    assert tail.startswith("vinculo buoy: interrupted") and "out" in tail
    assert "Traceback" not in command.err.decode()
    # What finished is written: sweep.csv holds some but not all of the runs (the 5 sweep
    # frequencies, and any history frequencies the study adds), each with its amplitude.
    with (tmp_path / "out" / "sweep.csv").open() as f:
        rows = [r for r in csv.DictReader(f) if r["model"] == "particle"]
    assert 1 <= len(rows) < total
    assert all(float(r["relative_amplitude"]) > 0.0 for r in rows)
    assert (tmp_path / "out" / "summary.txt").exists()
