"""The buoy of the case study as a benchmark row, in vinculo and (when installed) in Exudyn.

The model is the default :class:`~vinculo.buoy.case.BuoyCase` particle model
(:func:`vinculo.buoy.model.build_model`): a sphere made of 7 point masses held rigid by 15
distance constraints, tied by a string (a distance constraint) to an anchor that moves with the
tank, shaken at 0.9 Hz with the case's ramp, fluid forces on the centre particle.

The Exudyn model is read back from the built vinculo system, so that both codes integrate the same
equations: the particles' masses and initial positions, the constraints' particle pairs and
lengths. In Exudyn:

- each particle is a ``NodePoint`` with a ``MassPoint``; the centre's mass includes the added mass
  ``Ca rho V`` (vinculo puts it in the mass matrix on the centre's translation only);
- gravity is a constant ``Force`` load ``m g`` on each particle's own mass (not the added mass);
- the anchor is a ``NodePoint`` (with an arbitrary mass of 1 kg) whose three coordinates are held
  by ``CoordinateConstraint`` s to the ground, the x one with an offset user function giving the
  tank displacement ``X_t(t)``; the string is a ``DistanceConstraint`` from it to the attachment;
- the fluid force on the centre is a ``Force`` load with a Python user function:
  ``m_f (a_t - g) + Ca m_f a_t`` (buoyancy, Froude-Krylov and the known part of the added-mass
  force, a_t the tank's acceleration along x) plus the Morison drag
  ``1/2 rho Cd A |u_f - v| (u_f - v)`` with the centre's current velocity v. Exudyn calls the
  Python function at every residual evaluation, which costs it time that a built-in load would not.
"""

from __future__ import annotations

import re
import time
from dataclasses import dataclass, field

import numpy as np

import vinculo
from vinculo.bench.models import COMPARISON, Integration
from vinculo.bench.runner import Run, time_exudyn
from vinculo.buoy.case import BuoyCase
from vinculo.buoy.model import BuoyModel, build_model, tank_law
from vinculo.buoy.tank import tank_motion

#: Largest accepted gap between the two codes' buoy-centre x positions at t_end, in m.
#: Both codes use generalised-alpha with spectral radius 0.9 (vinculo's Newton stops at 1e-10 of
#: the length scale, Exudyn's at its own relative 1e-8), both second order.
#: At dt = 1e-3 over 20 s at 0.9 Hz (near the 0.92 Hz resonance; the centre is 43 mm off the
#: anchor at t_end), halving vinculo's step moves the centre by 1.0e-6 m, so either code's
#: discretisation error is about 1.3e-6 m (Richardson, second order), and the two codes agree to
#: 1e-7 m. The tolerance is ten times the discretisation error; a difference in the model moves
#: the centre by far more (without drag: 86 mm; without added mass: 43 mm; Cd 0.20 instead of
#: 0.22: 1.9 mm).
CENTRE_TOLERANCE = 1e-5

_PAIR = re.compile(r"\(particles (\d+)-(\d+)\)")
_MOVING = re.compile(r"to a moving point #\d+ \(particle (\d+)\)")


@dataclass(frozen=True)
class BuoyBench:
    """The buoy benchmark run.

    Attributes:
        name: label for the tables.
        case: the study's parameters (the default case unless given).
        frequency: excitation frequency, in Hz.
        t_end: simulated time, in s.
        dt: step, in s.
    """

    name: str = "buoy, 7 particles, 0.9 Hz, 20 s"
    case: BuoyCase = field(default_factory=BuoyCase)
    frequency: float = 0.9
    t_end: float = 20.0
    dt: float = 1e-3

    @property
    def steps(self) -> int:
        """Number of steps of the run."""
        return round(self.t_end / self.dt)

    def build(self) -> BuoyModel:
        """The vinculo particle model, the tank driven harmonically with the case's ramp."""
        return build_model(self.case, tank_law(self.case, self.frequency))


def run_vinculo_buoy(
    bench: BuoyBench, integration: Integration = COMPARISON, repeat: int = 1
) -> Run:
    """Best of ``repeat`` runs of the buoy in vinculo with ``integration`` (default tolerances).

    Arguments:
        bench: the run.
        integration: scheme parameters shared with Exudyn.
        repeat: number of timed runs.

    Returns:
        The :class:`~vinculo.bench.runner.Run`; its ``tip`` is the sphere centre's position at
        ``t_end``.
    """
    model = bench.build()
    best = None
    for _ in range(repeat):
        start = time.perf_counter()
        try:
            solution = vinculo.simulate(
                model.system, t_end=bench.t_end, dt=bench.dt, scheme="generalized-alpha",
                rho_inf=integration.rho_inf, jacobian_reuse=integration.jacobian_reuse,
                save_every=bench.steps,
            )
        except (vinculo.ConvergenceError, vinculo.NegativeTensionError) as error:
            return Run(time.perf_counter() - start, 0, None, f"failed: {error}")
        seconds = time.perf_counter() - start
        if best is None or seconds < best.seconds:
            # A run total (only the last state is stored).
            best = Run(
                seconds,
                bench.steps,
                solution.particle(model.centre)[-1],
                f"{solution.linear_solver}, "
                f"{solution.residual_evaluations / bench.steps:.2f} residuals/step",
            )
    assert best is not None
    return best


