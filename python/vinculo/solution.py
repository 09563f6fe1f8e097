"""The result of a simulation: trajectories, multipliers and solver statistics."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from vinculo import _core
from vinculo._core import ConstraintId, ParticleId, Point, System
from vinculo.errors import InvalidInputError, UnknownHandleError

__all__ = ["Solution"]

_ARRAY_FIELDS = (
    "times",
    "positions",
    "velocities",
    "multipliers",
    "constraint_residual",
    "velocity_violation",
    "newton_iterations",
    "step_sizes",
    "residual_norms",
    "increment_norms",
)


def _read_only(array: np.ndarray, dtype: Any) -> np.ndarray:
    """``array`` (a fresh array, shared with nobody) with the given dtype, made read-only."""
    result = np.asarray(array, dtype=dtype)
    result.flags.writeable = False
    return result


def _description(error: BaseException | None) -> dict[str, Any] | None:
    """The description of the error that stopped a run (:attr:`Solution.error`): the exception's
    class name as 'kind', its message, and its details but the partial solution."""
    if error is None:
        return None
    details = getattr(error, "details", {})
    return {
        "kind": type(error).__name__,
        "message": getattr(error, "message", str(error)),
        **{key: value for key, value in details.items() if key != "solution"},
    }


@dataclass(frozen=True, eq=False)
class Solution:
    """Everything one call of :func:`vinculo.simulate` computed.

    Row 0 of every array is the initial state (0 Newton iterations, step size 0, multipliers from
    the consistent initial accelerations); row ``k`` is the state after step ``k``. With
    ``simulate(..., t_eval=...)`` the rows are the requested times instead
    (interpolated inside the steps that contain them; the initial state is a row only when
    ``t_start`` is requested), and the per-row statistics are those of the containing step. The
    arrays are read-only.

    Attributes:
        times: (s,) times of the stored states, in s.
        positions: (s, n, 3) particle positions, in m.
        velocities: (s, n, 3) particle velocities, in m/s.
        multipliers: (s, m) Lagrange multipliers, one column per constraint equation. The force of
            constraint k on the particles is ``Phi_q[k]^T lambda_k``.
        constraint_residual: (s,) ``max_k |s_k Phi_k|`` at each stored time, in m (``s_k`` is the
            constraint's scale, see ``System.constraint_scales``): the position-level
            violation, at the Newton tolerance or below (also :attr:`position_violation`).
        velocity_violation: (s,) ``max_k |s_k (Phi_q v + Phi_t)|`` at each stored time, in m/s:
            the velocity-level violation. With ``formulation='index-3'`` the schemes enforce the
            position constraints only, so the velocities drift off the velocity constraints by an
            amount that shrinks with the step: a measure of the run's accuracy. With
            ``formulation='ggl'`` both levels hold at every step, to the Newton tolerance.
        newton_iterations: (s,) Newton iterations of each step.
        step_sizes: (s,) size of each step, in s (smaller than ``dt`` where steps were halved).
        residual_norms: (s,) the last scaled residual norm each step's Newton solve evaluated:
            at the step's answer, or at the iterate before its last increment when Newton stopped
            on that increment (docs/theory/newton.md).
        increment_norms: (s,) norm of each step's last Newton increment.
        error: None after a complete run; for the partial solution carried by a
            :class:`vinculo.ConvergenceError`, the core's description of the failure (keys
            'kind', 'message', 'time', 'step_size', 'residual', 'iterations', 'equation').
        system: a copy of the :class:`vinculo.System` that was simulated, taken when the run
            ended (:meth:`vinculo.System.copy`): later edits of the original do not reach it.
        linear_solver: the linear solver the run used: 'dense LU' (small systems),
            'tree elimination' (tree-shaped constraint graphs: chains, ropes, branched strings,
            lines with bending stiffness) or 'sparse LU' (graphs with loops across branches;
            every GGL run above the dense size; ``linear_solver='sparse-lu'``).
        factorisations: number of Newton iteration matrices factorised over the run (one per
            Newton iteration in full Newton, ``jacobian_reuse=False``; fewer with the default,
            which keeps a matrix while it contracts fast, and with modified Newton).
        residual_evaluations: number of evaluations of the step equations' residual by Newton's
            iterations over the run, rejected steps included (a step makes one more than its
            iterations, or as many when Newton stops on its last increment because the residual
            it was solved from already met the tolerance; docs/theory/newton.md).
        scheme: the time discretisation: 'trapezoidal', 'backward-euler' or 'generalized-alpha'.
        steps_taken: steps attempted, including those rejected and retried.
        steps_rejected: attempts rejected (Newton failed, or the error estimate of an
            error-controlled step exceeded the tolerance).
        accepted_step_sizes: size of every accepted step, in s, whether its state was stored or
            not (its length is :attr:`steps_accepted`).
        formulation: the equations discretised: 'index-3' or 'ggl'.
    """

    times: np.ndarray
    positions: np.ndarray
    velocities: np.ndarray
    multipliers: np.ndarray
    constraint_residual: np.ndarray
    velocity_violation: np.ndarray
    newton_iterations: np.ndarray
    step_sizes: np.ndarray
    residual_norms: np.ndarray
    increment_norms: np.ndarray
    error: dict[str, Any] | None
    system: System
    linear_solver: str = ""
    factorisations: int = 0
    residual_evaluations: int = 0
    scheme: str = ""
    steps_taken: int = 0
    steps_rejected: int = 0
    accepted_step_sizes: np.ndarray = field(
        default_factory=lambda: _read_only(np.empty(0), np.float64)
    )
    formulation: str = ""

    @classmethod
    def from_core(cls, result: _core.RunResult, system: System) -> Solution:
        """Build a solution from the run returned by ``vinculo._core.simulate``.

        Arguments:
            result: the core's ``RunResult`` (its arrays are fresh read-only copies).
            system: the system that was simulated.

        Returns:
            The solution; for a run that stopped early, :attr:`error` describes the exception of
            ``result.error``.
        """
        # The core's arrays are fresh copies, read-only and of the dtypes of the fields.
        arrays = {name: getattr(result, name) for name in _ARRAY_FIELDS}
        return cls(
            **arrays,
            error=_description(result.error),
            system=system,
            linear_solver=result.linear_solver,
            factorisations=result.factorisations,
            residual_evaluations=result.residual_evaluations,
            scheme=result.scheme,
            steps_taken=result.steps_taken,
            steps_rejected=result.steps_rejected,
            accepted_step_sizes=result.accepted_step_sizes,
            formulation=result.formulation,
        )

    @property
    def success(self) -> bool:
        """True if the run reached ``t_end``."""
        return self.error is None

    @property
    def position_violation(self) -> np.ndarray:
        """(s,) ``max_k |s_k Phi_k|`` at each stored time, in m (the same array as
        :attr:`constraint_residual`)."""
        return self.constraint_residual

    @property
    def num_steps(self) -> int:
        """Number of stored states less the initial one (the completed steps when every step is
        stored; see :attr:`steps_accepted` otherwise)."""
        return max(len(self.times) - 1, 0)

    @property
    def steps_accepted(self) -> int:
        """Number of accepted steps (stored or not)."""
        return len(self.accepted_step_sizes)

    def particle(self, particle: ParticleId) -> np.ndarray:
        """Trajectory of one particle.

        Arguments:
            particle: the handle returned by ``System.add_particle``.

        Returns:
            (s, 3) positions of that particle at the stored times (a read-only view).

        Raises:
            UnknownHandleError: if ``particle`` is not a ParticleId of this system.
        """
        index = self._index(particle, ParticleId, self.positions.shape[1], "particle")
        return self.positions[:, index, :]

    def point(self, point: Point) -> np.ndarray:
        """Trajectory of a point fixed in a body or in the ground (``System.point``).

        Arguments:
            point: the point (a combination of particles with constant weights).

        Returns:
            (s, 3) positions of the point at the stored times.

        Raises:
            InvalidInputError: if the point uses a particle this solution does not have.
        """
        return self._combine(point, self.positions, offset=True)

    def point_velocity(self, point: Point) -> np.ndarray:
        """Velocity history of a point fixed in a body or in the ground (``System.point``).

        Arguments:
            point: the point.

        Returns:
            (s, 3) velocities of the point at the stored times.

        Raises:
            InvalidInputError: if the point uses a particle this solution does not have.
        """
        return self._combine(point, self.velocities, offset=False)

    def _combine(self, point: Point, values: np.ndarray, offset: bool) -> np.ndarray:
        """sum_k w_k values[:, p_k] (+ the point's constant position when ``offset``)."""
        weights = point.weights
        count = values.shape[1]
        if any(p >= count for p, _ in weights):
            raise InvalidInputError(
                f"{point!r} uses a particle this solution of {count} particles does not have",
                name="point",
                value=point,
            )
        out = np.zeros((values.shape[0], 3))
        if offset:
            out += np.asarray(point.position(np.zeros((count, 3))))
        for p, w in weights:
            out += w * values[:, p, :]
        return out

    def particle_velocity(self, particle: ParticleId) -> np.ndarray:
        """Velocity history of one particle.

        Arguments:
            particle: the handle returned by ``System.add_particle``.

        Returns:
            (s, 3) velocities of that particle at the stored times (a read-only view).

        Raises:
            UnknownHandleError: if ``particle`` is not a ParticleId of this system.
        """
        index = self._index(particle, ParticleId, self.velocities.shape[1], "particle")
        return self.velocities[:, index, :]

    def multiplier(self, constraint: ConstraintId) -> np.ndarray:
        """Lagrange multiplier of a constraint's first equation.

        Arguments:
            constraint: the handle returned by ``System.add_*`` for a constraint.

        Returns:
            (s,) multiplier history. For a distance constraint ``Phi = L^2 - |q_a - q_b|^2`` a
            positive value is tension; see :meth:`distance_tension`.

        Raises:
            UnknownHandleError: if ``constraint`` is not a ConstraintId of this system.
        """
        index = self._index(constraint, ConstraintId, self.multipliers.shape[1], "constraint")
        return self.multipliers[:, index]

    def distance_tension(self, constraint: ConstraintId, length: float | None = None) -> np.ndarray:
        """Tension in a distance constraint (a massless rigid link).

        With ``Phi = L^2 - |q_a - q_b|^2`` the constraint force on ``a`` is
        ``-2 lambda (q_a - q_b)``, of magnitude ``2 lambda L``: positive values pull the two ends
        together (tension), negative values push them apart (compression).

        Arguments:
            constraint: the handle returned by ``add_distance`` or ``add_distance_to_point``.
            length: the constraint's length L, in m (None: the length the system holds).

        Returns:
            (s,) tension in N.

        Raises:
            UnknownHandleError: if ``constraint`` is not a ConstraintId of this system.
            InvalidInputError: ``length`` is None and the constraint is not a distance.
        """
        multiplier = self.multiplier(constraint)
        if length is None:
            length = float(self.system.constraint_lengths[constraint.index])
            if not np.isfinite(length):
                raise InvalidInputError(
                    f"constraint {constraint.index} is not a distance: it has no tension",
                    name="constraint",
                    value=constraint.index,
                )
        return 2.0 * multiplier * float(length)

    def kinetic_energy(self) -> np.ndarray:
        """Kinetic energy ``sum 1/2 m |v|^2`` at each stored time.

        Returns:
            (s,) energies in J.
        """
        return np.asarray(self.system.kinetic_energy(self.velocities), dtype=np.float64)

    def potential_energy(self) -> np.ndarray:
        """Potential energy of gravity and springs at each stored time.

        Returns:
            (s,) energies in J (gravity relative to the origin).
        """
        return np.asarray(self.system.potential_energy(self.positions), dtype=np.float64)

    def energy(self) -> np.ndarray:
        """Total mechanical energy (kinetic plus potential) at each stored time.

        Returns:
            (s,) energies in J. Without dissipative or time-dependent forces and constraints it is
            conserved by the exact motion; alpha > 1/2 makes it decay.
        """
        return self.kinetic_energy() + self.potential_energy()

    def save_netcdf(self, path: Any, *, attributes: dict[str, Any] | None = None) -> Any:
        """Write this run to a NetCDF4 file (see :func:`vinculo.io.save_netcdf`).

        Arguments:
            path: the file to write, ending in ``.nc`` or ``.nc4``.
            attributes: parameters of the run to store as file attributes.

        Returns:
            The path written (a :class:`pathlib.Path`).

        Raises:
            InvalidInputError: a bad path or an attribute that cannot be stored.
        """
        from vinculo.io.netcdf import save_netcdf

        return save_netcdf(self, path, attributes=attributes)

    def summary(self) -> str:
        """A short readable account of the run.

        Returns:
            Several lines: outcome, steps, the largest constraint residual, Newton iterations per
            step and the smallest step size.
        """
        lines = []
        if self.success:
            lines.append(f"completed: t = {self.times[0]:.6g} .. {self.times[-1]:.6g} s")
        else:
            assert self.error is not None
            stop = self.times[-1] if len(self.times) else float("nan")
            outcome = "INTERRUPTED" if self.error.get("kind") == "Interrupted" else "FAILED"
            lines.append(f"{outcome} at t = {stop:.6g} s: {self.error.get('message', '')}")
        lines.append(
            f"steps: {self.num_steps} ({self.system.num_particles} particles, "
            f"{self.system.num_constraints} constraint equations)"
        )
        if self.num_steps > 0:
            iterations = self.newton_iterations[1:]
            lines.append(f"max constraint residual: {np.max(self.constraint_residual):.3e} m")
            lines.append(
                f"max velocity-constraint residual: {np.max(self.velocity_violation):.3e} m/s"
            )
            lines.append(
                f"Newton iterations per step: mean {np.mean(iterations):.2f}, "
                f"max {int(np.max(iterations))}"
            )
            sizes = self.accepted_step_sizes
            sizes = sizes if len(sizes) else self.step_sizes[1:]
            lines.append(f"min step size: {np.min(sizes):.6g} s")
        if self.linear_solver:
            lines.append(f"linear solver: {self.linear_solver}")
        return "\n".join(lines)

    def __repr__(self) -> str:
        status = "success" if self.success else "failed"
        if self.error is not None and self.error.get("kind") == "Interrupted":
            status = "interrupted"
        return (
            f"Solution({status}, steps={self.num_steps}, particles={self.positions.shape[1]}, "
            f"constraint equations={self.multipliers.shape[1]})"
        )

    @staticmethod
    def _index(handle: Any, kind: type, size: int, what: str) -> int:
        """Check a handle's type and range and return its index."""
        if not isinstance(handle, kind):
            raise UnknownHandleError(
                f"expected a {kind.__name__}, got {handle!r} ({type(handle).__name__}); "
                f"use the handle returned when the {what} was added",
                name=what,
                value=handle,
            )
        index = int(handle.index)
        if not 0 <= index < size:
            raise UnknownHandleError(
                f"{kind.__name__} with index {index} is not in this solution "
                f"(it has {size}); was the handle made by another System?",
                name=what,
                value=index,
            )
        return index
