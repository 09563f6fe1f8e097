"""The one entry point that integrates a system in time."""

from __future__ import annotations

import sys
import time
from collections.abc import Callable, Sequence
from typing import IO, Any

import numpy as np

from vinculo import _core, errors
from vinculo._core import System
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
    scheme: str = "trapezoidal",
    rho_inf: float | None = None,
    formulation: str = "index-3",
    t_start: float = 0.0,
    tolerance: float = 1e-10,
    max_iterations: int = 25,
    max_halvings: int = 4,
    initial_tolerance: float = 1e-8,
    save_every: int = 1,
    progress: bool | ProgressCallback = False,
    jacobian_reuse: bool = False,
    adaptive: bool = False,
    rtol: float = 1e-6,
    atol: float = 1e-6,
    h_min: float = 1e-10,
    h_max: float | None = None,
    t_eval: Sequence[float] | np.ndarray | None = None,
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
        scheme: 'trapezoidal' (the generalised trapezoidal rule with ``alpha``),
            'backward-euler' (the same rule with alpha = 1), or 'generalized-alpha' (the
            generalised-alpha scheme of Arnold and Brüls for index-3 systems: second order, with
            numerical damping of the high frequencies set by ``rho_inf``).
        rho_inf: spectral radius at infinite frequency of 'generalized-alpha', in [0, 1]
            (default 0.9): 1 adds no numerical damping, 0 removes the highest frequencies in one
            step; the low frequencies are barely damped in every case.
        formulation: 'index-3' (default: position constraints only, the velocities satisfy
            ``Phi_q v + Phi_t = 0`` to the scheme's accuracy) or 'ggl' (the stabilised index-2
            formulation of Gear, Gupta and Leimkuhler: the velocity constraints are added with a
            second multiplier on the kinematics, ``q' = v + Phi_q^T mu``, so both levels hold at
            every step to the Newton tolerance; same orders, same meaning of the multipliers,
            about twice the unknowns and the general sparse LU instead of the tree elimination).
        t_start: initial time, in s.
        tolerance: Newton stops when the scaled residual and the last increment (both lengths, see
            docs/theory/formulation.md) are below ``tolerance * system.length_scale()``.
        max_iterations: Newton iterations allowed per attempt.
        max_halvings: how many times a failing step may be halved before giving up.
        initial_tolerance: largest initial violation accepted, relative to the model's scales:
            ``|s_k Phi_k| <= initial_tolerance * length_scale`` for positions and
            ``|s_k (Phi_q v + Phi_t)| <= initial_tolerance * speed`` for velocities, the speed being
            the largest initial speed or ``sqrt(|g| length_scale)``.
        save_every: store every k-th step (the last step is always stored); long runs of large
            models need it to keep the output in memory.
        progress: True draws a progress bar on standard error; a callable is called as
            ``progress(t, t_end)`` about twice a second of wall time.
        jacobian_reuse: modified Newton: keep the factorised iteration matrix across iterations
            and steps, refreshing it when the Newton increments shrink by less than half per
            iteration, after 8 iterations with one matrix, and whenever the step size changes (a
            step that fails with an old matrix is retried once with a fresh one). The converged
            states are the same to the Newton tolerance; ``Solution.factorisations`` counts the
            factorisations. Each step stops with an error near ``tolerance`` (full Newton stops
            far below it), which enters the velocities divided by ``dt``: with small steps lower
            the tolerance. False: full Newton (a new matrix every iteration).
        adaptive: choose the step sizes by a local error estimate (on positions and velocities,
            not multipliers) and a PI controller so that each step meets ``rtol`` and ``atol``;
            ``dt`` is then the first step. False: fixed steps of ``dt`` (halved where Newton fails).
            The estimate's weighted RMS norm over the free coordinates, with the weights
            ``atol + rtol |q|`` for positions and ``atol U / L + rtol |v|`` for velocities
            (``L = system.length_scale()``, ``U`` the speed scale of ``initial_tolerance``), times
            ``T / h`` (error per unit step, ``T = L / U``) must be <= 1. A rejected step is retried
            smaller (``Solution.steps_rejected`` counts them). The error of a run is then about
            proportional to the tolerance (a few times it on a swinging pendulum). With
            ``jacobian_reuse`` keep ``tolerance`` far below ``rtol``: modified Newton's error
            near its tolerance looks like a step error at small steps.
        rtol: relative tolerance of adaptive steps, in (0, 1).
        atol: absolute tolerance of adaptive steps, in m (positions).
        h_min: smallest adaptive step, in s: a run that would need a smaller one stops with
            :class:`StepSizeTooSmallError`.
        h_max: largest adaptive step, in s (default: no limit).
        t_eval: times at which to return the state with ``adaptive=True`` (strictly increasing,
            within ``[t_start, t_end]``), interpolated inside the step that contains each (cubic
            Hermite positions, its derivative for velocities, linear multipliers) without forcing
            the steps onto them. Default: the state after every accepted step (every
            ``save_every``-th).

    Returns:
        The :class:`Solution`.

    Raises:
        InvalidInputError: a bad argument (``dt <= 0``, ``t_end < t_start``, an unknown
            ``scheme`` or ``formulation``, ``alpha`` outside [1/2, 1], ``rho_inf`` outside [0, 1],
            a parameter of another scheme, a non-positive tolerance, ...).
        InconsistentInitialStateError: the initial state violates a constraint by more than
            ``initial_tolerance`` (see ``System.project_initial_state``).
        ConvergenceError: a step failed even at the smallest step size; its ``solution`` attribute
            holds every step completed before.
        StepSizeTooSmallError: (a ConvergenceError) adaptive steps would have to be smaller than
            ``h_min`` to meet the tolerances; ``solution`` holds every state computed before.
        UserFunctionError: a function of a user force or constraint group raised (its exception
            is the ``__cause__``; ``solution`` holds the steps completed before).
        UserFunctionOutputError: such a function returned a wrong shape or a non-finite value.
    """
    settings = _run_settings(
        t_end,
        dt,
        alpha,
        scheme=scheme,
        rho_inf=rho_inf,
        formulation=formulation,
        t_start=t_start,
        tolerance=tolerance,
        max_iterations=max_iterations,
        max_halvings=max_halvings,
        initial_tolerance=initial_tolerance,
        save_every=save_every,
        jacobian_reuse=jacobian_reuse,
        adaptive=adaptive,
        rtol=rtol,
        atol=atol,
        h_min=h_min,
        h_max=h_max,
        t_eval=t_eval,
    )
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
        data = _core.simulate(system, settings, progress=callback)
    finally:
        if bar is not None:
            bar.close()
    # A user function's own exception (with its traceback), chained as the cause; it is not
    # part of the solution (which is saved to files).
    cause = data["error"].pop("cause", None) if data.get("error") is not None else None
    # The solution keeps its own copy of the system, so that editing the system afterwards
    # (adding particles, constraints or forces) leaves the solution's metadata and energies
    # those of the run.
    solution = Solution.from_core(data, system.copy())
    if solution.error is not None:
        raise _convergence_error(solution.error, solution) from cause
    return solution


def _run_settings(
    t_end: float,
    dt: float,
    alpha: float | None,
    *,
    scheme: str,
    formulation: str,
    jacobian_reuse: bool,
    adaptive: bool,
    t_eval: Sequence[float] | np.ndarray | None,
    **options: Any,
) -> _core.RunSettings:
    """The settings of a run, as one object of the compiled core, for :func:`simulate` and
    :class:`vinculo.Simulation` alike (their meaning: :func:`simulate`).

    The core checks every value's range when it builds the settings; this checks first what
    Python must convert: the names are strings and ``t_eval`` is one-dimensional. ``options`` are
    the other keyword arguments of :func:`simulate` (less ``progress``), passed on unchanged.

    Returns:
        The core's ``RunSettings`` (its ``SimulationOptions``), taken by ``_core.simulate`` and
        ``_core.Simulation``.

    Raises:
        InvalidInputError: ``scheme`` or ``formulation`` is not a string, or ``t_eval`` is not a
            1-D sequence of times.
    """
    if not isinstance(scheme, str):
        raise errors.InvalidInputError(
            f"scheme must be a name ('trapezoidal', 'backward-euler' or 'generalized-alpha'), "
            f"got {scheme!r}",
            name="scheme",
            value=scheme,
        )
    if not isinstance(formulation, str):
        raise errors.InvalidInputError(
            f"formulation must be a name ('index-3' or 'ggl'), got {formulation!r}",
            name="formulation",
            value=formulation,
        )
    times = None
    if t_eval is not None:
        array = np.asarray(t_eval, dtype=np.float64)
        if array.ndim != 1:
            raise errors.InvalidInputError(
                f"t_eval must be a 1-D sequence of times, got an array of shape {array.shape}",
                name="t_eval",
                value=t_eval,
            )
        times = [float(x) for x in array]
    return _core.RunSettings(
        t_end,
        dt,
        alpha,
        scheme=scheme,
        formulation=formulation,
        jacobian_reuse=bool(jacobian_reuse),
        adaptive=bool(adaptive),
        t_eval=times,
        **options,
    )

def _convergence_error(error: dict[str, Any], solution: Solution) -> errors.VinculoError:
    """The exception for a run the core stopped early, carrying the partial solution."""
    details = {key: value for key, value in error.items() if key != "message"}
    message = str(error.get("message") or "the simulation stopped early")
    kind = details.get("kind")
    # The core names the failure; a name of one of our classes selects it, anything else
    # (a description of a Newton failure) is a ConvergenceError.
    cls = getattr(errors, str(kind), None) if kind else None
    if not (isinstance(cls, type) and issubclass(cls, errors.VinculoError)):
        cls = errors.ConvergenceError
    return cls(message, **details, solution=solution)
