"""Type stubs of vinculo's compiled core (the PyO3 extension ``vinculo._core``).

Users import from ``vinculo``; this module is the thin layer the Python package is built on.
"""
from typing import Any, Callable, Sequence, Union

import numpy as np
import numpy.typing as npt

from vinculo.errors import VinculoError

class Law:
    """A prescribed scalar function of time with its first and second derivatives.

    Built by the constructors ``Law.constant``, ``Law.polynomial``, ``Law.sine``, ``Law.tabulated``,
    ``Law.spline``, ``Law.piecewise_linear``, ``Law.driven``, ``Law.apply`` and ``Law.function``, and
    composed with ``+ - * / **`` (between laws and numbers).
    """
    @staticmethod
    def constant(value: float) -> "Law":
        """value at every time (rate and acceleration 0)."""
    @staticmethod
    def polynomial(coefficients: Sequence[float]) -> "Law":
        """c0 + c1 t + c2 t^2 + ...  (coefficients in increasing powers)."""
    @staticmethod
    def sine(amplitude: float, frequency: float, phase: float = 0.0, offset: float = 0.0,
             ramp_time: float = 0.0, t_start: float = 0.0) -> "Law":
        """offset + amplitude s(t) sin(2 pi frequency (t - t_start) + phase); s is a C2 quintic ramp
        from 0 at t_start to 1 at t_start + ramp_time (s = 1 when ramp_time = 0)."""
    @staticmethod
    def tabulated(times: Sequence[float], values: Sequence[float]) -> "Law":
        """Natural cubic spline through the samples (C2). Runs must stay within [times[0], times[-1]];
        evaluated outside, the spline continues along its end tangents."""
    @staticmethod
    def spline(times: Sequence[float], values: Sequence[float], ends: str = "natural",
               slopes: tuple[float, float] | None = None) -> "Law":
        """Cubic spline through the samples with end condition "natural", "clamped" (with the end
        slopes) or "not-a-knot"."""
    @staticmethod
    def apply(name: str, law: Scalar, exponent: float | None = None) -> "Law":
        """name(law) for "sqrt", "sin", "cos", "exp", "log", or law ** exponent for "power"."""
    @staticmethod
    def function(function: Callable[[float], tuple[float, float, float]],
                 name: str | None = None) -> "Law":
        """A law computed by a Python function t -> (value, rate, acceleration)."""
    def __add__(self, other: Scalar) -> "Law": ...
    def __radd__(self, other: Scalar) -> "Law": ...
    def __sub__(self, other: Scalar) -> "Law": ...
    def __rsub__(self, other: Scalar) -> "Law": ...
    def __mul__(self, other: Scalar) -> "Law": ...
    def __rmul__(self, other: Scalar) -> "Law": ...
    def __truediv__(self, other: Scalar) -> "Law": ...
    def __rtruediv__(self, other: Scalar) -> "Law": ...
    def __pow__(self, exponent: float) -> "Law": ...
    def __neg__(self) -> "Law": ...
    def __pos__(self) -> "Law": ...
    @staticmethod
    def piecewise_linear(times: Sequence[float], values: Sequence[float]) -> "Law":
        """Linear interpolation between knots (left-continuous rate), at rest outside them.

        Arguments:
            times: strictly increasing knot times (at least one).
            values: the value at each knot.

        Returns:
            The law.

        Raises:
            InvalidInputError: lengths differ, no knot, times not increasing, a value not finite.
        """
    @staticmethod
    def driven(x: float, t: float = 0.0) -> "Law":
        """A piecewise-linear law whose values are set while a run is stepped.

        Arguments:
            x: the value at time t (and before).
            t: the time of the first value, in s.

        Returns:
            The law (``set`` adds values; copies of it share them).

        Raises:
            InvalidInputError: a number is not finite.
        """
    def set(self, t: float, x: float) -> None:
        """Set a driven law's value at time t: the law moves linearly to it from the last value.

        Arguments:
            t: the time, in s (after the last time set).
            x: the value at t.

        Raises:
            InvalidInputError: the law is not driven, t is not after the last time set, or a
                number is not finite.
        """
    def __call__(self, t: float) -> float:
        """The law's value at time t."""
    def derivatives(self, t: float) -> tuple[float, float, float]:
        """(value, first derivative, second derivative) at t."""
    def domain(self) -> tuple[float, float]:
        """Interval of time on which the law is defined (-inf, inf for analytic laws)."""

Scalar = Union[float, Law]
Vector = Sequence[Scalar]

class ParticleId:
    """Handle of a particle, returned by ``System.add_particle``; valid only with its system."""
    index: int
    """Position of the particle in the system (row of ``Solution.positions``)."""
class Point:
    """A point fixed in a body (an affine combination of its particles, constant weights) or in
    the ground, returned by ``System.point``. Every constraint and force method accepts it where
    it accepts a ParticleId (docs/theory/mechanisms.md)."""
    weights: list[tuple[int, float]]
    """The particles it combines, as (particle index, weight) pairs (none for a ground point)."""
    def position(self, positions: Sequence[Sequence[float]]) -> tuple[float, float, float]:
        """Its world position for the positions (n, 3) of every particle of its system.

        Arguments:
            positions: the positions of all particles (rows of ``Solution.positions``).

        Returns:
            The point's position (m).

        Raises:
            InvalidInputError: fewer rows than the point's particles need.
        """
class ConstraintId:
    """Handle of a constraint, returned by the ``System.add_*`` constraint methods."""
    index: int
    """Index of the constraint's first equation in the multiplier array."""
class ForceId:
    """Handle of a force element, returned by the ``System.add_*`` force methods."""
    index: int
    """Position of the force element in the system."""

class UserGroup:
    """A group of user-defined forces or constraints (``System.add_force_group`` /
    ``System.add_constraint_group``)."""
    name: str
    kind: str
    """"force" or "constraint"."""
    arity: int
    constraint_indices: list[int]
    """Equations of a constraint group (columns of ``Solution.multipliers``)."""
    calls: dict[str, int]
    """Calls of each function during the last run: "force", "jacobian"; or "phi", "gradient",
    "hessian", "phi_t", "gamma". Finite-difference evaluations count as calls of the function
    they evaluate."""
    seconds: dict[str, float]
    """Wall time in each function during the last run, the crossing (GIL, array copies, shape
    checks) included."""
    def __len__(self) -> int: ...
    def evaluate(self, call: str, t: float, q: npt.ArrayLike, v: npt.ArrayLike | None = None,
                 finite_differences: bool = False) -> Any:
        """Function ``call`` of the group at (t, q, v) as the core evaluates it (counts and caches
        untouched): "force" -> forces; "jacobian" -> (df_dq, df_dv); "phi", "gradient",
        "hessian", "phi_t", "gamma" -> that term. ``finite_differences=True``: the core's
        finite-difference value instead of the user function (compare the two to check a
        derivative)."""

