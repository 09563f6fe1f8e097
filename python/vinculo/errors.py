"""The exceptions vinculo raises.

Every exception derives from :class:`VinculoError`, so ``except vinculo.VinculoError`` catches
anything vinculo reports on purpose. Each class also derives from the built-in exception a Python
user would expect (``ValueError`` for bad input, ``LookupError`` for an unknown handle,
``RuntimeError`` for a failed solve), so generic handlers keep working.

Every constructor has the signature ``(message, **details)``: the message is the text shown to the
user, and each detail is stored as an attribute of the same name (and in the ``details`` dict).
The compiled core builds them as ``cls(message, name=..., value=...)``, in one place
(``crates/vinculo-python/src/errors.rs``): the class is chosen by the variant of the core's error,
for an error of a call and for the error that stopped a run alike; a stopped run's exception
carries its partial :class:`vinculo.Solution` as ``solution``.

One class is not a :class:`VinculoError`: :class:`Interrupted`, the ``KeyboardInterrupt`` of a run
stopped by Ctrl-C, which derives from ``KeyboardInterrupt`` (and not from ``Exception``) so that
``except KeyboardInterrupt`` catches it and ``except Exception`` does not.
"""

from __future__ import annotations

from typing import Any

__all__ = [
    "ConvergenceError",
    "InconsistentInitialStateError",
    "InstabilityError",
    "InternalError",
    "Interrupted",
    "InvalidInputError",
    "MooringFileError",
    "NegativeTensionError",
    "OutputTooLargeError",
    "RedundantConstraintsError",
    "ReentrantRunError",
    "SchedulerError",
    "StepSizeTooSmallError",
    "UnknownHandleError",
    "UserFunctionError",
    "UserFunctionOutputError",
    "VinculoError",
]

# Attribute names that a detail must not overwrite (they belong to the exception machinery).
_RESERVED = frozenset({"args", "message", "details", "with_traceback", "add_note", "__notes__"})


def _rebuild(cls: type[_Detailed], message: str, details: dict[str, Any]) -> _Detailed:
    """Recreate an exception from its message and details (used by pickle)."""
    return cls(message, **details)


class _Detailed:
    """The message and details of vinculo's exceptions (shared by :class:`VinculoError` and
    :class:`Interrupted`, which have different built-in bases)."""

    message: str
    details: dict[str, Any]

    def __init__(self, message: str = "", **details: Any) -> None:
        super().__init__(message)
        self.message = message
        self.details: dict[str, Any] = dict(details)
        for key, value in details.items():
            if key not in _RESERVED:
                setattr(self, key, value)

    def __str__(self) -> str:
        return self.message

    def __repr__(self) -> str:
        parts = [repr(self.message)]
        parts += [f"{key}={value!r}" for key, value in self.details.items() if key != "solution"]
        return f"{type(self).__name__}({', '.join(parts)})"

    def __reduce__(self) -> tuple[Any, ...]:
        return (_rebuild, (type(self), self.message, self.details))


class VinculoError(_Detailed, Exception):
    """Root of every exception vinculo raises (but :class:`Interrupted`, a ``KeyboardInterrupt``).

    Raised directly only for conditions no subclass describes; catch it to handle any vinculo error.

    Arguments:
        message: what went wrong, with the offending value, and what to do about it.
        **details: machine-readable facts about the error (for example ``name`` and ``value`` of a
            bad argument); each is stored as an attribute and in :attr:`details`.
    """


class Interrupted(_Detailed, KeyboardInterrupt):
    """A run stopped by Ctrl-C (SIGINT), with everything it computed.

    Raised by :func:`vinculo.simulate` and ``Simulation.step_to`` wherever the interrupt lands:
    in the core's steps (which look for it about ten times a second), in the progress callback,
    or inside a user function (a force or constraint group's function, a law's callable). It is
    a ``KeyboardInterrupt``, so ``except KeyboardInterrupt`` catches it (and ``except Exception``
    does not). ``solution`` holds every state stored before the interrupt, and the state where
    the run stopped (stored even between two rows of ``save_every``): each one a completed,
    converged step, so its states satisfy the constraints as in a complete run and match it up to
    the interrupt.

    Arguments:
        message: where the run stopped.
        **details: ``time``, ``solution``; for an interrupt inside a user function also
            ``group`` and ``call`` (as :class:`UserFunctionError`).

    Attributes:
        time: the time the run reached, the end of its last step (s); for an interrupt inside a
            user function, the time of that function's call.
        solution: the partial :class:`vinculo.Solution` (None when the run was interrupted before
            its first state was computed).
    """

    time: float | None = None
    group: str | None = None
    call: str | None = None
    solution: Any = None


