"""Four small models with known answers, shared by the examples, the CLI and the tests.

Each model has a ``build_*`` function returning the system with the handles of its parts, and a
``run_*`` function that simulates it and extracts the quantity its reference predicts:

- single pendulum (L = 1 m, released horizontally): period against the exact elliptic-integral
  period, and rod tension against the energy-derived closed form;
- double pendulum (equal masses and lengths, small amplitude): the two normal-mode frequencies
  against ``omega^2 = (2 -/+ sqrt 2) g / l``;
- hanging chain of N links released from a straight, tilted shape: energy conservation and the
  constraint residual;
- particle sliding on a frictionless inclined plane: acceleration ``g sin(theta)`` along the slope
  and normal force ``m g cos(theta)`` from the multiplier.

Gravity is ``(0, 0, -g)`` throughout; pendulums swing in the x-z plane.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import scipy.linalg
import scipy.special

from vinculo._core import ConstraintId, ParticleId, System
from vinculo.simulate import simulate
from vinculo.solution import Solution

__all__ = [
    "GRAVITY",
    "DoublePendulum",
    "DoublePendulumResult",
    "HangingChain",
    "HangingChainResult",
    "InclinedPlane",
    "InclinedPlaneResult",
    "Pendulum",
    "PendulumResult",
    "build_double_pendulum",
    "build_hanging_chain",
    "build_inclined_plane",
    "build_pendulum",
    "crossing_period",
    "double_pendulum_angles",
    "exact_pendulum_period",
    "normal_mode_frequencies",
    "pendulum_tension",
    "run_double_pendulum",
    "run_hanging_chain",
    "run_inclined_plane",
    "run_pendulum",
    "zero_crossings",
]

GRAVITY = 9.81
"""Standard gravity used by the demos, in m/s^2 (the value of the reference period in
docs/theory/formulation.md)."""


# --------------------------------------------------------------------------------------------
# Signal analysis shared by the models
# --------------------------------------------------------------------------------------------


def zero_crossings(
    times: np.ndarray, values: np.ndarray, rates: np.ndarray | None = None
) -> np.ndarray:
    """Times at which a sampled signal crosses zero.

    Between two samples of opposite sign the crossing is located on the cubic Hermite interpolant
    of the values and their rates (error O(h^4)) when ``rates`` is given, or by linear
    interpolation (error O(h^2)) otherwise.

    Arguments:
        times: (s,) increasing sample times.
        values: (s,) the signal.
        rates: (s,) its time derivative, if known.

    Returns:
        The crossing times, increasing.
    """
    t = np.asarray(times, dtype=np.float64)
    x = np.asarray(values, dtype=np.float64)
    v = None if rates is None else np.asarray(rates, dtype=np.float64)
    # A sample exactly at zero is counted once: as the start of the interval that leaves it.
    left = np.flatnonzero((x[:-1] > 0) & (x[1:] <= 0) | (x[:-1] < 0) & (x[1:] >= 0))
    crossings = np.empty(len(left))
    for out, k in enumerate(left):
        t0, t1, x0, x1 = t[k], t[k + 1], x[k], x[k + 1]
        h = t1 - t0
        u = x0 / (x0 - x1)  # linear estimate, in [0, 1]
        if v is not None:
            m0, m1 = v[k] * h, v[k + 1] * h
            for _ in range(8):  # Newton on the Hermite cubic p(u), started from the linear estimate
                u2, u3 = u * u, u * u * u
                p = (
                    (2 * u3 - 3 * u2 + 1) * x0
                    + (u3 - 2 * u2 + u) * m0
                    + (-2 * u3 + 3 * u2) * x1
                    + (u3 - u2) * m1
                )
                dp = (
                    (6 * u2 - 6 * u) * x0
                    + (3 * u2 - 4 * u + 1) * m0
                    + (-6 * u2 + 6 * u) * x1
                    + (3 * u2 - 2 * u) * m1
                )
                if dp == 0:
                    break
                u = min(max(u - p / dp, 0.0), 1.0)
        crossings[out] = t0 + u * h
    return crossings


def crossing_period(
    times: np.ndarray, values: np.ndarray, rates: np.ndarray | None = None
) -> float:
    """Period of an oscillating signal from its zero crossings.

    Consecutive crossings of a signal symmetric about zero are half a period apart; the period is
    ``2 (t_last - t_first) / (number of crossings - 1)``.

    Arguments:
        times: (s,) increasing sample times.
        values: (s,) the signal.
        rates: (s,) its time derivative, if known (more accurate crossings).

    Returns:
        The period, or NaN if the signal crosses zero fewer than twice.
    """
    crossings = zero_crossings(times, values, rates)
    if len(crossings) < 2:
        return float("nan")
    return float(2.0 * (crossings[-1] - crossings[0]) / (len(crossings) - 1))


# --------------------------------------------------------------------------------------------
# Single pendulum
# --------------------------------------------------------------------------------------------


def exact_pendulum_period(length: float, gravity: float, amplitude: float) -> float:
    """Exact period of a simple pendulum released at rest.

    ``T = 4 sqrt(L / g) K(k)`` with ``k = sin(amplitude / 2)`` and K the complete elliptic integral
    of the first kind (scipy's ``ellipk`` takes the parameter ``m = k^2``).

    Arguments:
        length: L, in m.
        gravity: g, in m/s^2.
        amplitude: release angle from the downward vertical, in rad (below pi).

    Returns:
        The period in s (2.367841947576237 s for L = 1, g = 9.81, amplitude pi/2).
    """
    k = np.sin(amplitude / 2.0)
    return float(4.0 * np.sqrt(length / gravity) * scipy.special.ellipk(k * k))


@dataclass(frozen=True)
class Pendulum:
    """A point mass on a massless rod of length ``length`` about a fixed pivot at the origin."""

    system: System
    bob: ParticleId
    rod: ConstraintId
    length: float
    mass: float
    gravity: float
    amplitude: float


def build_pendulum(
    length: float = 1.0,
    mass: float = 1.0,
    gravity: float = GRAVITY,
    amplitude: float = np.pi / 2,
) -> Pendulum:
    """A simple pendulum released at rest.

    Arguments:
        length: rod length, in m.
        mass: bob mass, in kg.
        gravity: g, in m/s^2 (acting along -z).
        amplitude: release angle from the downward vertical, in rad (pi/2: horizontal).

    Returns:
        The model; the bob starts at ``L (sin a, 0, -cos a)``.
    """
    system = System(gravity=(0.0, 0.0, -gravity))
    position = (length * np.sin(amplitude), 0.0, -length * np.cos(amplitude))
    if amplitude == np.pi / 2:
        position = (length, 0.0, 0.0)  # exactly horizontal, without cos(pi/2) round-off
    bob = system.add_particle(mass, [float(c) for c in position])
    rod = system.add_distance_to_point(bob, (0.0, 0.0, 0.0), length)
    return Pendulum(system, bob, rod, length, mass, gravity, amplitude)


def pendulum_tension(model: Pendulum, positions: np.ndarray) -> np.ndarray:
    """Rod tension from energy conservation, at given bob positions.

    With the angle theta from the downward vertical, ``v^2 = 2 g L (cos theta - cos theta0)``, so
    ``T = m g cos theta + m v^2 / L = m g (3 cos theta - 2 cos theta0)`` with
    ``cos theta = -z / L``.

    Arguments:
        model: the pendulum.
        positions: (..., 3) bob positions.

    Returns:
        (...) tensions, in N.
    """
    cos_theta = -np.asarray(positions)[..., 2] / model.length
    return model.mass * model.gravity * (3.0 * cos_theta - 2.0 * np.cos(model.amplitude))


@dataclass(frozen=True)
class PendulumResult:
    """A pendulum run with its measured and exact periods."""

    model: Pendulum
    solution: Solution
    period: float
    exact_period: float

    @property
    def relative_error(self) -> float:
        """Relative error of the measured period."""
        return abs(self.period - self.exact_period) / self.exact_period

    def summary_line(self) -> str:
        """One line for the command line."""
        return (
            f"pendulum: period {self.period:.9f} s, exact {self.exact_period:.9f} s "
            f"(relative error {self.relative_error:.1e}), "
            f"max constraint residual {np.max(self.solution.constraint_residual):.1e} m"
        )


def run_pendulum(
    periods: float = 3.0,
    dt: float = 1e-3,
    alpha: float = 0.5,
    model: Pendulum | None = None,
    progress: bool = False,
) -> PendulumResult:
    """Simulate a pendulum over a few periods and measure its period.

    The period comes from the zero crossings of x(t) (Hermite-interpolated with the velocity).

    Arguments:
        periods: how many exact periods to simulate (a quarter period more is added so that the
            last crossing is inside the run).
        dt: step size, in s.
        alpha: the integrator's parameter.
        model: the pendulum (default: ``build_pendulum()``, L = 1 m released horizontally).
        progress: draw a progress bar.

    Returns:
        The run and its periods.
    """
    model = model if model is not None else build_pendulum()
    exact = exact_pendulum_period(model.length, model.gravity, model.amplitude)
    t_end = dt * np.ceil((periods + 0.25) * exact / dt)
    solution = simulate(model.system, t_end, dt, alpha, progress=progress)
    x = solution.particle(model.bob)[:, 0]
    vx = solution.particle_velocity(model.bob)[:, 0]
    period = crossing_period(solution.times, x, vx)
    return PendulumResult(model, solution, period, exact)


# --------------------------------------------------------------------------------------------
# Double pendulum
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class DoublePendulum:
    """Two equal point masses on two equal massless rods, hung from a fixed pivot particle."""

    system: System
    pivot: ParticleId
    upper: ParticleId
    lower: ParticleId
    upper_link: ConstraintId
    lower_link: ConstraintId
    length: float
    mass: float
    gravity: float


def build_double_pendulum(
    theta1: float = 0.01,
    theta2: float = 0.0,
    length: float = 1.0,
    mass: float = 1.0,
    gravity: float = GRAVITY,
) -> DoublePendulum:
    """A double pendulum released at rest.

    Arguments:
        theta1: angle of the upper rod from the downward vertical, in rad.
        theta2: angle of the lower rod from the downward vertical, in rad.
        length: length of each rod, in m.
        mass: mass of each bob, in kg.
        gravity: g, in m/s^2 (acting along -z).

    Returns:
        The model; the pivot is a fixed particle at the origin.
    """
    system = System(gravity=(0.0, 0.0, -gravity))
    pivot = system.add_particle(mass, (0.0, 0.0, 0.0), fixed=True)
    p1 = np.array([length * np.sin(theta1), 0.0, -length * np.cos(theta1)])
    p2 = p1 + np.array([length * np.sin(theta2), 0.0, -length * np.cos(theta2)])
    upper = system.add_particle(mass, [float(c) for c in p1])
    lower = system.add_particle(mass, [float(c) for c in p2])
    upper_link = system.add_distance(pivot, upper, length)
    lower_link = system.add_distance(upper, lower, length)
    return DoublePendulum(
        system, pivot, upper, lower, upper_link, lower_link, length, mass, gravity
    )


def normal_mode_frequencies(length: float, gravity: float) -> tuple[float, float]:
    """Angular frequencies of the small oscillations of a double pendulum (equal m, equal l).

    ``omega^2 = (2 -/+ sqrt 2) g / l``.

    Arguments:
        length: l, in m.
        gravity: g, in m/s^2.

    Returns:
        (slow, fast) angular frequencies, in rad/s.
    """
    root2 = np.sqrt(2.0)
    return (
        float(np.sqrt((2.0 - root2) * gravity / length)),
        float(np.sqrt((2.0 + root2) * gravity / length)),
    )


def double_pendulum_angles(
    model: DoublePendulum, solution: Solution
) -> tuple[np.ndarray, np.ndarray]:
    """Rod angles from the downward vertical and their rates.

    Arguments:
        model: the double pendulum.
        solution: a run of it.

    Returns:
        (angles, rates), each (s, 2): columns are the upper and the lower rod.
    """
    q0 = solution.particle(model.pivot)
    q1, q2 = solution.particle(model.upper), solution.particle(model.lower)
    v0 = solution.particle_velocity(model.pivot)
    v1, v2 = solution.particle_velocity(model.upper), solution.particle_velocity(model.lower)
    angles, rates = [], []
    for (qa, va), (qb, vb) in (((q0, v0), (q1, v1)), ((q1, v1), (q2, v2))):
        d, w = qb - qa, vb - va
        x, z, vx, vz = d[:, 0], -d[:, 2], w[:, 0], -w[:, 2]
        angles.append(np.arctan2(x, z))
        rates.append((z * vx - x * vz) / (x * x + z * z))
    return np.stack(angles, axis=1), np.stack(rates, axis=1)


def _linear_modes() -> tuple[np.ndarray, np.ndarray]:
    """Mass matrix and M-normalised mode shapes of the linearised double pendulum (m = l = g = 1).

    Kinetic energy ``1/2 m l^2 (2 th1'^2 + 2 th1' th2' + th2'^2)``, potential
    ``1/2 m g l (2 th1^2 + th2^2)``; the shapes do not depend on m, l or g.
    """
    mass = np.array([[2.0, 1.0], [1.0, 1.0]])
    stiffness = np.array([[2.0, 0.0], [0.0, 1.0]])
    _, shapes = scipy.linalg.eigh(stiffness, mass)  # slow mode first
    return mass, shapes


@dataclass(frozen=True)
class DoublePendulumResult:
    """A double pendulum run with its measured and exact normal-mode frequencies."""

    model: DoublePendulum
    solution: Solution
    angles: np.ndarray
    modal: np.ndarray
    frequencies: tuple[float, float]
    exact_frequencies: tuple[float, float]

    @property
    def relative_errors(self) -> tuple[float, float]:
        """Relative errors of the (slow, fast) angular frequencies."""
        return tuple(  # type: ignore[return-value]
            abs(w - e) / e for w, e in zip(self.frequencies, self.exact_frequencies, strict=True)
        )

    def summary_line(self) -> str:
        """One line for the command line."""
        (w1, w2), (e1, e2) = self.frequencies, self.exact_frequencies
        r1, r2 = self.relative_errors
        return (
            f"double pendulum: omega {w1:.6f} and {w2:.6f} rad/s, exact {e1:.6f} and {e2:.6f} "
            f"(relative errors {r1:.1e}, {r2:.1e})"
        )


def run_double_pendulum(
    t_end: float = 20.0,
    dt: float = 1e-3,
    alpha: float = 0.5,
    model: DoublePendulum | None = None,
    progress: bool = False,
) -> DoublePendulumResult:
    """Simulate a small-amplitude double pendulum and measure its two frequencies.

    The rod angles are projected onto the linear normal modes (``eta = Phi^T M theta`` with
    M-normalised shapes ``Phi``); each modal coordinate then oscillates at one frequency, measured
    from its zero crossings.

    Arguments:
        t_end: duration, in s (several periods of the slow mode, 2.62 s for l = 1 m).
        dt: step size, in s.
        alpha: the integrator's parameter.
        model: the double pendulum (default: ``build_double_pendulum()``, which excites both
            modes).
        progress: draw a progress bar.

    Returns:
        The run with the modal coordinates (s, 2) and the measured frequencies.
    """
    model = model if model is not None else build_double_pendulum()
    solution = simulate(model.system, t_end, dt, alpha, progress=progress)
    angles, rates = double_pendulum_angles(model, solution)
    mass, shapes = _linear_modes()
    project = shapes.T @ mass
    modal = angles @ project.T
    modal_rates = rates @ project.T
    periods = [crossing_period(solution.times, modal[:, k], modal_rates[:, k]) for k in range(2)]
    frequencies = (2 * np.pi / periods[0], 2 * np.pi / periods[1])
    exact = normal_mode_frequencies(model.length, model.gravity)
    return DoublePendulumResult(model, solution, angles, modal, frequencies, exact)


# --------------------------------------------------------------------------------------------
# Hanging chain
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class HangingChain:
    """A chain of equal point masses joined by rigid massless links, hung from a fixed anchor."""

    system: System
    anchor: ParticleId
    particles: tuple[ParticleId, ...]
    links: tuple[ConstraintId, ...]
    link_length: float
    particle_mass: float
    gravity: float

    @property
    def total_length(self) -> float:
        """Length of the chain, in m."""
        return self.link_length * len(self.links)

    @property
    def total_mass(self) -> float:
        """Mass of the moving particles, in kg."""
        return self.particle_mass * len(self.particles)


def build_hanging_chain(
    num_links: int = 5,
    length: float = 1.0,
    mass: float = 1.0,
    gravity: float = GRAVITY,
    angle: float = np.pi / 3,
) -> HangingChain:
    """A chain released at rest from a straight shape tilted from the vertical.

    Arguments:
        num_links: number of links (and of moving particles, one at the end of each link).
        length: total length, in m.
        mass: total mass of the moving particles, in kg.
        gravity: g, in m/s^2 (acting along -z).
        angle: tilt of the straight initial shape from the downward vertical, in rad.

    Returns:
        The model; the anchor is a fixed particle at the origin.
    """
    if num_links < 1:
        from vinculo.errors import InvalidInputError

        raise InvalidInputError(
            f"num_links must be at least 1, got {num_links}", name="num_links", value=num_links
        )
    system = System(gravity=(0.0, 0.0, -gravity))
    link_length = length / num_links
    particle_mass = mass / num_links
    anchor = system.add_particle(particle_mass, (0.0, 0.0, 0.0), fixed=True)
    direction = np.array([np.sin(angle), 0.0, -np.cos(angle)])
    particles, links = [], []
    previous = anchor
    for k in range(1, num_links + 1):
        position = k * link_length * direction
        particle = system.add_particle(particle_mass, [float(c) for c in position])
        links.append(system.add_distance(previous, particle, link_length))
        particles.append(particle)
        previous = particle
    return HangingChain(
        system, anchor, tuple(particles), tuple(links), link_length, particle_mass, gravity
    )


@dataclass(frozen=True)
class HangingChainResult:
    """A chain run with its energy history."""

    model: HangingChain
    solution: Solution
    energy: np.ndarray

    @property
    def energy_scale(self) -> float:
        """``m g L`` of the whole chain, the scale of its energy changes, in J."""
        return self.model.total_mass * self.model.gravity * self.model.total_length

    @property
    def relative_energy_drift(self) -> float:
        """``max |E(t) - E(0)| / (m g L)`` over the run."""
        return float(np.max(np.abs(self.energy - self.energy[0])) / self.energy_scale)

    def summary_line(self) -> str:
        """One line for the command line."""
        return (
            f"hanging chain: {len(self.model.links)} links, {self.solution.num_steps} steps, "
            f"energy drift {self.relative_energy_drift:.1e} (relative to m g L), "
            f"max constraint residual {np.max(self.solution.constraint_residual):.1e} m"
        )


def run_hanging_chain(
    t_end: float = 5.0,
    dt: float = 1e-3,
    alpha: float = 0.5,
    model: HangingChain | None = None,
    progress: bool = False,
    **options: Any,
) -> HangingChainResult:
    """Simulate a chain released from a tilted straight shape.

    Arguments:
        t_end: duration, in s.
        dt: step size, in s.
        alpha: the integrator's parameter (1/2 conserves energy; more damps it).
        model: the chain (default: ``build_hanging_chain()``, 5 links tilted 60 degrees).
        progress: draw a progress bar.
        **options: run options of :func:`vinculo.simulate` (``jacobian_reuse``, ...).

    Returns:
        The run with its total energy at every stored time.
    """
    model = model if model is not None else build_hanging_chain()
    solution = simulate(model.system, t_end, dt, alpha, progress=progress, **options)
    return HangingChainResult(model, solution, solution.energy())


# --------------------------------------------------------------------------------------------
# Inclined plane
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class InclinedPlane:
    """A particle on a frictionless plane through the origin, inclined by ``angle`` about y.

    The plane's normal is ``normal_scale * (-sin th, 0, cos th)``; the downhill direction is
    ``-(cos th, 0, sin th)``.
    """

    system: System
    block: ParticleId
    plane: ConstraintId
    angle: float
    mass: float
    gravity: float
    normal_scale: float

    @property
    def downhill(self) -> np.ndarray:
        """Unit vector pointing down the slope."""
        return -np.array([np.cos(self.angle), 0.0, np.sin(self.angle)])


def build_inclined_plane(
    angle: float = np.radians(30.0),
    mass: float = 1.0,
    gravity: float = GRAVITY,
    normal_scale: float = 1.0,
) -> InclinedPlane:
    """A particle released at rest at the origin, on an inclined plane.

    Arguments:
        angle: inclination theta of the plane, in rad (0: horizontal).
        mass: in kg.
        gravity: g, in m/s^2 (acting along -z).
        normal_scale: length of the (not necessarily unit) normal vector given to the constraint.

    Returns:
        The model.
    """
    system = System(gravity=(0.0, 0.0, -gravity))
    block = system.add_particle(mass, (0.0, 0.0, 0.0))
    normal = [float(c) for c in normal_scale * np.array([-np.sin(angle), 0.0, np.cos(angle)])]
    plane = system.add_plane(block, normal, (0.0, 0.0, 0.0))
    return InclinedPlane(system, block, plane, angle, mass, gravity, normal_scale)


@dataclass(frozen=True)
class InclinedPlaneResult:
    """An inclined-plane run with the measured acceleration and normal force."""

    model: InclinedPlane
    solution: Solution
    acceleration: float
    normal_force: np.ndarray

    @property
    def exact_acceleration(self) -> float:
        """``g sin(theta)``, down the slope, in m/s^2."""
        return self.model.gravity * np.sin(self.model.angle)

    @property
    def exact_normal_force(self) -> float:
        """``m g cos(theta)``, in N."""
        return self.model.mass * self.model.gravity * np.cos(self.model.angle)

    def summary_line(self) -> str:
        """One line for the command line."""
        return (
            f"inclined plane: acceleration {self.acceleration:.9f} m/s^2 "
            f"(exact g sin th = {self.exact_acceleration:.9f}), normal force "
            f"{np.mean(self.normal_force):.9f} N (exact m g cos th = "
            f"{self.exact_normal_force:.9f})"
        )


def run_inclined_plane(
    t_end: float = 1.0,
    dt: float = 1e-3,
    alpha: float = 0.5,
    model: InclinedPlane | None = None,
    progress: bool = False,
) -> InclinedPlaneResult:
    """Simulate the sliding particle and measure its acceleration and the normal force.

    The acceleration is the quadratic coefficient (times 2) of a least-squares fit of the
    downhill distance against time; the normal force is ``lambda |n|`` (the constraint force is
    ``Phi_q^T lambda = n lambda``).

    Arguments:
        t_end: duration, in s.
        dt: step size, in s.
        alpha: the integrator's parameter.
        model: the plane (default: ``build_inclined_plane()``, 30 degrees, m = 1 kg).
        progress: draw a progress bar.

    Returns:
        The run with the measured acceleration (m/s^2) and normal force history (N).
    """
    model = model if model is not None else build_inclined_plane()
    solution = simulate(model.system, t_end, dt, alpha, progress=progress)
    distance = solution.particle(model.block) @ model.downhill
    coefficients = np.polynomial.polynomial.polyfit(solution.times, distance, 2)
    normal_force = solution.multiplier(model.plane) * model.normal_scale
    return InclinedPlaneResult(model, solution, float(2.0 * coefficients[2]), normal_force)
