"""The benchmark models, built identically in vinculo and (when installed) in Exudyn.

Every model is a set of point masses under gravity ``(0, 0, -9.81)`` linked by distance
constraints to a fixed anchor at the origin and to each other: a single pendulum (1 kg, 1 m,
released horizontally) and chains of N point masses (0.1 kg each, 0.1 m links unless stated),
either hanging straight down at rest (a static equilibrium: the test of pure throughput) or
released horizontally at rest (swinging: large motions, several Newton iterations per step).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

import vinculo

GRAVITY = 9.81


@dataclass(frozen=True)
class Chain:
    """N point masses in a row from a fixed anchor at the origin.

    Attributes:
        name: label for the tables.
        n: number of moving particles (1 with ``mass=1, link=1`` is the single pendulum).
        link: link length, in m.
        mass: mass of each particle, in kg.
        hanging: True: along -z at rest (equilibrium); False: along +x at rest (swinging).
        t_end: simulated time, in s.
        dt: step, in s.
    """

    name: str
    n: int
    link: float = 0.1
    mass: float = 0.1
    hanging: bool = True
    t_end: float = 1.0
    dt: float = 1e-3

    @property
    def steps(self) -> int:
        """Number of steps of the run."""
        return round(self.t_end / self.dt)

    def positions(self) -> np.ndarray:
        """Initial positions of the moving particles, shape (n, 3)."""
        s = self.link * np.arange(1, self.n + 1)
        out = np.zeros((self.n, 3))
        if self.hanging:
            out[:, 2] = -s
        else:
            out[:, 0] = s
        return out


def build_vinculo(model: Chain) -> tuple[vinculo.System, vinculo.ParticleId]:
    """The model as a vinculo System; returns it with the tip particle's handle."""
    system = vinculo.System(gravity=(0.0, 0.0, -GRAVITY))
    prev = system.add_particle(mass=1.0, position=(0.0, 0.0, 0.0), fixed=True)
    for p in model.positions():
        q = system.add_particle(mass=model.mass, position=tuple(p))
        system.add_distance(prev, q, length=model.link)
        prev = q
    return system, prev


def build_exudyn(model: Chain, exu):
    """The model in Exudyn: NodePoint + MassPoint per particle, DistanceConstraint per link,
    a NodePointGround anchor, gravity as a Force load m g on each particle.

    Returns:
        (system container, main system, tip node number).
    """
    from exudyn.itemInterface import (
        DistanceConstraint,
        Force,
        MarkerNodePosition,
        MassPoint,
        NodePoint,
        NodePointGround,
    )

    sc = exu.SystemContainer()
    mbs = sc.AddSystem()
    ground = mbs.AddNode(NodePointGround(referenceCoordinates=[0.0, 0.0, 0.0]))
    prev = mbs.AddMarker(MarkerNodePosition(nodeNumber=ground))
    node = ground
    for p in model.positions():
        node = mbs.AddNode(NodePoint(referenceCoordinates=[float(x) for x in p]))
        mbs.AddObject(MassPoint(mass=model.mass, nodeNumber=node))
        marker = mbs.AddMarker(MarkerNodePosition(nodeNumber=node))
        mbs.AddObject(DistanceConstraint(markerNumbers=[prev, marker], distance=model.link))
        mbs.AddLoad(Force(markerNumber=marker, loadVector=[0.0, 0.0, -model.mass * GRAVITY]))
        prev = marker
    mbs.Assemble()
    return sc, mbs, node


@dataclass(frozen=True)
class Integration:
    """The time integration both codes use for a row: generalised-alpha (index 3) with spectral
    radius ``rho_inf`` at the model's fixed step, and vinculo's Newton mode.

    Attributes:
        rho_inf: spectral radius at infinite frequency (0.9: Exudyn's default, damping only the
            highest frequencies; 0: the most damping, still second order).
        jacobian_reuse: vinculo's Newton: ``"auto"`` (its default), True (modified Newton,
            Exudyn's default mode) or False (full Newton).
    """

    rho_inf: float = 0.9
    jacobian_reuse: bool | str = "auto"

    def describe(self) -> str:
        """One line for the table headers."""
        newton = {"auto": "its default", True: "modified", False: "full"}[self.jacobian_reuse]
        return f"generalised-alpha rho_inf = {self.rho_inf:g}, vinculo with {newton} Newton"


#: The comparison rows: Exudyn's spectral radius, vinculo's default Newton.
COMPARISON = Integration(rho_inf=0.9)
#: The robustness rows (1 m chains released horizontally): the most high-frequency damping.
ROBUSTNESS = Integration(rho_inf=0.0)


def exudyn_settings(model: Chain, exu, dense: bool = False, rho_inf: float = 0.9):
    """Exudyn's generalised-alpha, index 3, at the fixed step ``model.dt``.

    Spectral radius ``rho_inf`` (0.9 is its default: with 1.0 Exudyn's index-3 solver fails
    within the first second on the pendulum and on swinging chains, and 0.99 fails on swinging
    chains too), its default Newton tolerances (relative 1e-8, absolute 1e-10) and modified
    Newton, no automatic step size, sparse (or dense) LU, no output written.

    Arguments:
        model: the run, anything with ``steps``, ``t_end`` and ``dt`` (a :class:`Chain` or a
            :class:`vinculo.bench.buoy.BuoyBench`).
        exu: the ``exudyn`` module.
        dense: Exudyn's dense LU instead of its sparse one.
        rho_inf: the spectral radius.
    """
    ss = exu.SimulationSettings()
    ti = ss.timeIntegration
    ti.numberOfSteps = model.steps
    ti.endTime = model.t_end
    ti.adaptiveStep = False
    ti.verboseMode = 0
    ti.generalizedAlpha.spectralRadius = rho_inf
    ti.generalizedAlpha.useIndex2Constraints = False
    ti.generalizedAlpha.useNewmark = False
    ss.linearSolver.solverType = (
        exu.LinearSolverType.EigenDense if dense else exu.LinearSolverType.EigenSparse
    )
    ss.solution.file.write = False
    ss.show.statistics = False
    ss.show.computationTime = False
    return ss