class System:
    """A model: particles, constraints and forces, reached through typed handles.

    Arguments:
        gravity: the uniform gravity vector (m/s^2), e.g. ``(0, 0, -9.81)``; it acts on every
            particle's mass (not on added mass).

    Raises:
        InvalidInputError: a gravity that is not three finite numbers.
    """
    def __init__(self, gravity: Sequence[float] = (0.0, 0.0, 0.0)) -> None: ...
    def copy(self) -> System:
        """An independent copy of the system as it is now; handles of this system work with it."""
    def __copy__(self) -> System: ...
    def add_particle(self, mass: float, position: Sequence[float],
                     velocity: Sequence[float] = (0.0, 0.0, 0.0), fixed: bool = False) -> ParticleId:
        """Add a point mass.

        Arguments:
            mass: the mass (kg, > 0).
            position: the initial position (m), three finite numbers.
            velocity: the initial velocity (m/s).
            fixed: a fixed particle never moves and carries no unknowns (a pivot, an anchor).

        Returns:
            The particle's handle.

        Raises:
            InvalidInputError: a mass <= 0 or a non-finite position or velocity.
        """
    def add_distance(self, a: ParticleId | Point, b: ParticleId | Point, length: float | None = None) -> ConstraintId:
        """A rigid link between two particles: Phi = L^2 - |q_a - q_b|^2 (paper eq. 17).

        The multiplier lambda is positive in tension; the tension is 2 lambda L
        (``Solution.distance_tension``).

        Arguments:
            a: one end.
            b: the other end.
            length: L (m, > 0); None: the current distance.

        Returns:
            The constraint's handle (one equation).

        Raises:
            InvalidInputError: a == b, or a length that is not finite and positive.
            UnknownHandleError: a handle of another system.
        """
    def add_elastic_distance(self, a: ParticleId | Point, b: ParticleId | Point, length: float | Law, ea: float,
                             share: float = 1.0) -> ConstraintId:
        """An elastic segment: |q_a - q_b| = l + (l / EA) T, its multiplier the tension T
        (docs/theory/moorings.md).

        Arguments:
            a: one end.
            b: the other end.
            length: the unstretched length (m), or a law of time (a winch).
            ea: the axial stiffness EA (N, > 0); ``math.inf``: inextensible.
            share: the segment's share of ``length``, l = share length(t) (in (0, 1]; a line of
                n segments on one winch law gives each 1/n).

        Returns:
            The constraint's handle (one equation; its multiplier is the tension in N).

        Raises:
            InvalidInputError: a == b, a length that is not positive at t = 0, a share out of
                (0, 1] or an EA that is not positive.
            UnknownHandleError: a handle of another system.
        """
    def add_distance_to_point(self, particle: ParticleId | Point, point: Vector,
                              length: float | None = None) -> ConstraintId:
        """A link from a particle to a prescribed point p(t): Phi = L^2 - |q - p(t)|^2.

        Arguments:
            particle: the particle.
            point: p(t) (m), each component a number or a Law (an anchor on a moving floor).
            length: L (m, > 0); None: the current distance at t = 0.

        Returns:
            The constraint's handle (one equation; tension 2 lambda L).

        Raises:
            InvalidInputError: a length that is not finite and positive.
            UnknownHandleError: a handle of another system.
        """
    def add_plane(self, particle: ParticleId | Point, normal: Vector, point: Vector) -> ConstraintId:
        """Hold a particle on a plane: Phi = n(t) . (q - p0(t)) (paper eq. 18).

        The constraint force is n lambda: with a unit normal, lambda is the normal force.

        Arguments:
            particle: the particle.
            normal: n(t), each component a number or a Law; it need not be unit (its length at
                t = 0 scales the equation).
            point: p0(t) (m), a point of the plane, numbers or Laws.

        Returns:
            The constraint's handle (one equation).

        Raises:
            InvalidInputError: a normal of zero length.
            UnknownHandleError: a handle of another system.
        """
    def add_fixed_coordinate(self, particle: ParticleId | Point, axis: int | str,
                             value: Scalar | None = None) -> ConstraintId:
        """Prescribe one coordinate of a particle: Phi = q[axis] - value(t).

        The multiplier is the force along +axis.

        Arguments:
            particle: the particle.
            axis: 0, 1, 2 or "x", "y", "z".
            value: the coordinate (m), a number or a Law; None keeps the current coordinate.

        Returns:
            The constraint's handle (one equation).

        Raises:
            InvalidInputError: an axis that is not one of the three.
            UnknownHandleError: a handle of another system.
        """
    def add_relative_coordinate(self, a: ParticleId | Point, b: ParticleId | Point, axis: int | str,
                                value: Scalar | None = None) -> ConstraintId:
        """Prescribe a coordinate of b relative to a: Phi = q_b[axis] - q_a[axis] - value(t).

        Three of them at 0 make two points coincide; one with a law drives a slider.

        Arguments:
            a: the reference particle or point.
            b: the other particle or point.
            axis: 0, 1, 2 or "x", "y", "z".
            value: the difference (m), a number or a Law; None keeps the current one.

        Returns:
            The constraint's handle (one equation).

        Raises:
            InvalidInputError: an axis that is not one of the three, a and b the same particle.
            UnknownHandleError: a handle of another system.
        """
    def add_dot_product(self, a: ParticleId | Point, b: ParticleId | Point, c: ParticleId | Point,
                        d: ParticleId | Point, value: Scalar | None = None) -> ConstraintId:
        """Prescribe the dot product of two directions: Phi = (q_b - q_a) . (q_d - q_c) - value(t).

        Zero keeps the directions perpendicular (a joint's axis equations); a constant keeps their
        angle. The multiplier scale is 1 / |q_d - q_c| at the start.

        Arguments:
            a: the start of the first direction (a particle or a point).
            b: its end.
            c: the start of the second direction.
            d: its end.
            value: the dot product (m^2), a number or a Law; None keeps the current one.

        Returns:
            The constraint's handle (one equation).

        Raises:
            InvalidInputError: a second direction of zero length (the first may start at zero:
                a point on a line through it).
            UnknownHandleError: a handle of another system.
        """
    def point(self, body: dict[str, Any] | Sequence[ParticleId] | None,
              position: Vector) -> Point:
        """The point of a body at a world position now; it moves with the body.

        Arguments:
            body: a rigid body (the dict of ``add_rigid_body`` or ``add_planar_body``), a frame
                of 4 particles (3 for a planar body), or None for the ground.
            position: the point's world position at the initial configuration (m); for a planar
                body, in its plane.

        Returns:
            The point (an affine combination of the body's frame particles).

        Raises:
            InvalidInputError: coplanar frame particles (collinear for 3), a point off a planar
                body's plane, or a position that is not finite.
            UnknownHandleError: a particle of another system.
        """
    def add_joint(self, kind: str, a: dict[str, Any] | Sequence[ParticleId] | None,
                  b: dict[str, Any] | Sequence[ParticleId] | None, at: Vector,
                  axis: Vector | None = None) -> list[ConstraintId]:
        """A joint between two bodies at a world point (docs/theory/mechanisms.md).

        Kinds: "spherical" (a shared point, 3 equations), "revolute" (a shared point and axis,
        5), "prismatic" (a shared line and orientation, 5), "fixed" (6), "orientation" (a shared
        orientation, translations free, 3), "point-on-line" (b's
        point on a's line along the axis, 2), "point-on-plane" (b's point on a's plane normal to
        the axis, 1). Between planar bodies (or a planar body and the ground) a joint keeps its
        in-plane equations: 2 for a shared point, 1 for a shared direction or line.

        Arguments:
            kind: the joint.
            a: the first body (a rigid or planar body's dict, a frame of particles) or None for the
                ground.
            b: the second body, or None for the ground.
            at: the joint's world point at the initial configuration (m).
            axis: the joint's axis (turning axis, sliding direction, line or plane normal);
                needed except for "spherical", "fixed" and "orientation". For planar bodies a revolute axis is
                the plane's normal, a sliding axis lies in the plane.

        Returns:
            The handles of its equations, one per equation, each named in messages and
            redundancy reports by the joint and what it holds ("revolute joint #1: shared point
            along x", "...: A's axis normal to B's e1").

        Raises:
            InvalidInputError: an unknown kind, a missing or zero axis, bodies of different
                kinds or planes, both bodies the ground.
            UnknownHandleError: a particle of another system.
        """
    def add_torque(self, body: dict[str, Any] | Sequence[ParticleId], torque: Scalar,
                   axis: Vector, at: Vector) -> ForceId:
        """A torque about a world axis on a body turning about it (a motor at a revolute joint),
        as a couple on two points of the body: tau (n x r) / |r|^2 at an arm point and its
        opposite at ``at``, r = arm - at normal to the axis.

        Arguments:
            body: the body (its dict or frame).
            torque: tau (N m), a number or a Law (``laws.function`` for a user function).
            axis: the axis n (normalised).
            at: a point of the axis, on the body (m).

        Returns:
            The force's handle.

        Raises:
            InvalidInputError: a zero axis, the ground as the body.
        """
    def add_rigid_cluster(self, particles: Sequence[ParticleId]) -> dict[str, Any]:
        """Make existing particles one rigid body, with their own masses (bodies may share
        particles: two clusters with one in common are joined there by a spherical joint).

        Its frame is 4 of them in space (held by the tetrahedron's 6 edges, every other particle
        by 3 distances to it), or 3 when they all lie in a plane normal to a world axis (the
        triangle's 3 sides, 2 distances for every other particle; each particle must then already
        be held in that plane, by a fixed coordinate).

        Arguments:
            particles: at least 3 distinct particles, not collinear.

        Returns:
            {"particles": the particles, "frame": its 4 (or 3) frame particles, "constraints":
            the distances}.

        Raises:
            InvalidInputError: fewer than 3, repeated or collinear particles, a planar cluster
                whose particles are not held in their plane.
            RedundantConstraintsError: a degenerate configuration.
        """
    def add_planar_body(self, mass: float, centre: Vector, inertia: float, normal: int | str = "y",
                        velocity: Vector | None = None,
                        angular_velocity: float = 0.0) -> dict[str, Any]:
        """A rigid body moving in the plane normal to a world axis: three particles of mass m/3
        at an equilateral triangle of circumradius sqrt(I / m) about the centre, held by its
        three sides, their normal coordinates fixed (docs/theory/mechanisms.md).

        Arguments:
            mass: m (kg, > 0).
            centre: the centre of mass (m); its normal coordinate is the plane's.
            inertia: I, the moment about the normal through the centre (kg m^2, > 0).
            normal: the plane's normal axis, "x", "y" or "z" (or 0, 1, 2).
            velocity: the centre's velocity (m/s, in the plane).
            angular_velocity: about the normal (rad/s).

        Returns:
            {"particles": [3 ParticleId], "frame": the same, "constraints": [6 ConstraintId],
            "normal": the axis}.

        Raises:
            InvalidInputError: a mass or moment not > 0, a velocity out of the plane.
        """
    def add_spring_damper(self, a: ParticleId | Point, b: ParticleId | Point, stiffness: float, damping: float = 0.0,
                          rest_length: float | None = None) -> ForceId:
        """A linear spring and dashpot between two particles: axial force k (l - L0) + c l'.

        Arguments:
            a: one end.
            b: the other end.
            stiffness: k (N/m, >= 0).
            damping: c (N s/m, >= 0).
            rest_length: L0 (m); None: the current distance.

        Returns:
            The force's handle.

        Raises:
            InvalidInputError: a negative or non-finite coefficient, or a == b.
            UnknownHandleError: a handle of another system.
        """
    def add_bending(self, a: ParticleId | Point, b: ParticleId | Point, c: ParticleId | Point, ei: float,
                    spacing: float | None = None) -> ForceId:
        """Bending stiffness of a line at its particle ``b``, between its neighbours ``a`` and
        ``c``: a force on the three particles from the energy
        ``EI / (2 l^3) |q_a - 2 q_b + q_c|^2``, which is ``EI theta^2 / (2 l)`` for segments of
        length ``l`` meeting at a small angle ``theta`` (a beam element of curvature
        ``theta / l``), zero on a straight evenly spaced line and unchanged by rigid motions.
        Put one at every interior node of a chain of distances to give it bending stiffness.

        Arguments:
            a: the previous node.
            b: the node (the middle particle).
            c: the next node.
            ei: bending stiffness EI (N m^2, >= 0).
            spacing: node spacing l (m, > 0); None: the mean of the current distances a-b and
                b-c.

        Returns:
            The force's handle.

        Raises:
            InvalidInputError: a negative or non-finite EI, a spacing that is not positive, or a
                particle given twice.
            UnknownHandleError: a handle of another system.
        """
    def add_force(self, particle: ParticleId | Point, force: Vector) -> ForceId:
        """A prescribed force on one particle, each component a number or a Law of time (N).

        Arguments:
            particle: the particle.
            force: (fx, fy, fz), floats or Laws.

        Returns:
            The force's handle.

        Raises:
            UnknownHandleError: a handle of another system.
        """
    def add_linear_drag(self, particle: ParticleId | Point, coefficient: float) -> ForceId:
        """Linear drag f = -c v on one particle.

        Arguments:
            particle: the particle.
            coefficient: c (N s/m, >= 0).

        Returns:
            The force's handle.

        Raises:
            InvalidInputError: a negative or non-finite coefficient.
            UnknownHandleError: a handle of another system.
        """
    def add_quadratic_drag(self, particle: ParticleId | Point, coefficient: float) -> ForceId:
        """Quadratic drag f = -c |v| v on one particle.

        Arguments:
            particle: the particle.
            coefficient: c (N s^2/m^2, >= 0).

        Returns:
            The force's handle.

        Raises:
            InvalidInputError: a negative or non-finite coefficient.
            UnknownHandleError: a handle of another system.
        """
    def add_force_group(
        self,
        particles: npt.ArrayLike,
        force: Callable[[float, np.ndarray, np.ndarray], npt.ArrayLike],
        jacobian: Callable[[float, np.ndarray, np.ndarray], tuple[npt.ArrayLike, npt.ArrayLike]]
        | None = None,
        name: str | None = None,
    ) -> "UserGroup":
        """Forces computed by one Python function for a whole group of elements at once.

        ``particles`` is a (k,) integer array (one particle per element, arity 1) or (k, a)
        (a particles per element, arity a: pairs, triples or more) of particle indices (``ParticleId.index``). Once per
        evaluation point (each Newton residual) the core calls ``force(t, q, v)`` with the
        positions and velocities of every element's particles, arrays of shape (k, 3) for arity 1
        or (k, a, 3) for arity a >= 2, and expects the forces on those particles (N) in the same
        shape. Element i's result must depend only on ``t`` and row i of ``q`` and ``v``.

        ``jacobian(t, q, v)`` returns ``(df_dq, df_dv)``, each (k, 3a, 3a) with a the arity:
        entry [i, 3p + l, 3r + m] is d(component l of the force on particle p) / d(coordinate m
        of particle r) of element i. Without it the core uses forward differences over the whole
        group (each coordinate of every element perturbed at once by
        h = sqrt(eps) max(|x|, s), s the largest |x| in the group): 6a extra ``force`` calls per
        Jacobian, accurate to ~1e-8 relative, which changes Newton's rate, not the solution.

        Returns the group, whose ``calls`` and ``seconds`` report the calls of the last run.
        A function that raises stops the run with ``UserFunctionError`` (the partial solution
        kept, the function's exception as ``__cause__``); a result of the wrong shape or with NaN
        stops it with ``UserFunctionOutputError``. Models with user groups assemble serially.

        Raises:
            InvalidInputError: ``particles`` not a (k,) or (k, 2) integer array, a pair with
                the same particle twice, a function that is not callable.
            UnknownHandleError: a particle index out of range.
        """
    def add_constraint_group(
        self,
        particles: npt.ArrayLike,
        phi: Callable[[float, np.ndarray], npt.ArrayLike],
        gradient: Callable[[float, np.ndarray], npt.ArrayLike] | None = None,
        hessian: Callable[[float, np.ndarray], npt.ArrayLike] | None = None,
        phi_t: Callable[[float, np.ndarray], npt.ArrayLike] | None = None,
        gamma: Callable[[float, np.ndarray, np.ndarray], npt.ArrayLike] | None = None,
        scale: float | None = None,
        name: str | None = None,
    ) -> "UserGroup":
        """Constraint equations Phi_i(q, t) = 0, one per element, computed by Python functions
        for a whole group of elements at once.

        ``particles`` as for :meth:`add_force_group`; q (and v) are (k, 3) or (k, 2, 3).
        ``phi(t, q)`` returns the k residuals. Optional, each replaced by finite differences
        over the group when missing:

        - ``gradient(t, q)``: dPhi/dq, (k, a, 3) ((k, 3) is accepted for arity 1);
          fallback: central differences of ``phi`` (6a calls, ~4e-11 relative);
        - ``hessian(t, q)``: d2Phi/dq2, (k, 3a, 3a); fallback: forward differences of
          ``gradient`` (3a calls), or second differences of ``phi`` without a gradient (~1e-5;
          it only enters Newton's matrix);
        - ``phi_t(t, q)``: dPhi/dt, (k,); fallback: central difference in t (2 calls);
        - ``gamma(t, q, v)``: Phi'' - Phi_q q'', (k,); fallback: second difference of ``phi``
          along (q + s v, t + s) (2 calls).

        ``scale`` is s such that s Phi is a length (1 by default; 1/(2L) for L^2 - |d|^2): it
        scales the equation's row and multiplier in the linear solves and the constraint-health
        measures. The multipliers of the group are the columns ``group.constraint_indices`` of
        ``Solution.multipliers``.

        Raises:
            InvalidInputError: bad ``particles``, a non-callable function, a scale that is not
                finite and positive, an element touching only fixed particles.
            UnknownHandleError: a particle index out of range.
        """
    def add_rigid_body(
        self,
        mass: float,
        centre: Vector,
        inertia: Sequence[Sequence[float]],
        velocity: Vector | None = None,
        angular_velocity: Vector | None = None,
        points: Sequence[Vector] | None = None,
        point_mass_fraction: float = 0.01,
        particles: int = 7,
    ) -> dict[str, Any]:
        """A rigid body of 7 particles (octahedron + centre; more for points off the octahedron)
        with the given mass, centre of mass and inertia tensor (kg m^2, about the centre, world
        axes), held rigid by 15 independent distances (3 more per added point).

        Returns {"centre": ParticleId, "vertices": [6 ParticleId: +e1, -e1, +e2, -e2, +e3, -e3],
        "points": [ParticleId per point], "particles": [...], "frame": [4 ParticleId: the centre,
        +e1, +e2, +e3], "constraints": [ConstraintId...], "axes": 3x3 principal axes as columns}.

        With ``particles=4`` the body is a tetrahedron of four particles of mass m/4 at the
        corners (+-a1, +-a2, +-a3) (an even number of minus signs) along the principal axes,
        a_k = sqrt(J_k / m), held by its 6 edges: exact mass, centre and inertia with 12
        coordinates instead of 21, for mechanisms of many bodies. It takes no ``points`` (use
        ``System.point``) and returns {"particles", "frame": the 4 particles, "centre": a Point,
        "constraints", "axes"}.
        Raises InvalidInputError (bad mass, non-symmetric or flat inertia),
        RedundantConstraintsError (degenerate geometry)."""
    def add_morison(
        self,
        particle: ParticleId,
        *,
        volume: float,
        area: float,
        drag_coefficient: float,
        added_mass_coefficient: float,
        density: float = 1000.0,
        fluid_motion: Vector | None = None,
        in_water: bool = False,
    ) -> ForceId:
        """Fluid forces on a body's centre particle (Morison equation, docs/theory/hydrodynamics.md).

        The fluid moves as a rigid body by X_f(t) = fluid_motion: rho V (a_f - g) + Ca rho V a_f
        + 1/2 rho Cd A |u_f - v| (u_f - v), with u_f, a_f the derivatives of X_f; the added mass
        Ca rho V joins the particle's translational inertia. With ``in_water``, u_f and a_f are
        the system's water's velocity and local acceleration at the particle (``set_water``:
        its current and waves; the particle counted as submerged), as a MoorDyn point's.

        Arguments:
            particle: the body's reference particle (its centre).
            volume: displaced volume V (m^3, > 0; >= 0 in water).
            area: frontal area A for the drag (m^2, >= 0).
            drag_coefficient: Cd (>= 0).
            added_mass_coefficient: Ca (>= 0).
            density: fluid density rho (kg/m^3, > 0).
            fluid_motion: X_f(t) (m), numbers or Laws; None: still fluid.
            in_water: in the system's water instead (then no ``fluid_motion``; the volume may
                be 0, for drag alone).

        Returns:
            The force's handle.

        Raises:
            InvalidInputError: a value outside its domain.
            UnknownHandleError: a handle of another system.
        """
    def add_seabed_contact(
        self,
        node: ParticleId,
        *,
        depth: float,
        diameter: float,
        length: float,
        kbot: float = 3.0e6,
        cbot: float = 3.0e5,
        tangent: tuple[ParticleId, ParticleId] | None = None,
        friction: float = 0.0,
        axial_friction: float | None = None,
        friction_damping: float = 200.0,
        static_dynamic_scale: float = 1.0,
        damping_ramp: float = 0.0,
        grid: SeabedGrid | None = None,
    ) -> ForceId:
        """Contact of a line node with the seabed, MoorDyn's model: the plane ``z = -depth``,
        or the heights of ``grid`` (docs/theory/seabed-and-line-loads.md).

        While the node penetrates (``p = z_b - z > 0``, ``z_b`` the seabed's height under
        it) the seabed pushes it up (vertically, on a slope too) with
        ``N = d l (kbot p - cbot v_z)``, and friction opposes its sliding velocity ``w`` (or,
        with ``axial_friction``, each of its parts along and across the line):
        ``-mu friction_damping w`` for slow sliding, ``-mu |N| w / |w|`` (Coulomb) once
        ``friction_damping |w| > static_dynamic_scale |N|``.

        Arguments:
            node: the line node.
            depth: water depth (m); the seabed is the plane z = -depth.
            diameter: the line's volume-equivalent diameter d (m, > 0).
            length: the length of line l the node stands for (m, > 0): half a segment on each
                side.
            kbot: seabed stiffness per unit area (Pa/m, >= 0), MoorDyn's kBot.
            cbot: seabed damping per unit area (Pa s/m, >= 0), MoorDyn's cBot.
            tangent: (a, b): the line's direction at the node points from particle a to b (the
                node's neighbours, or the node and its one neighbour at an end of the line);
                None: isotropic friction with ``friction``.
            friction: transverse kinetic friction coefficient (>= 0), MoorDyn's
                FrictionCoefficient.
            axial_friction: axial kinetic friction coefficient (>= 0, MoorDyn-F's MuKA): the
                sliding velocity splits along and across the line, each part with its own
                coefficient; None: MoorDyn-C's single coefficient, ``friction`` on the whole
                sliding velocity whatever the line's direction.
            friction_damping: slope of the friction at small speeds (N s/m, > 0), MoorDyn's
                FricDamp.
            static_dynamic_scale: ratio of static to kinetic friction (>= 1), MoorDyn's
                StatDynFricScale.
            damping_ramp: penetration (m, >= 0) over which the damping grows linearly from zero
                to ``cbot``, which smooths the contact for Newton's iteration; 0: MoorDyn's law,
                full damping from the first touch.
            grid: a seabed of varying height (MoorDyn's 3D seafloor), shared by the nodes;
                ``depth`` then places nothing. None: the plane z = -depth.

        Returns:
            The force's handle.

        Raises:
            InvalidInputError: a value outside its domain, or a tangent that is not two
                different particles.
            UnknownHandleError: a handle of another system.
        """
    def add_line_hydrodynamics(
        self,
        node: ParticleId,
        *,
        diameter: float,
        length: float,
        cd: float = 0.0,
        cdax: float = 0.0,
        ca: float = 0.0,
        caax: float = 0.0,
        density: float = 1025.0,
        tangent: tuple[ParticleId, ParticleId] | None = None,
    ) -> ForceId:
        """Buoyancy, drag and added mass of a line node in water, MoorDyn's model in the line's
        local frame (docs/theory/seabed-and-line-loads.md; in waves docs/theory/ocean.md).

        With the volume ``V = pi d^2 / 4 l`` and the velocity relative to the water
        ``r = u - v`` (``u`` the flow of the system's water, :meth:`set_water`) split into its
        parts along (``r_a``) and across (``r_n``) the line: buoyancy ``rho V g`` upwards, normal
        drag ``1/2 rho cd d l |r_n| r_n``, axial drag ``1/2 rho cdax pi d l |r_a| r_a``, and the
        water's acceleration ``a`` gives ``rho V ((1 + ca) a_n + (1 + caax) a_a)``. The added
        mass is MoorDyn's ``rho V (ca (I - t t^T) + caax t t^T)``: ``ca rho V`` across the line
        and ``caax rho V`` along it (without a tangent, ``ca rho V`` in every direction). In
        water with a free surface the loads (not the added mass) are scaled by the node's wet
        fraction ``clamp((eta - z) / d + 1/2, 0, 1)``.

        Arguments:
            node: the line node.
            diameter: the line's volume-equivalent diameter d (m, > 0).
            length: the length of line l the node stands for (m, > 0).
            cd: normal drag coefficient (>= 0).
            cdax: axial drag coefficient (>= 0).
            ca: normal added-mass coefficient (>= 0).
            caax: axial added-mass coefficient (>= 0).
            density: water density rho (kg/m^3, > 0).
            tangent: (a, b): the line's direction at the node, from particle a to b, as for
                ``add_seabed_contact``; None: drag with ``cd`` in every direction.

        Returns:
            The force's handle.

        Raises:
            InvalidInputError: a value outside its domain, or a tangent that is not two
                different particles.
            UnknownHandleError: a handle of another system.
        """
    def add_damping_matrix(self, particles: Sequence[ParticleId],
                           matrix: npt.NDArray[np.float64]) -> ForceId:
        """A linear velocity coupling ``f = -D v`` over any number of particles: a damping
        matrix, or a linear first-order system ``x' = A x + B u`` whose states are the
        velocities of auxiliary particles of mass ``mu`` (rows ``mu (A x + B u)``), as the
        radiation memory of :mod:`vinculo.ocean.bem`.

        Arguments:
            particles: the n particles, each once.
            matrix: D, (3n, 3n) (N s/m): row 3p + k is the force component k on particle p,
                column 3r + l the velocity component l of particle r.

        Returns:
            The force's handle.

        Raises:
            InvalidInputError: a matrix of the wrong size or with non-finite entries, a
                particle given twice.
        """
    def add_floating_body(
        self,
        body: dict[str, Any] | Sequence[ParticleId],
        hull: Any,
        *,
        origin: Vector | None = None,
        axis: Vector | None = None,
        density: float = 1025.0,
        ca: float = 0.0,
        cd: float = 0.0,
        drag_area: float = 0.0,
        added_mass: float | None = None,
        layers: int = 40,
    ) -> ForceId:
        """The water's loads on a rigid body from its instantaneous submerged volume
        (docs/theory/ocean.md, "Floating bodies").

        The hull is cut into ``layers`` horizontal layers and each layer into 24 cells, points
        of the body. Each cell carries ``F rho dV ((1 + ca) a - g)`` (buoyancy, Froude-Krylov
        and the water's share of the added-mass force; ``a`` the water's local acceleration on
        the body's axis at the cell's layer) and its share of the drag
        ``1/2 rho cd A |u - v| (u - v)``, with ``F`` its wet fraction under the local surface
        (the exact share of its layer's volume below the waterline; 1 in water without a
        surface), so that the restoring in heave, roll and pitch follows from the geometry. The
        added mass joins the centre particle's inertia (translation only).

        Arguments:
            body: a rigid body (``add_rigid_body``'s dict) or 4 of its particles.
            hull: a :class:`vinculo.ocean.Hull`, in the body's frame.
            origin: where the hull's origin is now (m); None: the body's centre particle.
            axis: the hull's axis (its z) now; None: (0, 0, 1).
            density: water density (kg/m^3).
            ca: added-mass coefficient.
            cd: drag coefficient.
            drag_area: the drag's frontal area A (m^2).
            added_mass: the body's added mass (kg); None: ``ca rho V0``, V0 the hull's volume
                below z = 0 now.
            layers: layers over the hull's height.

        Returns:
            The force's handle.

        Raises:
            InvalidInputError: a bad hull, value or frame, or an added mass without a centre
                particle to carry it.
        """
    def element_forces(self, forces: Sequence[ForceId | int],
                       positions: npt.NDArray[np.float64], velocities: npt.NDArray[np.float64],
                       times: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
        """The force each force element exerts on the particles it acts on (a line element's
        node alone), at stored states: a line end's hydrodynamic and seabed loads, for the
        force of the line on its end point.

        Arguments:
            forces: the elements (handles or indices).
            positions: (m, n, 3) positions (m) of the system's n particles.
            velocities: (m, n, 3) velocities (m/s).
            times: (m,) times (s).

        Returns:
            (m, k, 3) forces (N), one per time and element.

        Raises:
            InvalidInputError: arrays of the wrong shape, or an element that is not one.
        """
    def set_water(self, water: Water) -> None:
        """Put the line elements and floating bodies (added before and after) in ``water``:
        its current, waves and free surface. Build it with :class:`vinculo.ocean.Sea` (``Sea.water()``); until then a
        system's water is still water that fills all space.

        Arguments:
            water: the water.
        """
    def set_slack(self, constraint: ConstraintId) -> None:
        """Let an elastic segment go slack: shorter than its unstretched length it carries no
        tension and no compression, ``T = max(0, EA (|d| - L) / L)``, as MoorDyn's segments
        (docs/theory/moorings.md). Mooring lines (``vinculo.mooring``) are made of such
        segments.

        Arguments:
            constraint: an elastic segment of finite EA (``add_elastic_distance``).

        Raises:
            InvalidInputError: a constraint that is not such a segment, or not one of this
                system's.
        """
    def set_strain_curve(self, constraint: ConstraintId, strains: Sequence[float],
                         tensions: Sequence[float]) -> None:
        """Give an elastic segment a tension-strain curve (MoorDyn's nonlinear EA): its
        tension follows the piecewise linear curve through (strains[k], tensions[k]),
        continued along its end pieces, instead of Hooke's law; its equation becomes
        ``Phi + L e(T) = 0`` with the compliance ``L e'(T)`` at the current tension
        (docs/theory/moorings.md). Its EA is then the curve's stiffest piece's.

        Arguments:
            constraint: an elastic segment of finite EA between two particles.
            strains: increasing strains (-).
            tensions: increasing tensions (N), one per strain.

        Raises:
            InvalidInputError: fewer than two points, values not finite or not increasing, or
                a constraint that is not such a segment.
        """
    def set_axial_damping(self, constraint: ConstraintId, damping: float) -> None:
        """Give an elastic segment internal axial damping: the tension
        ``damping * u . (v_a - v_b)`` along it (``u`` the unit vector from b to a), stretched or
        slack, as MoorDyn's BA / l (N s/m). The same force as a spring-damper of zero stiffness
        between the segment's particles, computed with the segment's own geometry
        (docs/theory/moorings.md). Mooring lines (``vinculo.mooring``) damp their segments
        this way.

        Arguments:
            constraint: an elastic segment between two particles (``add_elastic_distance``).
            damping: the damping coefficient (N s/m), finite and >= 0.

        Raises:
            InvalidInputError: a constraint that is not such a segment (between points of
                bodies, add a spring-damper of zero stiffness), or a damping that is negative
                or not finite.
        """
    def set_tension_only(self, constraint: ConstraintId) -> None:
        """Declare a distance constraint a string: runs stop with NegativeTensionError when it
        would have to push.

        Arguments:
            constraint: a distance (to a particle or to a point).

        Raises:
            InvalidInputError: a constraint that is not a distance, or not one of this system's.
        """
    @property
    def constraint_lengths(self) -> npt.NDArray[np.float64]:
        """Length of each constraint (m); NaN for constraints that are not distances."""
    @property
    def inertia(self) -> npt.NDArray[np.float64]:
        """Translational inertia of each particle: mass plus added mass (kg); a line node's
        added mass is its normal one, Ca rho V (along the line, its inertia is
        m + CaAx rho V: the step problems correct it)."""
    @property
    def num_particles(self) -> int:
        """Number of particles, fixed ones included."""
    @property
    def num_constraints(self) -> int:
        """Number of constraint equations (= length of the multiplier vector)."""
    @property
    def gravity(self) -> tuple[float, float, float]:
        """The gravity vector (m/s^2)."""
    def masses(self) -> npt.NDArray[np.float64]:
        """(n,) mass of each particle (kg), added mass excluded."""
    def fixed(self) -> npt.NDArray[np.bool_]:
        """(n,) True for the fixed particles."""
    def initial_positions(self) -> npt.NDArray[np.float64]:
        """(n, 3)."""
    def initial_velocities(self) -> npt.NDArray[np.float64]:
        """(n, 3) initial velocities (m/s)."""
    def constraint_names(self) -> list[str]:
        """One readable name per constraint equation, e.g. 'distance #0 (particles 0-1)'."""
    def constraint_scales(self) -> npt.NDArray[np.float64]:
        """Per equation: the factor s_k such that s_k Phi_k is a length (1/(2L) for a distance)."""
    def length_scale(self) -> float:
        """Characteristic length of the model: Newton and initial tolerances are relative to it."""
    def particles(self) -> list[ParticleId]:
        """The handles of every particle, in the order they were added."""
    def constraint_residual(self, positions: npt.ArrayLike, t: float = 0.0) -> npt.NDArray[np.float64]:
        """Phi(q, t) for an (n, 3) array of positions, per equation (unscaled)."""
    def kinetic_energy(self, velocities: npt.ArrayLike) -> npt.NDArray[np.float64]:
        """Sum 1/2 m |v|^2 for (..., n, 3) velocities; returns shape (...)."""
    def potential_energy(self, positions: npt.ArrayLike) -> npt.NDArray[np.float64]:
        """Gravity and spring potential for (..., n, 3) positions; returns shape (...)."""
    def set_initial_state(self, positions: npt.ArrayLike,
                          velocities: npt.ArrayLike | None = None) -> None:
        """Set the initial positions and velocities of every particle (fixed ones included).

        Arguments:
            positions: (n, 3) positions (m).
            velocities: (n, 3) velocities (m/s); None: at rest.

        Raises:
            InvalidInputError: arrays of another shape, or non-finite values.
        """
    def project_initial_state(self, tolerance: float = 1e-12, max_iterations: int = 50) -> dict[str, float]:
        """Move the initial positions and velocities onto Phi = 0 and Phi_q v + Phi_t = 0 with the
        least mass-weighted change; returns {'position_change': max |dq|, 'velocity_change': max |dv|,
        'iterations': n}."""

class RunSettings:
    """The settings of a run (the keyword arguments of ``vinculo.simulate`` less ``progress``,
    with the same names, defaults and meaning), converted to the core's options and checked once.
    ``simulate`` and ``Simulation`` take it.

    Raises:
        InvalidInputError: a value out of its range (as ``vinculo.simulate``).
    """
    def __init__(self, t_end: float, dt: float, alpha: float | None = None, t_start: float = 0.0,
                 tolerance: float = 1e-10, max_iterations: int = 25, max_halvings: int = 4,
                 initial_tolerance: float = 1e-8, save_every: int = 1,
                 jacobian_reuse: bool | None = None, scheme: str = "trapezoidal",
                 rho_inf: float | None = None, formulation: str = "index-3",
                 adaptive: bool = False, rtol: float = 1e-6, atol: float = 1e-6,
                 h_min: float = 1e-10, h_max: float | None = None,
                 t_eval: list[float] | None = None,
                 max_output_bytes: float | None = None,
                 linear_solver: str = "auto") -> None: ...

class RunResult:
    """A run as the compiled core returns it (``simulate``, ``Simulation.solution``): the stored
    states and the statistics as typed read-only attributes (each array a fresh numpy copy,
    read-only), and the error that stopped the run early as the exception that reports it.
    ``vinculo.Solution`` is built from it (``Solution.from_core``).

    Row 0 is the initial state (0 iterations, step 0, multipliers from the consistent initial
    accelerations); row k > 0 holds the multipliers of the step that ends at ``times[k]``, which
    act at t_{k-1} + alpha dt for the trapezoidal schemes, where they evaluate the dynamics, and
    at ``times[k]`` for generalized-alpha. With adaptive=True and t_eval: one row per requested
    time, interpolated in its step, with that step's statistics.
    """
    @property
    def times(self) -> npt.NDArray[np.float64]:
        """Stored times, shape (s,), in s."""
    @property
    def positions(self) -> npt.NDArray[np.float64]:
        """Positions, shape (s, n, 3), in m."""
    @property
    def velocities(self) -> npt.NDArray[np.float64]:
        """Velocities, shape (s, n, 3), in m/s."""
    @property
    def multipliers(self) -> npt.NDArray[np.float64]:
        """Lagrange multipliers, shape (s, m)."""
    @property
    def constraint_residual(self) -> npt.NDArray[np.float64]:
        """max_k |s_k Phi_k| at each stored time, shape (s,), in m."""
    @property
    def velocity_violation(self) -> npt.NDArray[np.float64]:
        """max_k |s_k (Phi_q v + Phi_t)| at each stored time, shape (s,), in m/s."""
    @property
    def newton_iterations(self) -> npt.NDArray[np.int64]:
        """Newton iterations of each stored step, shape (s,)."""
    @property
    def step_sizes(self) -> npt.NDArray[np.float64]:
        """Size of each stored step, shape (s,), in s."""
    @property
    def residual_norms(self) -> npt.NDArray[np.float64]:
        """The last scaled residual norm Newton evaluated in each stored step, shape (s,), in m."""
    @property
    def increment_norms(self) -> npt.NDArray[np.float64]:
        """Last scaled Newton increment norm of each stored step, shape (s,), in m."""
    @property
    def accepted_step_sizes(self) -> npt.NDArray[np.float64]:
        """Size of every accepted step, stored or not, in s."""
    @property
    def steps_taken(self) -> int:
        """Steps attempted, including those rejected and retried."""
    @property
    def steps_rejected(self) -> int:
        """Attempts rejected (Newton failed, or the error estimate exceeded the tolerance)."""
    @property
    def factorisations(self) -> int:
        """Newton iteration matrices factorised over the run."""
    @property
    def residual_evaluations(self) -> int:
        """Residual evaluations of the step equations by Newton's iterations over the run."""
    @property
    def linear_solver(self) -> str:
        """The linear solver of the steps: 'dense LU', 'tree elimination' or 'sparse LU'."""
    @property
    def scheme(self) -> str:
        """The time discretisation: 'trapezoidal', 'backward-euler' or 'generalized-alpha'."""
    @property
    def formulation(self) -> str:
        """The equations discretised: 'index-3' or 'ggl'."""
    @property
    def error(self) -> VinculoError | None:
        """None when the run reached its end; otherwise the exception of the error that stopped
        it, of the ``vinculo.errors`` class the core's error selects, with the partial
        ``vinculo.Solution`` as its ``solution`` attribute and, for a failed user function, the
        user's exception as its ``__cause__``."""

class SeabedGrid:
    """Heights of the seabed on a grid of x and y ticks (m), bilinear in each cell and held
    at the edge's height beyond it (MoorDyn's 3D seafloor; build it with
    :class:`vinculo.mooring.Seafloor`; docs/theory/seabed-and-line-loads.md)."""

    def __init__(self, x: npt.NDArray[np.float64], y: npt.NDArray[np.float64],
                 z: npt.NDArray[np.float64]) -> None:
        """``x`` (nx) and ``y`` (ny) strictly increasing, finite ticks; ``z`` (nx, ny) heights.

        Raises:
            InvalidInputError: ticks not increasing or not finite, heights of another shape
                or not finite.
        """
    def height_and_slope(self, x: float, y: float) -> tuple[float, float, float]:
        """The height z_b at (x, y) and its slopes dz_b/dx, dz_b/dy."""
    def heights_at(self, x: list[float], y: list[float]) -> list[float]:
        """The heights at the points (x[k], y[k]).

        Raises:
            InvalidInputError: for lists of different lengths.
        """

class Water:
    """The core's water: a current, linear wave components and a free surface at z = eta
    (z up, still-water level z = 0, seabed z = -depth). Build it with
    :class:`vinculo.ocean.Sea`; see docs/theory/ocean.md for the equations."""

    def __init__(self, depth: float, g: float, amplitudes: npt.NDArray[np.float64],
                 omegas: npt.NDArray[np.float64], directions: npt.NDArray[np.float64],
                 phases: npt.NDArray[np.float64], current_kind: str,
                 current_velocity: npt.NDArray[np.float64],
                 current_heights: npt.NDArray[np.float64], current_exponent: float,
                 stretching_name: str, free_surface: bool, ramp: float = 0.0) -> None:
        """Arguments:
            depth: water depth (m, > 0; inf: deep water).
            g: gravity (m/s^2).
            amplitudes: wave amplitudes (m).
            omegas: angular frequencies (rad/s).
            directions: directions of travel (rad from x towards y).
            phases: phases (rad).
            current_kind: "uniform", "power" or "table".
            current_velocity: (n, 3) velocities (m/s): one for "uniform" and "power" (at the
                surface), one per height for "table".
            current_heights: the table's heights (m, increasing).
            current_exponent: the power law's exponent.
            stretching_name: "wheeler" or "vertical".
            free_surface: whether the water has a free surface (False: it fills all space).
            ramp: the waves grow over this time (s) by (1 - cos(pi t / ramp)) / 2.

        Raises:
            InvalidInputError: a value outside its domain, named.
        """
    @property
    def wave_numbers(self) -> npt.NDArray[np.float64]:
        """The components' wave numbers k (rad/m), roots of omega^2 = g k tanh(k h)."""
    def flow(self, points: npt.NDArray[np.float64], t: float,
             gradients: bool = False) -> dict[str, npt.NDArray[np.float64]]:
        """The flow at many points at one time.

        Arguments:
            points: (n, 3) positions (m).
            t: time (s).
            gradients: also return ``velocity_gradient`` (n, 3, 3).

        Returns:
            ``velocity`` and ``acceleration`` (n, 3), ``pressure`` (n,: the waves' dynamic
            pressure over the density, m^2/s^2), ``elevation`` (n,: eta above each point).
        """
    def elevation(self, xy: npt.NDArray[np.float64],
                  t: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
        """The surface elevation (m), (len(t), len(xy)).

        Arguments:
            xy: (n, 2) horizontal positions (m).
            t: (m,) times (s).

        Returns:
            The elevation at each time and position.
        """

def solve_statics(system: System, tolerance: float = 1e-9, max_iterations: int = 1000,
                  t: float = 0.0, newton_first: bool = True
                  ) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], float, int, str]:
    """The static equilibrium (see ``vinculo.mooring.statics.solve_statics``).

    Returns:
        (positions (n, 3), multipliers (m,), residual, iterations, method).

    Raises:
        ConvergenceError: when neither Newton's method nor the continuation converges.
    """
