"""The one entry point that integrates a system in time."""

from __future__ import annotations

import sys
import time
from collections.abc import Callable
from typing import IO, Any

from vinculo import _core, errors
from vinculo._core import System
from vinculo.run_options import RunOptions
from vinculo.solution import Solution

__all__ = ["ProgressBar", "simulate"]

ProgressCallback = Callable[[float, float], None]


class ProgressBar:
    """A one-line text progress bar, redrawn in place (used by ``simulate(progress=True)``).

    Arguments:
        stream: where to draw it (standard error by default).
        width: number of characters of the bar itself.
    """

    def __init__(self, stream: IO[str] | None = None, width: int = 30) -> None:
        self.stream = stream if stream is not None else sys.stderr
        self.width = width
        self.started = time.perf_counter()
        self.drawn = False

    def __call__(self, t: float, t_end: float) -> None:
        """Draw the bar for simulated time ``t`` out of ``t_end``."""
        fraction = 1.0 if t_end <= 0 else min(max(t / t_end, 0.0), 1.0)
        filled = round(fraction * self.width)
        bar = "#" * filled + "-" * (self.width - filled)
        elapsed = time.perf_counter() - self.started
        self.stream.write(
            f"\rvinculo [{bar}] {100 * fraction:5.1f}%  t = {t:.4g} / {t_end:.4g} s  "
            f"({elapsed:.1f} s)"
        )
        self.stream.flush()
        self.drawn = True

    def close(self) -> None:
        """End the line the bar is drawn on (if anything was drawn)."""
        if self.drawn:
            self.stream.write("\n")
            self.stream.flush()
            self.drawn = False


def simulate(
    system: System,
    t_end: float,
    dt: float,
    alpha: float | None = None,
    *,
    progress: bool | ProgressCallback = False,
    **options: Any,
) -> Solution:
    """Integrate a constrained system from ``t_start`` to ``t_end``.

    The equations ``M v' + F(q, v, t) - Phi_q^T lambda = 0``, ``v = q'``, ``Phi(q, t) = 0`` are
    discretised by the scheme named by ``scheme`` and solved step by step with Newton's method, the
    position constraints (with ``formulation='ggl'`` also the velocity constraints) holding at the
    end of every step. A step that does not converge is
    retried with half the step size, up to ``max_halvings`` times.

    Arguments:
        system: the model (its initial positions and velocities are the initial state).
        t_end: final time, in s (not before ``t_start``).
        dt: step size, in s (positive).
        alpha: parameter of the generalised trapezoidal rule, in [1/2, 1] (default 1/2): 1/2 is the
            trapezoidal rule (second order, no numerical damping), 1 is backward Euler (first
            order, strongly damped); values between add damping but are first order.
        progress: True draws a progress bar on standard error; a callable is called as
            ``progress(t, t_end)`` about twice a second of wall time (an exception it raises
            stops the run and propagates with the partial solution as its ``solution``
            attribute).
        **options: the run's options, by name, each described in :class:`RunOptions`:
            ``scheme``, ``rho_inf``, ``formulation``, ``t_start``, ``tolerance``,
            ``max_iterations``, ``max_halvings``, ``initial_tolerance``, ``save_every``,
            ``jacobian_reuse``, ``adaptive``, ``rtol``, ``atol``, ``h_min``, ``h_max``,
            ``t_eval``, ``max_output_bytes`` and ``linear_solver``.

    Returns:
        The :class:`Solution`.

    Raises:
        InvalidInputError: a bad argument (``dt <= 0``, ``t_end < t_start``, an unknown
            ``scheme`` or ``formulation``, ``alpha`` outside [1/2, 1], ``rho_inf`` outside [0, 1],
            a parameter of another scheme, a non-positive tolerance, ...).
        TypeError: a keyword argument that is not one of the options.
        InconsistentInitialStateError: the initial state violates a constraint by more than
            ``initial_tolerance`` (see ``System.project_initial_state``).
        ConvergenceError: a step failed even at the smallest step size; its ``solution`` attribute
            holds every step completed before.
        StepSizeTooSmallError: (a ConvergenceError) adaptive steps would have to be smaller than
            ``h_min`` to meet the tolerances; ``solution`` holds every state computed before.
        NegativeTensionError: a string (a tension-only distance) would have to push;
            ``solution`` holds every step up to that one.
        UserFunctionError: a function of a user force or constraint group raised (its exception
            is the ``__cause__``; ``solution`` holds the steps completed before).
        UserFunctionOutputError: such a function returned a wrong shape or a non-finite value.
        Interrupted: (a ``KeyboardInterrupt``) Ctrl-C, in the core's steps, the progress
            callback or a user function; ``solution`` holds every state stored before.
        ReentrantRunError: a user function of ``system`` ran ``system`` (or a copy of it) again.
        OutputTooLargeError: the stored output would exceed ``max_output_bytes`` (by default a
            third of the memory available): refused before the run starts, or, for adaptive
            steps, stopped when it reaches it (``solution`` holds what was stored).
    """
    settings = RunOptions.of("simulate", options).settings(t_end, dt, alpha)
    bar: ProgressBar | None = None
    callback: ProgressCallback | None
    if progress is True:
        bar = ProgressBar()
        callback = bar
    elif progress is False or progress is None:
        callback = None
    elif callable(progress):
        callback = progress
    else:
        raise errors.InvalidInputError(
            f"progress must be True, False or a callable progress(t, t_end), got {progress!r}",
            name="progress",
            value=progress,
        )
    try:
        result = _core.simulate(system, settings, progress=callback)
    finally:
        if bar is not None:
            bar.close()
    # A run that stopped early: the exception the core's error maps to, with the user's exception
    # of a failed user function as its cause and the partial solution attached.
    if result.error is not None:
        raise result.error
    # The solution keeps its own copy of the system, so that editing the system afterwards
    # (adding particles, constraints or forces) leaves the solution's metadata and energies
    # those of the run.
    return Solution.from_core(result, system.copy())
