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
"""

from __future__ import annotations

from typing import Any

__all__ = [
    "ConvergenceError",
    "InconsistentInitialStateError",
    "InstabilityError",
    "InternalError",
    "InvalidInputError",
    "NegativeTensionError",
    "RedundantConstraintsError",
    "SchedulerError",
    "StepSizeTooSmallError",
    "UnknownHandleError",
    "UserFunctionError",
    "UserFunctionOutputError",
    "VinculoError",
]

# Attribute names that a detail must not overwrite (they belong to the exception machinery).
_RESERVED = frozenset({"args", "message", "details", "with_traceback", "add_note", "__notes__"})


def _rebuild(cls: type[VinculoError], message: str, details: dict[str, Any]) -> VinculoError:
    """Recreate an exception from its message and details (used by pickle)."""
    return cls(message, **details)


class VinculoError(Exception):
    """Root of every exception vinculo raises.

    Raised directly only for conditions no subclass describes; catch it to handle any vinculo error.

    Arguments:
        message: what went wrong, with the offending value, and what to do about it.
        **details: machine-readable facts about the error (for example ``name`` and ``value`` of a
            bad argument); each is stored as an attribute and in :attr:`details`.
    """

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


class InvalidInputError(VinculoError, ValueError):
    """An argument is out of its domain.

    Raised when building a model or starting a run with a value that cannot be simulated: a mass
    that is not finite and positive, a position or velocity containing NaN or infinity, a distance
    length that is not positive, a distance from a particle to itself, a plane with a zero normal,
    ``t_end`` before ``t_start``, a step ``dt`` that is not positive, ``alpha`` outside [1/2, 1],
    a non-positive tolerance, a tabulated law with too few or unsorted samples, and so on.
    Details usually include ``name`` (the argument) and ``value`` (what was given).
    """


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


class InternalError(VinculoError):
    """Something that should never happen happened inside vinculo.

    Raised when the core detects a broken internal invariant (a bug, not a user error). Please
    report it with the smallest model that reproduces it.
    """