def point_stiffness(system: System, positions: npt.NDArray[np.float64],
                    multipliers: npt.NDArray[np.float64], particle: int,
                    t: float = 0.0) -> npt.NDArray[np.float64]:
    """The 3x3 stiffness K = -dF/dx (N/m) at a particle in an equilibrium.

    Raises:
        ConvergenceError: a singular equilibrium Jacobian at the point.
    """
def points_stiffness(system: System, positions: npt.NDArray[np.float64],
                     multipliers: npt.NDArray[np.float64], particles: list[int],
                     t: float = 0.0) -> npt.NDArray[np.float64]:
    """The joint 3n x 3n stiffness (N/m) at n particles in an equilibrium: blocks
    K_ij = -dF_i/dx_j.

    Raises:
        ConvergenceError: a singular equilibrium Jacobian, or block of its inverse on the points.
        InvalidInputError: no particles, one out of range, or one listed twice.
    """
def point_force(system: System, positions: npt.NDArray[np.float64],
                multipliers: npt.NDArray[np.float64], particle: int,
                t: float = 0.0) -> tuple[float, float, float]:
    """The force (N) of the system's elements on a particle in an equilibrium."""
def simulate(system: System, settings: RunSettings,
             progress: Callable[[float, float], None] | None = None) -> RunResult:
    """Integrate.

    progress(t, t_end) is called about twice a second of wall time; Ctrl-C is looked for about
    ten times a second.

    Arguments:
        system: the model.
        settings: the run's settings.
        progress: the progress callback, or None.

    Returns:
        The run; a run that stopped early (Ctrl-C included: ``vinculo.errors.Interrupted``)
        returns the states computed before, with its ``error``.

    Raises:
        VinculoError: the ``vinculo.errors`` class of an error found before the first step (bad
            settings, an inconsistent initial state, an output too large for memory, a run
            started from a user function of the same system, ...).
        BaseException: the exception the progress callback raised (but a ``KeyboardInterrupt``,
            reported as the run's ``error``), with the partial solution as its ``solution``.
    """

