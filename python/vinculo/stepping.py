"""A simulation advanced step by step by the caller: coupling loops, snapshots, driven points."""

from __future__ import annotations

import os
from typing import Any

import numpy as np

from vinculo import _core
from vinculo._core import Snapshot, System
from vinculo.run_options import RunOptions
from vinculo.solution import Solution

__all__ = ["Simulation", "Snapshot"]


class Simulation:
    """A running simulation that the caller advances with :meth:`step_to`.

    It takes the arguments of :func:`vinculo.simulate` (except ``progress``) and runs the same
    steps: stepping to ``t1`` and then to ``t2`` stores the same states, bit for bit, as one call
    of ``simulate`` to ``t2`` (fixed steps land on an intermediate time that is on their grid;
    error-controlled steps stop at the end of the step that reaches it, see :attr:`time`).
    Between calls the caller may read the state, set driven laws (:func:`vinculo.driven`), and
    take or restore snapshots. The simulation keeps its own copy of ``system``: editing the system
    afterwards does not change the run (driven laws and user groups are shared with the copy).

    Arguments:
        system: the model (its initial positions and velocities are the initial state).
        t_end: the latest time the run may reach, in s (the last fixed step lands on it).
        dt: step size, in s (the first step with ``adaptive=True``).
        alpha: parameter of the generalised trapezoidal rule (see :func:`vinculo.simulate`).
        **options: the run's options, by name, as for :func:`vinculo.simulate` (each described
            in :class:`vinculo.RunOptions`).

    Raises:
        InvalidInputError: a bad argument (as :func:`vinculo.simulate`).
        TypeError: a keyword argument that is not one of the options.
        InconsistentInitialStateError: the initial state violates a constraint.
        OutputTooLargeError: the stored output would exceed ``max_output_bytes``.
        ReentrantRunError: created from inside a user function of ``system``.
    """

    def __init__(
        self, system: System, t_end: float, dt: float, alpha: float | None = None, **options: Any
    ) -> None:
        self._system = system.copy()
        settings = RunOptions.of("Simulation", options).settings(t_end, dt, alpha)
        self._core = _core.Simulation(system, settings)

    def step_to(self, t: float) -> None:
        """Advance to time ``t`` (at most ``t_end``).

        Arguments:
            t: the time to reach, in s (not before :attr:`time`).

        Raises:
            InvalidInputError: ``t`` is before the current time (restore a snapshot to go back).
            ConvergenceError: (or its subclasses, as :func:`vinculo.simulate`) the run stopped;
                its ``solution`` holds every state stored before, and the simulation keeps them
                (restore a snapshot to go on from an earlier state).
            Interrupted: (a ``KeyboardInterrupt``) Ctrl-C stopped the steps; ``solution`` as
                above (restore a snapshot to go on).
            ReentrantRunError: called from inside a user function of the simulation's system.
        """
        self._core.step_to(float(t))

    @property
    def time(self) -> float:
        """Current time, in s (where the last step ended)."""
        return self._core.time

    @property
    def positions(self) -> np.ndarray:
        """Current positions, shape (n, 3), in m (a copy)."""
        return self._core.positions

    @property
    def velocities(self) -> np.ndarray:
        """Current velocities, shape (n, 3), in m/s (a copy)."""
        return self._core.velocities

    @property
    def multipliers(self) -> np.ndarray:
        """Current Lagrange multipliers, shape (m,) (signs as in :func:`vinculo.simulate`)."""
        return self._core.multipliers

    def solution(self) -> Solution:
        """The states stored so far.

        Returns:
            The :class:`Solution`, as :func:`vinculo.simulate` returns it for the same run.
        """
        return Solution.from_core(self._core.solution(), self._system.copy())

    def snapshot(self) -> Snapshot:
        """A copy of the running state, to return to with :meth:`restore`.

        Returns:
            The snapshot (its ``time`` attribute says when it was taken).
        """
        return self._core.snapshot()

    def restore(self, snapshot: Snapshot) -> None:
        """Return to the state of a snapshot; stepping on repeats the later steps bit for bit.

        States stored after the snapshot are dropped. A snapshot of another simulation of the
        same system carries the state but not the history: the stored states restart at it. A
        driven law keeps every value set (values are set once, at increasing times): the steps
        after a restore see them.

        Arguments:
            snapshot: taken by :meth:`snapshot` of a simulation of the same system.

        Raises:
            InvalidInputError: the snapshot is of another system (other particle or constraint
                counts, or another model), or not a snapshot.
        """
        self._core.restore(snapshot)

    def save_snapshot(self, path: str | os.PathLike[str]) -> None:
        """Save a snapshot of the current state to a file (a small binary format, floats bit-exact).

        With ``adaptive=True`` the file also holds the error control's state (the next step size
        and the step-size controller's memory), so a run loaded from it takes the same steps as
        the saved run would.

        Arguments:
            path: the file to write.

        Raises:
            InvalidInputError: the run has stopped, or the file cannot be written.
        """
        self._core.snapshot().save(os.fspath(path))

    def load_snapshot(self, path: str | os.PathLike[str]) -> None:
        """Restore the state saved by :meth:`save_snapshot` (here or in another process).

        The run goes on from the saved state as the saved run would, bit for bit; the stored
        states restart at the snapshot's (the history before it is not in the file), unless the
        snapshot is of this very run (then as :meth:`restore`).

        Arguments:
            path: the file written by :meth:`save_snapshot`.

        Raises:
            InvalidInputError: the file cannot be read, is not a snapshot file, is truncated or
                corrupt, or is a snapshot of another system.
        """
        self._core.restore(Snapshot.load(os.fspath(path)))
