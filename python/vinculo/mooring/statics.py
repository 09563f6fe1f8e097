"""The static equilibrium of a system of lines and points, and its stiffness at a point.

:func:`solve_statics` finds the positions and the multipliers (the segments' tensions) where
every free particle is in equilibrium at rest: Newton's method on the equilibrium equations with
their analytic Jacobian (the assembly of a time step with the mass terms dropped), and, when it
fails (slack lines, lines lying on the seabed), pseudo-transient continuation: damped implicit
pseudo-steps whose damping decreases as the residual does, finished by Newton's method
(``docs/theory/moorings.md``). Both keep every segment able to push, and refuse an equilibrium
with a compressed segment (the continuation buckles such a line down); where it cannot buckle
(spare tether standing on its anchor, stiff in bending), the continuation runs again with the
segments slack while shorter than their length, as in a run. The result does not depend on any
time step. Friction, which depends on the sliding velocity, is zero at rest, as in MoorDyn's
initial conditions.

:func:`point_stiffness` gives the 3x3 linearised stiffness ``K = -dF/dx`` at a point from the
same analytic Jacobian (its Schur complement on the point), the other particles staying in
equilibrium; :func:`points_stiffness` the joint one of several points.

Example:
    >>> import vinculo
    >>> from vinculo.mooring.statics import solve_statics
    >>> s = vinculo.System(gravity=(0.0, 0.0, -9.81))
    >>> top = s.add_particle(1.0, (0.0, 0.0, 0.0), fixed=True)
    >>> mass = s.add_particle(2.0, (0.0, 0.0, -1.0))
    >>> segment = s.add_elastic_distance(top, mass, 1.0, 1e4)
    >>> eq = solve_statics(s)
    >>> round(float(eq.positions[1, 2]), 6), round(float(eq.multipliers[0]), 6)
    (-1.001962, 19.62)
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from vinculo import _core


@dataclass
class Statics:
    """A static equilibrium.

    Arguments:
        positions: ``(particles, 3)`` positions (m); fixed particles where they are.
        multipliers: ``(constraints,)`` multipliers; an elastic segment's is its tension (N).
        residual: the final scaled residual (m).
        iterations: the Newton iterations made in all.
        method: ``"newton"``, ``"continuation"`` when Newton's method alone failed, or
            ``"slack continuation"`` when the continuation with every segment able to push did
            not end (the module documentation).
        t: the time at which it holds (the laws of winches and prescribed points at ``t``).
    """

    positions: np.ndarray
    multipliers: np.ndarray
    residual: float
    iterations: int
    method: str
    t: float = 0.0

    def apply(self, system: Any) -> None:
        """Make the equilibrium the initial state of ``system`` (at rest).

        Arguments:
            system: the :class:`vinculo.System` it was solved for.
        """
        system.set_initial_state(self.positions, np.zeros_like(self.positions))


def solve_statics(system: Any, *, tolerance: float = 1e-9, max_iterations: int = 1000,
                  t: float = 0.0, newton_first: bool = True, apply: bool = True) -> Statics:
    """The static equilibrium of ``system``, from its initial positions.

    Arguments:
        system: the :class:`vinculo.System`.
        tolerance: on the scaled residual and increment, relative to the model's length scale.
            Where the residual's own round-off is larger (a stiff bending line far from the
            origin), Newton stops at that round-off once its increments stop shrinking.
        max_iterations: the largest number of Newton iterations of Newton's method and the
            continuation in all, and of the continuation with slack segments.
        t: the time at which the laws (winches, prescribed points) are evaluated.
        newton_first: try Newton's method first (False: the continuation at once).
        apply: make the equilibrium the system's initial state (at rest).

    Returns:
        The :class:`Statics`.

    Raises:
        ConvergenceError: when neither Newton's method nor either continuation converges.
        InvalidInputError: for a tolerance or iteration count out of range.
    """
    positions, multipliers, residual, iterations, method = _core.solve_statics(
        system, tolerance, max_iterations, t, newton_first)
    result = Statics(positions=np.asarray(positions), multipliers=np.asarray(multipliers),
                     residual=float(residual), iterations=int(iterations), method=method, t=t)
    if apply:
        result.apply(system)
    return result


def point_stiffness(system: Any, statics: Statics, particle: int) -> np.ndarray:
    """The linearised stiffness ``K = -dF/dx`` (N/m) of ``system`` at a point.

    ``F`` is the force that the system's elements exert on the point, and the other free
    particles stay in equilibrium as it moves; a restoring mooring has a positive definite
    ``K`` (a spring's sign). A fixed point is freed for the computation.

    Arguments:
        system: the :class:`vinculo.System`.
        statics: its equilibrium (:func:`solve_statics`).
        particle: the point's particle index.

    Returns:
        ``(3, 3)`` stiffness, ``K[i, j] = -dF_i/dx_j``.

    Raises:
        ConvergenceError: when the equilibrium's Jacobian is singular at the point (an
            inextensible taut line is infinitely stiff along itself).
    """
    return np.asarray(_core.point_stiffness(system, statics.positions, statics.multipliers,
                                            int(particle), statics.t))


def points_stiffness(system: Any, statics: Statics, particles: list[int]) -> np.ndarray:
    """The joint linearised stiffness (N/m) of ``system`` at several points.

    The ``(3n, 3n)`` matrix of blocks ``K[3i:3i+3, 3j:3j+3] = -dF_i/dx_j``: ``F_i`` the force of
    the system's elements on point i (:func:`point_force`) as point j moves, the other points
    held and every other free particle in equilibrium (``docs/theory/moorings.md``). Its diagonal
    blocks are :func:`point_stiffness` of each point; its off-diagonal blocks couple points
    joined through the system (the two fairleads of a bridle). Fixed points are freed for the
    computation.

    Arguments:
        system: the :class:`vinculo.System`.
        statics: its equilibrium (:func:`solve_statics`).
        particles: the points' particle indices, each once.

    Returns:
        ``(3n, 3n)`` stiffness.

    Raises:
        ConvergenceError: when the equilibrium's Jacobian, or its inverse's block on the points,
            is singular (an inextensible taut line between two of them).
        InvalidInputError: for no points, an index out of range or a point listed twice.
    """
    return np.asarray(_core.points_stiffness(system, statics.positions, statics.multipliers,
                                             [int(p) for p in particles], statics.t))


def point_force(system: Any, statics: Statics, particle: int) -> np.ndarray:
    """The force (N) that the system's elements exert on a particle in an equilibrium: its
    constraints through their multipliers and its forces at rest; not gravity on the particle.

    Arguments:
        system: the :class:`vinculo.System`.
        statics: its equilibrium.
        particle: the particle index.

    Returns:
        ``(3,)`` force (N).
    """
    return np.asarray(_core.point_force(system, statics.positions, statics.multipliers,
                                        int(particle), statics.t))