def time_simulate(system: System, settings: RunSettings, repeats: int = 1) -> float:
    """The least wall-clock time of ``repeats`` runs of the core's integration, in Rust alone
    (no conversion of the solution to Python objects): the reference of the Python overhead
    benchmark (``python -m vinculo.bench python-overhead``).

    Arguments:
        system: the model.
        settings: the run's settings.
        repeats: the number of runs (>= 1).

    Returns:
        The least time of one run, in s.

    Raises:
        InvalidInputError: ``repeats`` below 1.
        RuntimeError: a run failed (its message).
    """

class Snapshot:
    """A copy of a running simulation's state (``Simulation.snapshot``), restored by
    ``Simulation.restore``."""
    @property
    def time(self) -> float:
        """Time of the snapshot, in s."""
    def save(self, path: str) -> None:
        """Save the snapshot to a file (format: ``crates/vinculo/src/snapshot_file.rs``).

        Arguments:
            path: the file to write.

        Raises:
            InvalidInputError: a snapshot of an error-controlled or stopped run, or the file
                cannot be written.
        """
    @staticmethod
    def load(path: str) -> "Snapshot":
        """Load a snapshot saved by ``save``.

        Arguments:
            path: the file.

        Returns:
            The snapshot.

        Raises:
            InvalidInputError: unreadable, not a snapshot file, other version, truncated or corrupt.
        """

