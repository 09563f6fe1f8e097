"""The keyword options of a run, the same for :func:`vinculo.simulate` and `vinculo.Simulation`."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, fields
from typing import Any

import numpy as np

from vinculo import _core, errors

__all__ = ["RunOptions"]


@dataclass(frozen=True, kw_only=True, eq=False)
class RunOptions:
    """How a run steps: the keyword options of :func:`vinculo.simulate` and
    :class:`vinculo.Simulation` (both take them as keyword arguments, with these names and
    defaults, and pass them to the compiled core as one ``RunSettings``, which checks every value's
    range). What the schemes and formulations discretise, and how a failing step is halved, is
    told by :func:`vinculo.simulate`. Options kept as an object are passed on as keywords:
    ``simulate(system, t_end, dt, **dataclasses.asdict(options))``.

    Arguments:
        scheme: 'trapezoidal' (the generalised trapezoidal rule with ``alpha``),
            'backward-euler' (the same rule with alpha = 1), or 'generalized-alpha' (the
            generalised-alpha scheme of Arnold and Brüls for index-3 systems: second order, with
            numerical damping of the high frequencies set by ``rho_inf``).
        rho_inf: spectral radius at infinite frequency of 'generalized-alpha', in [0, 1]
            (default 0.5 with the index-3 formulation, 0.9 with 'ggl'): 1 adds no numerical
            damping, 0 removes the highest frequencies in one step; the low frequencies are barely
            damped in every case. Index-3 generalised-alpha is unstable at coarse steps for large
            ``rho_inf`` (0.9 needs about 100 steps per period of the fastest resolved motion, 0.5
            about 10: docs/theory/time-rules.md), hence its smaller default; the GGL form is stable
            at every ``rho_inf`` measured.
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
        max_halvings: how many times a failing step may be halved before giving up (at most 30
            are made: dt / 2^30 is a billionth of dt; larger values mean 30). A halved step
            that the floating-point times cannot resolve (fewer than 50 spacings of t) stops
            the run with a ``StepSizeTooSmallError`` instead. A model with seabed contact has
            four more: its fixed steps go to each touchdown and lift-off of a node and through
            the transient it starts from dt / 16 (docs/theory/seabed-and-line-loads.md, contact
            events).
        initial_tolerance: largest initial violation accepted, relative to the model's scales:
            ``|s_k Phi_k| <= initial_tolerance * length_scale`` for positions and
            ``|s_k (Phi_q v + Phi_t)| <= initial_tolerance * speed`` for velocities, the speed being
            the largest initial speed or ``sqrt(|g| length_scale)``.
        save_every: store every k-th step (the last step is always stored); long runs of large
            models need it to keep the output in memory.
        jacobian_reuse: when Newton reuses a factorised iteration matrix instead of a new one.
            ``"auto"`` (default): the matrix is kept across iterations and steps while it shrinks
            the Newton increments by a tenth or better per iteration, and an iteration made with
            a kept matrix stops when the distance to the solution it bounds (the contraction
            mapping bound ``theta / (1 - theta) |dx|``) is below a thousandth of ``tolerance``;
            with a new matrix it stops as full Newton. A static chain factorises once per run, a
            swinging one about once a step, and the answer stays within about a thousandth of the
            tolerance per step of full Newton's (docs/theory/newton.md). ``True``: modified
            Newton, Exudyn's default mode: the matrix is kept while the increments shrink by
            half or better per iteration, after 8 iterations with one matrix a new one, and each
            step stops with an error near ``tolerance`` (full Newton stops far below it), which
            enters the velocities divided by ``dt`` (with small steps lower the tolerance).
            ``False``: full Newton (a new matrix every iteration). Every mode makes a new matrix
            when the step size changes, and a step that fails with an old matrix is retried once
            with a new one; ``Solution.factorisations`` counts the factorisations.
        adaptive: choose the step sizes by a local error estimate (on positions and velocities,
            not multipliers) and a PI controller so that each step meets ``rtol`` and ``atol``;
            ``dt`` is then the first step. False: fixed steps of ``dt`` (halved where Newton fails).
            The estimate is step doubling: each step is taken again as two half steps, whose
            difference gives its local error (three Newton solves per step); the run goes on
            from the two half steps' answer, the more accurate one. Its weighted RMS
            norm over the free coordinates, with the weights ``atol + rtol |q|`` for positions
            (counted per unit step: times ``T / h``, ``T = L / U``, ``L = system.length_scale()``,
            ``U`` the speed scale of ``initial_tolerance``) and ``atol U / L + rtol |v|`` for
            velocities (per step), must be <= 1. A rejected step is retried smaller
            (``Solution.steps_rejected`` counts them). Newton's tolerance is lowered to a
            hundredth of ``min(rtol, atol / L)`` when that is smaller. The position error of a run
            is then about proportional to the tolerance, from 1e-3 down to 1e-10 (measured: 2 to
            12 times it for the trapezoidal rule, up to 50 for generalised-alpha on runs of 5 to 6
            time scales ``T``; docs/theory/adaptive.md). Index-3 velocities drift off the
            velocity constraints by more: ``formulation='ggl'`` holds them.
        rtol: relative tolerance of adaptive steps, in (0, 1).
        atol: absolute tolerance of adaptive steps, in m (positions).
        h_min: smallest adaptive step, in s: a run that would need a smaller one stops with
            :class:`StepSizeTooSmallError`.
        h_max: largest adaptive step, in s (default: no limit).
        t_eval: times at which to return the state (strictly increasing, within
            ``[t_start, t_end]``), with fixed or adaptive steps, interpolated inside the step that
            contains each (cubic Hermite positions, its derivative for velocities, linear
            multipliers) without forcing the steps onto them; a time on a step's end is that
            step's state. Default: the state after every accepted step (every
            ``save_every``-th).
        max_output_bytes: the largest memory the stored output may take, in bytes (default:
            a third of the memory available, ``MemAvailable`` of ``/proc/meminfo``, since the
            arrays grow by doubling and are copied once when returned; no limit where it cannot
            be read; an output of at most 16 MiB is not checked against it). A run whose output
            would be larger (about ``(t_end - t_start) / dt / save_every`` states, or
            ``len(t_eval)``, of 56 + 48 n + 8 m bytes each for n particles and m constraint
            equations, and 8 bytes per step) is refused before it starts with
            :class:`OutputTooLargeError`; an error-controlled run, whose number of steps is known
            only as it goes, stops with that error when its output reaches the limit
            (``solution`` keeps what it stored).
        linear_solver: how the Newton iteration matrix is factorised. 'auto' (default): the
            block elimination along the particle graph's tree (linear cost: chains, branched
            strings, lines with bending stiffness, whose couplings join a particle and its
            ancestors in a spanning tree of the constraints) where the matrix's pattern allows
            it, else a dense LU up to 48 unknowns and the general sparse LU (faer) above.
            'sparse-lu': never the tree elimination (the dense LU up to 48 unknowns, the general
            sparse LU above), to compare the two. ``Solution.linear_solver`` names the one used.
    """

    scheme: str = "trapezoidal"
    rho_inf: float | None = None
    formulation: str = "index-3"
    t_start: float = 0.0
    tolerance: float = 1e-10
    max_iterations: int = 25
    max_halvings: int = 4
    initial_tolerance: float = 1e-8
    save_every: int = 1
    jacobian_reuse: bool | str = "auto"
    adaptive: bool = False
    rtol: float = 1e-6
    atol: float = 1e-6
    h_min: float = 1e-10
    h_max: float | None = None
    t_eval: Sequence[float] | np.ndarray | None = None
    max_output_bytes: float | None = None
    linear_solver: str = "auto"

    @classmethod
    def of(cls, caller: str, options: dict[str, Any]) -> RunOptions:
        """The options a caller was given as keyword arguments.

        Arguments:
            caller: the function or class that took them, for the message of an unknown name.
            options: the keyword arguments.

        Returns:
            The options, the defaults where a keyword was not given.

        Raises:
            TypeError: a keyword that is not an option (as for any unknown keyword argument); the
                message lists the options.
        """
        known = _NAMES
        unknown = [name for name in options if name not in known]
        if unknown:
            raise TypeError(
                f"{caller}() got an unexpected keyword argument {unknown[0]!r}; "
                f"its run options are {', '.join(known)} (see vinculo.RunOptions)"
            )
        return cls(**options)

    def _jacobian_reuse(self) -> bool | None:
        """``jacobian_reuse`` as the core takes it: None for ``"auto"``."""
        value = self.jacobian_reuse
        if isinstance(value, str) and value == "auto":
            return None
        if isinstance(value, (bool, np.bool_)):
            return bool(value)
        raise errors.InvalidInputError(
            f"jacobian_reuse must be 'auto' (the default), True (modified Newton) or False (full "
            f"Newton), got {value!r}",
            name="jacobian_reuse",
            value=value,
        )

    def settings(self, t_end: float, dt: float, alpha: float | None) -> _core.RunSettings:
        """The settings of a run to ``t_end`` with steps ``dt`` and these options, as one object
        of the compiled core (its ``SimulationOptions``, checked once).

        The core checks every value's range; this checks first what Python must convert: the
        names are strings and ``t_eval`` is one-dimensional.

        Arguments:
            t_end: final time, in s.
            dt: step size, in s (the first step with ``adaptive=True``).
            alpha: parameter of the generalised trapezoidal rule (None: its default, 1/2).

        Returns:
            The core's ``RunSettings``, taken by ``_core.simulate`` and ``_core.Simulation``.

        Raises:
            InvalidInputError: ``scheme``, ``formulation`` or ``linear_solver`` is not a string,
                ``jacobian_reuse`` is not ``"auto"``, True or False, ``t_eval`` is not a 1-D
                sequence of times, or a value is out of its range (checked by the core).
        """
        if not isinstance(self.scheme, str):
            raise errors.InvalidInputError(
                f"scheme must be a name ('trapezoidal', 'backward-euler' or 'generalized-alpha'), "
                f"got {self.scheme!r}",
                name="scheme",
                value=self.scheme,
            )
        if not isinstance(self.formulation, str):
            raise errors.InvalidInputError(
                f"formulation must be a name ('index-3' or 'ggl'), got {self.formulation!r}",
                name="formulation",
                value=self.formulation,
            )
        if not isinstance(self.linear_solver, str):
            raise errors.InvalidInputError(
                f"linear_solver must be a name ('auto' or 'sparse-lu'), got {self.linear_solver!r}",
                name="linear_solver",
                value=self.linear_solver,
            )
        times = None
        if self.t_eval is not None:
            array = np.asarray(self.t_eval, dtype=np.float64)
            if array.ndim != 1:
                raise errors.InvalidInputError(
                    f"t_eval must be a 1-D sequence of times, got an array of shape {array.shape}",
                    name="t_eval",
                    value=self.t_eval,
                )
            times = [float(x) for x in array]
        options = {name: getattr(self, name) for name in _NAMES}
        options.update(
            jacobian_reuse=self._jacobian_reuse(), adaptive=bool(self.adaptive), t_eval=times
        )
        return _core.RunSettings(t_end, dt, alpha, **options)


#: The options' names, in their order (read once: ``dataclasses.fields`` takes microseconds a
#: call, which every run would pay twice).
_NAMES = tuple(field.name for field in fields(RunOptions))