class InvalidInputError(VinculoError, ValueError):
    """An argument is out of its domain.

    Raised when building a model or starting a run with a value that cannot be simulated: a mass
    that is not finite and positive, a position or velocity containing NaN or infinity, a distance
    length that is not positive, a distance from a particle to itself, a plane with a zero normal,
    ``t_end`` before ``t_start``, a step ``dt`` that is not positive, ``alpha`` outside [1/2, 1],
    a non-positive tolerance, a tabulated law with too few or unsorted samples, and so on.
    Details usually include ``name`` (the argument) and ``value`` (what was given).
    """


class MooringFileError(InvalidInputError):
    """A mooring input file (MoorDyn's format) is malformed or asks for what is not supported.

    Raised by :func:`vinculo.mooring.read_moordyn` and everything that reads such a file (the
    ``vinculo mooring`` commands): a value that is not a number, a missing column, a reference
    to an unknown line type or point, or a feature vinculo does not model yet (rods, bodies,
    wave kinematics, ...). The message starts with the file and the line, then the field.

    Attributes:
        file: the file's path (text).
        line: the line number in the file (1-based; None when the problem is not on one line).
        field: the column or option name.
        value: the offending text or value.
    """

    file: str | None = None
    line: int | None = None
    field: str | None = None
    value: Any = None


class UnknownHandleError(VinculoError, LookupError):
    """A handle does not refer to anything in this system.

    Raised when a ``ParticleId``, ``ConstraintId`` or ``ForceId`` belongs to another system or is
    out of range, or when a raw integer is passed where a handle is expected.
    """


class InconsistentInitialStateError(InvalidInputError):
    """The initial positions or velocities violate a constraint.

    Raised by ``simulate`` when ``|s_k Phi_k|`` at the start exceeds ``initial_tolerance`` for some
    constraint equation ``k`` (or the velocities violate ``Phi_q v + Phi_t = 0``). The message names
    the constraint. Call ``System.project_initial_state()`` to move the initial state onto the
    constraints with the least mass-weighted change, or fix the model.
    """


class RedundantConstraintsError(InvalidInputError):
    """Some constraint equations are combinations of others.

    Redundant constraints leave the multipliers undetermined and make every linear solve singular.
    Raised when a rigid body is built, or when a run starts on a system whose constraint gradients
    are linearly dependent. The message names the dependent constraint and those it is a
    combination of; remove one of them.

    Attributes:
        constraint: name of the dependent constraint; ``index`` its index.
        depends_on: names of the constraints it is a combination of; ``depends_on_indices`` theirs.
    """

    constraint: str | None = None
    index: int | None = None
    depends_on: list[str] | None = None
    depends_on_indices: list[int] | None = None


class SchedulerError(VinculoError, ConnectionError):
    """A Dask distributed scheduler cannot be used.

    Raised by parameter studies given a scheduler address that cannot be reached (or when the
    ``distributed`` package is not installed). Nothing has run; the message names the address.

    Attributes:
        address: the scheduler address given.
    """


class NegativeTensionError(VinculoError, RuntimeError):
    """A string (a tension-only distance) would have to push.

    Raised by :func:`vinculo.simulate` at the first step where a constraint declared with
    ``System.set_tension_only`` carries a negative tension: from then on the model (an
    inextensible rod) no longer describes a string, so the run stops instead of returning
    unphysical motion. ``solution`` holds every step up to and including that one.

    Attributes:
        time: when the tension first became negative (s).
        constraint: the string's name; ``index`` its index.
        tension: the (negative) tension it would need, in N.
        solution: the partial :class:`vinculo.Solution`.
    """

    time: float | None = None
    constraint: str | None = None
    index: int | None = None
    tension: float | None = None
    solution: Any = None


class ConvergenceError(VinculoError, RuntimeError):
    """A time step could not be completed.

    Raised by :func:`vinculo.simulate` when Newton's method does not converge even after the allowed
    number of step halvings (or the Jacobian is singular). Nothing computed is lost: ``solution``
    holds every step completed before the failure.

    Attributes:
        time: the time at the start of the step that failed (s).
        step_size: the last (smallest) step size tried (s).
        residual: the residual norm when Newton stopped.
        iterations: the Newton iterations of the last attempt.
        equation: name of the equation with the largest residual (a constraint or a particle's
            dynamics), where the core could tell.
        solution: the partial :class:`vinculo.Solution` up to the last completed step.
    """

    time: float | None = None
    step_size: float | None = None
    residual: float | None = None
    iterations: int | None = None
    equation: str | None = None
    solution: Any = None