class Simulation:
    """The core's stepping object; ``vinculo.Simulation`` wraps it.

    Arguments:
        system: the model (the simulation keeps its own copy).
        settings: the run's settings (``RunSettings``: t_end, dt and the rest).

    Raises:
        InvalidInputError: a bad argument.
        InconsistentInitialStateError: the initial state violates a constraint.
    """
    def __init__(self, system: System, settings: RunSettings) -> None: ...
    def step_to(self, t: float) -> None:
        """Advance to time t (at most t_end).

        Arguments:
            t: the time to reach, in s.

        Raises:
            InvalidInputError: t is before the current time.
            ConvergenceError: (or another ``vinculo.errors`` class, as ``RunResult.error``) the
                run stopped, now or at an earlier call; its ``solution`` holds the states stored.
        """
    @property
    def time(self) -> float:
        """Current time, in s."""
    @property
    def positions(self) -> npt.NDArray[np.float64]:
        """Current positions, shape (n, 3)."""
    @property
    def velocities(self) -> npt.NDArray[np.float64]:
        """Current velocities, shape (n, 3)."""
    @property
    def multipliers(self) -> npt.NDArray[np.float64]:
        """Current multipliers, shape (m,)."""
    def solution(self) -> RunResult:
        """The states stored so far, as ``simulate`` returns them."""
    def snapshot(self) -> Snapshot:
        """A copy of the running state."""
    def restore(self, snapshot: Snapshot) -> None:
        """Return to the state of a snapshot of a simulation of the same system.

        Arguments:
            snapshot: the snapshot.

        Raises:
            InvalidInputError: a snapshot of another system, or not a snapshot.
        """