def model_topology(system: vinculo.System) -> tuple[list[tuple[int, int, float]], int, float]:
    """The links of a buoy model, read back from the vinculo system.

    Arguments:
        system: a system built by :func:`vinculo.buoy.model.build_model` with a massless string.

    Returns:
        ``(links, attachment, string_length)``: the particle pairs and lengths of the rigid
        body's distance constraints, the particle the string is tied to, and the string's length.

    Raises:
        ValueError: the system has other kinds of constraints, or a constraint's length differs
            from its particles' initial distance (the names were not read correctly).
    """
    positions = system.initial_positions()
    lengths = system.constraint_lengths
    links: list[tuple[int, int, float]] = []
    anchored: list[tuple[int, float]] = []
    for name, length in zip(system.constraint_names(), lengths, strict=True):
        pair, moving = _PAIR.search(name), _MOVING.search(name)
        if pair is not None:
            i, j = int(pair.group(1)), int(pair.group(2))
            gap = float(np.linalg.norm(positions[i] - positions[j]))
            if abs(gap - length) > 1e-12:
                raise ValueError(f"constraint {name!r}: length {length} but particles {gap} apart")
            links.append((i, j, float(length)))
        elif moving is not None:
            anchored.append((int(moving.group(1)), float(length)))
        else:
            raise ValueError(f"constraint {name!r} has no Exudyn counterpart in this benchmark")
    if len(anchored) != 1:
        raise ValueError(f"expected one string link to the anchor, found {len(anchored)}")
    return links, *anchored[0]


def build_exudyn_buoy(bench: BuoyBench, exu):
    """The buoy in Exudyn (see the module's description), from the vinculo model.

    Arguments:
        bench: the run.
        exu: the ``exudyn`` module.

    Returns:
        ``(system container, main system, centre node, anchor node)``.
    """
    from exudyn.itemInterface import (
        CoordinateConstraint,
        DistanceConstraint,
        Force,
        MarkerNodeCoordinate,
        MarkerNodePosition,
        MassPoint,
        NodePoint,
        NodePointGround,
    )

    case = bench.case
    model = bench.build()
    system = model.system
    links, attachment, string_length = model_topology(system)
    positions = system.initial_positions()
    masses = system.masses()
    inertia = system.inertia  # mass + added mass (on the centre)
    gravity = np.asarray(system.gravity)

    sc = exu.SystemContainer()
    mbs = sc.AddSystem()
    nodes, markers = [], []
    for k in range(len(masses)):
        node = mbs.AddNode(NodePoint(referenceCoordinates=[float(x) for x in positions[k]]))
        mbs.AddObject(MassPoint(mass=float(inertia[k]), nodeNumber=node))
        marker = mbs.AddMarker(MarkerNodePosition(nodeNumber=node))
        mbs.AddLoad(Force(markerNumber=marker, loadVector=[float(x) for x in masses[k] * gravity]))
        nodes.append(node)
        markers.append(marker)
    for i, j, length in links:
        mbs.AddObject(DistanceConstraint(markerNumbers=[markers[i], markers[j]], distance=length))

    # The anchor: a point node whose coordinates follow the tank floor.
    motion = tank_motion(case, bench.frequency)
    ground = mbs.AddNode(NodePointGround(referenceCoordinates=[0.0, 0.0, 0.0]))
    ground_marker = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=ground, coordinate=0))
    anchor = mbs.AddNode(NodePoint(referenceCoordinates=[0.0, 0.0, 0.0]))
    mbs.AddObject(MassPoint(mass=1.0, nodeNumber=anchor))

    def tank_x(mbs, t, item, offset):
        return motion.at(t)[0]

    for axis in range(3):
        coordinate = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=anchor, coordinate=axis))
        mbs.AddObject(
            CoordinateConstraint(
                markerNumbers=[ground_marker, coordinate],
                offset=0.0,
                offsetUserFunction=tank_x if axis == 0 else 0,
            )
        )
    anchor_marker = mbs.AddMarker(MarkerNodePosition(nodeNumber=anchor))
    mbs.AddObject(
        DistanceConstraint(
            markerNumbers=[anchor_marker, markers[attachment]], distance=string_length
        )
    )

    # Fluid forces on the centre (particle 0 of the rigid body).
    centre = model.centre.index
    displaced = case.displaced_mass
    ca = case.added_mass_coefficient
    drag = 0.5 * case.fluid_density * case.drag_coefficient * case.frontal_area
    velocity = exu.OutputVariableType.Velocity
    current = exu.ConfigurationType.Current
    centre_node = nodes[centre]

    def fluid_force(mbs, t, load):
        _, u, a = motion.at(t)
        v = mbs.GetNodeOutput(centre_node, velocity, configuration=current)
        rx, ry, rz = u - v[0], -v[1], -v[2]
        c = drag * (rx * rx + ry * ry + rz * rz) ** 0.5
        return [
            displaced * (1.0 + ca) * a - displaced * gravity[0] + c * rx,
            -displaced * gravity[1] + c * ry,
            -displaced * gravity[2] + c * rz,
        ]

    mbs.AddLoad(
        Force(
            markerNumber=markers[centre],
            loadVector=[0.0, 0.0, 0.0],
            loadVectorUserFunction=fluid_force,
        )
    )
    mbs.Assemble()
    return sc, mbs, centre_node, anchor


def run_exudyn_buoy(
    bench: BuoyBench, exu, integration: Integration = COMPARISON, repeat: int = 1
) -> Run:
    """Best of ``repeat`` runs of the buoy in Exudyn (settings of
    :func:`vinculo.bench.models.exudyn_settings`), the faster of its dense and sparse LU kept.

    Arguments:
        bench: the run.
        exu: the ``exudyn`` module.
        repeat: number of timed runs per linear solver.

    Returns:
        The :class:`~vinculo.bench.runner.Run`; its ``tip`` is the sphere centre's position at
        ``t_end``.
    """
    def build():
        _, mbs, centre, _anchor = build_exudyn_buoy(bench, exu)
        return mbs, centre

    return time_exudyn(build, bench, exu, integration, repeat, (False, True))