class StepSizeTooSmallError(ConvergenceError):
    """Error-controlled steps would have to be smaller than ``h_min``.

    Raised by :func:`vinculo.simulate` with ``adaptive=True`` when the step that meets ``rtol`` and
    ``atol`` is below ``h_min``: loosen the tolerances, lower ``h_min``, or look for a
    discontinuity in the model's laws. ``solution`` holds every state computed before.

    Attributes:
        time: the time at the start of the step that could not be completed (s).
        step_size: the step the controller proposed (s).
        h_min: the smallest step allowed (s).
        error_norm: the weighted error norm of the last attempt (1 meets the tolerances).
        solution: the partial :class:`vinculo.Solution`.
    """

    h_min: float | None = None
    error_norm: float | None = None
class InstabilityError(ConvergenceError):
    """Index-3 generalised-alpha went unstable: the energy grew beyond what the model holds.

    Raised by :func:`vinculo.simulate` with ``scheme='generalized-alpha'`` and the index-3
    formulation when the mechanical energy of a constrained model under gravity and drag alone
    (no springs or bending, constraints that do not move) exceeds its initial value plus all the
    energy the model can exchange: the scheme is unstable at that ``rho_inf`` and step (measured
    table in the theory page "Time rules"). Use ``formulation='ggl'``, ``rho_inf <= 0.5``, or a
    smaller step. ``solution`` holds every step before.

    Attributes:
        time: the time at the end of the step where the energy passed the bound (s).
        step_size: the step size (s).
        rho_inf: the scheme's spectral radius at infinite frequency.
        energy: the mechanical energy reached (J).
        initial_energy: the initial mechanical energy (J).
        energy_bound: the bound it passed (J).
        solution: the partial :class:`vinculo.Solution`.
    """

    rho_inf: float | None = None
    energy: float | None = None
    initial_energy: float | None = None
    energy_bound: float | None = None


class UserFunctionError(VinculoError, RuntimeError):
    """A Python function of a user force or constraint group raised an exception.

    Raised by :func:`vinculo.simulate`: the run stops at the failing call and ``solution`` holds
    every step completed before. The function's own exception, with its traceback, is chained as
    ``__cause__``.

    Attributes:
        group: the group's name.
        call: the failing function ("force", "jacobian", "phi", "gradient", "hessian", "phi_t"
            or "gamma").
        time: the time of the call (s).
        solution: the partial :class:`vinculo.Solution` (None when the run stopped before its
            first step).
    """

    group: str | None = None
    call: str | None = None
    time: float | None = None
    solution: Any = None


class UserFunctionOutputError(UserFunctionError, ValueError):
    """A Python function of a user group returned an unusable result.

    The message names the group, the function, the shape returned and the one expected (or the
    first element with NaN or infinity) and says what to return. Same attributes as
    :class:`UserFunctionError`.
    """


class ReentrantRunError(VinculoError, RuntimeError):
    """A user function of a running system called back into a run of the same system.

    Raised by :func:`vinculo.simulate`, ``Simulation`` and the ``System`` and ``UserGroup`` methods
    that evaluate the model's user functions, when called from inside a user function (force or
    constraint group) of the run of that system (or of a copy of it, which shares its user groups):
    the outer run is in the middle of a call of that group, which a second run cannot share. Run a
    separate model (a System built anew) inside the function, or move the inner computation out of
    it. The outer run stops with this error (its ``solution`` holds the states before).

    Attributes:
        call: what was called ("simulate", "Simulation", "project_initial_state", ...).
        solution: the outer run's partial :class:`vinculo.Solution`, once it has stopped.
    """

    call: str | None = None
    solution: Any = None


class OutputTooLargeError(VinculoError, MemoryError):
    """The stored output of a run would not fit in the memory available.

    Raised by :func:`vinculo.simulate` and ``Simulation`` before a run starts when the states it
    would store (about ``(t_end - t_start) / dt / save_every`` of them, or ``len(t_eval)``, each of
    56 + 48 n + 8 m bytes for n particles and m constraint equations, plus 8 bytes per step for the
    step sizes) exceed ``max_output_bytes`` (default: half the memory available, since the output
    is copied once when it is returned), and during a run whose number of steps cannot be told
    beforehand (error-controlled steps) when its output reaches that size: then ``solution`` holds
    the states stored until then. Raise ``save_every``, give fewer ``t_eval`` times, shorten the
    run, or set ``max_output_bytes`` if you know better.

    Attributes:
        estimate: the stored output's size, in bytes (the estimate before the run, what was
            stored when it stopped during the run).
        limit: the largest output allowed, in bytes.
        states: the number of stored states it corresponds to.
        solution: the partial :class:`vinculo.Solution` when the run stopped during its steps.
    """

    estimate: int | None = None
    limit: int | None = None
    states: int | None = None
    solution: Any = None


class InternalError(VinculoError):
    """Something that should never happen happened inside vinculo.

    Raised when the core detects a broken internal invariant (a bug, not a user error). Please
    report it with the smallest model that reproduces it.
    """
