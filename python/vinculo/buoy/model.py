"""The particle model of the buoy (paper 3.3): a rigid sphere of 7 particles tied by a string.

The sphere is :meth:`vinculo.System.add_rigid_body` with the sphere's mass, centre and inertia
``2/5 m_s R^2``: an octahedron of six particles of ``m_s / 10`` at distance R around a centre
particle of ``0.4 m_s``, held rigid by 15 distance constraints. Its lowest vertex is the string's
attachment (``attachment="bottom"``), or the string is tied to the centre particle
(``attachment="centre"``). The fluid forces act on the centre particle
(:meth:`vinculo.System.add_morison`): buoyancy and Froude-Krylov, added mass on the translation
only, Morison drag, the fluid moving rigidly with the tank; with ``viscous_force = "stokes-layer"``
also the Stokes layer's damping and added mass (:meth:`vinculo.buoy.case.BuoyCase.stokes_layer`)
on the motion relative to the fluid. The string is a tension-only distance
from the anchor, which moves with the tank floor, to the attachment; with ``string_beads = n`` it
is a chain of n point masses (``string_mass / n`` each) and n + 1 equal links. A run stops with
:class:`vinculo.NegativeTensionError` at the first time a link would have to push.

Coordinates: x along the shaking, z up, the anchor at the origin when the tank is at rest.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass
from typing import Any

import numpy as np

import vinculo
from vinculo.buoy.case import BuoyCase
from vinculo.buoy.tank import MeasuredTankMotion, TankMotion, tank_motion
from vinculo.errors import InvalidInputError

__all__ = ["BuoyModel", "ParticleRun", "build_model", "run_particle_model"]


@dataclass
class BuoyModel:
    """A built particle model and the handles needed to read its results.

    Attributes:
        system: the :class:`vinculo.System`.
        centre: the sphere's centre particle.
        attachment: the particle the string is tied to.
        body: the dict returned by ``System.add_rigid_body``.
        links: the string's constraints, from the anchor to the attachment.
        beads: the string's point masses (empty for a massless string).
        link_length: length of each link (m).
        tank: the tank's displacement as a :class:`vinculo.Law` of time.
    """

    system: vinculo.System
    centre: vinculo.ParticleId
    attachment: vinculo.ParticleId
    body: dict[str, Any]
    links: list[vinculo.ConstraintId]
    beads: list[vinculo.ParticleId]
    link_length: float
    tank: vinculo.Law


def tank_law(case: BuoyCase, frequency: float) -> vinculo.Law:
    """The tank displacement ``X0 s(t) sin(2 pi f t)`` with the case's ramp, as a core law.

    Arguments:
        case: the parameters (amplitude X0 and ramp_periods are used).
        frequency: excitation frequency f, in Hz (> 0).

    Returns:
        The law (its derivatives are the tank's velocity and acceleration).

    Raises:
        InvalidInputError: the frequency is not finite and positive.
    """
    return tank_motion(case, frequency).law()  # validates the frequency


def build_model(
    case: BuoyCase,
    tank: vinculo.Law | float = 0.0,
    initial_rates: tuple[float, float] = (0.0, 0.0),
    *,
    frequency: float | None = None,
    duration: float | None = None,
    dt: float = 1e-3,
    state: tuple[np.ndarray, np.ndarray] | None = None,
) -> BuoyModel:
    """Build the particle model of ``case`` with the tank moving by ``tank`` (x displacement).

    Arguments:
        case: the study's parameters.
        tank: the tank's displacement X_t(t) along x (for example :func:`tank_law`, or a
            ``vinculo.tabulated`` law of measured displacements); a number for a tank at rest.
        initial_rates: initial angular rates (rad/s) of the string and of the sphere about the
            attachment, positive towards +x (free-vibration studies; only with a massless string).
        frequency: the frequency (Hz) at which the Stokes-layer force is evaluated
            (``case.viscous_force = "stokes-layer"`` only); default: the 2-DOF model's swing
            frequency.
        duration: with the Stokes layer and a moving tank, how long (s) the model will be run:
            the force ``c u_f(t)`` of the moving fluid is tabulated over it.
        dt: spacing (s) of that table (a natural cubic spline; the run's step is a good choice).
        state: ``(positions, velocities)``, arrays (n, 3), of every particle of a model of the
            same case (the last row of a run's ``Solution``), to continue that run: the sphere's
            7 particles and 15 distances are then built explicitly at those positions, the same
            particles in the same order as ``System.add_rigid_body`` makes them, and the beads
            too; ``initial_rates`` is then ignored.

    Returns:
        The :class:`BuoyModel`, upright (string vertical) at t = 0, at rest unless
        ``initial_rates`` are given.

    Raises:
        InvalidInputError: the Stokes layer with a moving tank and no ``duration``.
    """
    moving = isinstance(tank, vinculo.Law)
    if not moving:
        tank = vinculo.constant(float(tank))
    system = vinculo.System(gravity=(0.0, 0.0, -case.gravity))
    radius = case.radius
    centre_height = case.pendulum_length
    attach_height = centre_height - radius if case.attachment == "bottom" else centre_height
    inertia = case.centre_inertia
    # Rates: the attachment moves at l th1' along x; the sphere turns at th2' about +y.
    string_rate, sphere_rate = initial_rates
    if state is None:
        body = system.add_rigid_body(
            case.sphere_mass,
            (0.0, 0.0, centre_height),
            [[inertia, 0.0, 0.0], [0.0, inertia, 0.0], [0.0, 0.0, inertia]],
            velocity=(attach_height * string_rate + (centre_height - attach_height) * sphere_rate,
                      0.0, 0.0),
            angular_velocity=(0.0, sphere_rate, 0.0),
            points=[(0.0, 0.0, attach_height)],
        )
    else:
        body = _sphere_at(system, case, state)
    centre = body["centre"]
    attachment = body["points"][0]
    damping, viscous_mass = _stokes_layer(case, frequency)
    system.add_morison(
        centre,
        volume=case.volume,
        area=case.frontal_area,
        drag_coefficient=case.drag_coefficient,
        # the Stokes layer's added mass acts, like Morison's, on the acceleration relative to the
        # fluid: m_v (a_f - b'') is Morison's term with Ca raised by m_v / (rho V)
        added_mass_coefficient=case.added_mass_coefficient + viscous_mass / case.displaced_mass,
        density=case.fluid_density,
        fluid_motion=(tank, 0.0, 0.0),
    )
    if damping > 0.0:
        # -c (b' - u_f) = -c b' + c u_f(t): a linear drag and a force that follows the fluid
        system.add_linear_drag(centre, damping)
        if moving:
            system.add_force(centre, (_fluid_force(tank, damping, duration, dt), 0.0, 0.0))
    n = case.string_beads
    link = case.string_length / (n + 1)
    if state is None:
        beads = [
            system.add_particle(case.string_mass / n, (0.0, 0.0, link * (k + 1)))
            for k in range(n)
        ]
    else:
        beads = [
            system.add_particle(case.string_mass / n, state[0][7 + k], state[1][7 + k])
            for k in range(n)
        ]
    ends = [*beads, attachment]
    links = [system.add_distance_to_point(ends[0], (tank, 0.0, 0.0), length=link)]
    links += [system.add_distance(a, b, length=link) for a, b in itertools.pairwise(ends)]
    for c in links:
        system.set_tension_only(c)
    return BuoyModel(system, centre, attachment, body, links, beads, link, tank)


def _sphere_at(
    system: vinculo.System, case: BuoyCase, state: tuple[np.ndarray, np.ndarray]
) -> dict[str, Any]:
    """The sphere's 7 particles at ``state``'s first 7 rows, made rigid explicitly.

    Same layout as ``System.add_rigid_body`` for an isotropic body: the centre (0.4 m_s), then
    the vertices +x, -x, +y, -y, +z, -z (m_s / 10 each); the 12 edges of the octahedron
    (length R sqrt 2) and the centre's distances to +x, +y, +z (R): 15 independent distances.
    The attachment is vertex -z ("bottom") or the centre ("centre").
    """
    positions, velocities = (np.asarray(a, dtype=np.float64) for a in state)
    if positions.shape[0] < 7 + case.string_beads or positions.shape != velocities.shape:
        raise InvalidInputError(
            f"state must hold the positions and velocities of the model's "
            f"{7 + case.string_beads} particles, got shapes {positions.shape} and "
            f"{velocities.shape}",
            name="state",
            value=positions.shape,
        )
    masses = [0.4 * case.sphere_mass] + [0.1 * case.sphere_mass] * 6
    particles = [
        system.add_particle(mass, positions[k], velocities[k]) for k, mass in enumerate(masses)
    ]
    radius = case.radius
    constraints = [
        system.add_distance(particles[a], particles[b], length=radius * math.sqrt(2.0))
        for a, b in itertools.combinations(range(1, 7), 2)
        if not (a % 2 == 1 and b == a + 1)  # not opposite vertices
    ]
    constraints += [system.add_distance(particles[0], particles[k], length=radius)
                    for k in (1, 3, 5)]
    attachment = particles[6] if case.attachment == "bottom" else particles[0]
    return {"centre": particles[0], "vertices": particles[1:], "points": [attachment],
            "particles": particles, "constraints": constraints}


def _stokes_layer(case: BuoyCase, frequency: float | None) -> tuple[float, float]:
    """``(c, m_v)`` of the Stokes layer at ``frequency`` (the swing's by default), or zeros."""
    if case.viscous_force != "stokes-layer":
        return 0.0, 0.0
    if frequency is None:
        from vinculo.buoy.reference import TwoDofModel

        return TwoDofModel(case).viscous_terms(None)
    return case.stokes_layer(frequency)


def _fluid_force(tank: vinculo.Law, damping: float, duration: float | None, dt: float) -> Any:
    """``c u_f(t)`` as a core law: a natural spline through its values every ``dt`` s."""
    if duration is None or not (math.isfinite(duration) and duration > 0.0):
        raise InvalidInputError(
            f"the Stokes-layer force of a moving tank needs the run's duration, got {duration!r}; "
            f"pass duration= (s) to build_model",
            name="duration",
            value=duration,
        )
    count = math.ceil(duration / dt) + 3  # a little beyond the end: the law is defined on it
    times = np.arange(count + 1) * dt
    velocity = np.fromiter((tank.derivatives(t)[1] for t in times), np.float64, len(times))
    return vinculo.tabulated(times, damping * velocity)


@dataclass
class ParticleRun:
    """Time histories of one run of the particle model.

    Attributes:
        frequency: excitation frequency (Hz).
        time: sample times (s).
        tank: tank displacement X_t (m).
        buoy: horizontal displacement of the sphere's centre (m, absolute).
        relative: ``buoy - tank`` (m): the centre relative to the tank.
        height: height of the centre above the tank floor (m).
        tension: string tension at the anchor (N), from the link's multiplier.
        solution: the full :class:`vinculo.Solution`.
        error: None, or the exception that stopped the run early (the histories then end there).
        model: the :class:`BuoyModel` that was simulated (its handles locate the sphere, the
            string's beads and the attachment in ``solution``).
    """

    frequency: float
    time: np.ndarray
    tank: np.ndarray
    buoy: np.ndarray
    relative: np.ndarray
    height: np.ndarray
    tension: np.ndarray
    solution: vinculo.Solution
    error: vinculo.VinculoError | None = None
    model: BuoyModel | None = None


def run_particle_model(
    case: BuoyCase,
    frequency: float,
    t_end: float,
    *,
    dt: float = 1e-3,
    save_every: int = 5,
    tank: vinculo.Law | TankMotion | MeasuredTankMotion | None = None,
    progress: Any = None,
    t_start: float = 0.0,
    state: tuple[np.ndarray, np.ndarray] | None = None,
) -> ParticleRun:
    """Simulate the particle model at one frequency from rest.

    Arguments:
        case: the study's parameters.
        frequency: excitation frequency (Hz); used for the tank law unless ``tank`` is given,
            and for the Stokes-layer force (a measured record's own frequency replaces it).
        t_end: duration (s).
        dt: time step (s).
        save_every: keep every k-th step.
        tank: the tank's motion, instead of the harmonic one at ``frequency``: a core law of the
            displacement, or a motion object such as a measured record
            (:func:`vinculo.buoy.tank.read_tank_motion`), whose fit becomes the law.
        progress: passed to :func:`vinculo.simulate`.
        t_start: the time at which the run starts, in s (with ``state``: the time of that state).
        state: ``(positions, velocities)`` of every particle at ``t_start``, to continue an
            earlier run (its ``solution.positions[-1]``, ``solution.velocities[-1]``); default:
            upright and at rest.

    Returns:
        The :class:`ParticleRun`. A run stopped early by a negative string tension or a failed step
        keeps what it computed and carries the exception in ``error``.
    """
    if tank is None:
        law = tank_law(case, frequency)
    elif isinstance(tank, vinculo.Law):
        law = tank
    else:
        law = tank.law()
        frequency = tank.frequency
    model = build_model(case, law, frequency=frequency, duration=t_end, dt=dt, state=state)
    # The index-3 rule holds the velocity constraints only to its accuracy (about 1e-7 m/s at
    # the default step, growing as dt^2), so a continued state violates them by that much:
    # accept it, as the run would have gone on with it (a continued run matches an
    # uninterrupted one to round-off), rather than project it (the projection evaluates the
    # moving anchor at t = 0, not at t_start).
    initial_tolerance = 1e-8 if state is None else 1e-2
    error: vinculo.VinculoError | None = None
    try:
        solution = vinculo.simulate(
            model.system, t_end=t_end, dt=dt, save_every=save_every, progress=progress,
            t_start=t_start, initial_tolerance=initial_tolerance,
        )
    except (vinculo.ConvergenceError, vinculo.NegativeTensionError) as e:
        error, solution = e, e.solution
    time = solution.times
    tank_x = _evaluate(law, time)
    centre = solution.particle(model.centre)
    tension = solution.distance_tension(model.links[0])
    return ParticleRun(
        frequency=frequency,
        time=time,
        tank=tank_x,
        buoy=centre[:, 0],
        relative=centre[:, 0] - tank_x,
        height=centre[:, 2],
        tension=tension,
        solution=solution,
        error=error,
        model=model,
    )


def _evaluate(law: vinculo.Law, times: np.ndarray) -> np.ndarray:
    """Values of a core law at many times."""
    return np.fromiter((law(t) for t in times), dtype=np.float64, count=len(times))
