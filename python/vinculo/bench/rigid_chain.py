"""A chain of rigid bodies linked by revolute joints, in vinculo and in Exudyn side by side.

``python -m vinculo.bench rigid-chain`` builds N slender links (cuboids L x w x w, 0.1 m x
0.01 m x 0.01 m of steel), the first hinged to the ground at the origin, each hinged to the next at
its far end, every hinge turning about y, released at rest along +x under gravity. Both codes run
generalised-alpha at index 3 with spectral radius 0.9 (Exudyn's default) at dt = 1 ms for 1 s:
Exudyn publishes this problem (400 bodies, dt = 1 ms, 1 s of simulated time in 5.0 s on four
threads) as a measure of its speed. The bodies are exactly the same in mass, centre and inertia;
the codes differ in their coordinates (vinculo's particles, Exudyn's Euler parameters), so their
discrete solutions differ by the schemes' errors, which the table reports: each code's error is
the largest distance of a link's centre at t_end from its own answer at dt/2, times 4/3 (second
order), and the gap is the largest distance between the two codes' centres. Speed is the wall
time of the integration, model building excluded, the best of ``repeat`` runs, each code on one
thread.
"""

from __future__ import annotations

import argparse
import time
from dataclasses import dataclass, replace

import numpy as np

import vinculo
from vinculo.bench.models import GRAVITY, exudyn_settings

#: Steel, kg/m^3.
DENSITY = 7800.0


@dataclass(frozen=True)
class RigidChain:
    """N links hinged end to end, released along +x.

    Attributes:
        n: number of bodies.
        link: length of a link, in m.
        width: side of a link's square section, in m.
        t_end: simulated time, in s.
        dt: step, in s.
    """

    n: int = 400
    link: float = 0.1
    width: float = 0.01
    t_end: float = 1.0
    dt: float = 1e-3

    @property
    def steps(self) -> int:
        """Number of steps of the run."""
        return round(self.t_end / self.dt)

    @property
    def mass(self) -> float:
        """Mass of a link, kg."""
        return DENSITY * self.link * self.width**2

    def inertia(self) -> np.ndarray:
        """Inertia tensor of a link about its centre, its length along x (kg m^2)."""
        m, a, b = self.mass, self.link, self.width
        return np.diag(
            [m * (b * b + b * b) / 12, m * (a * a + b * b) / 12, m * (a * a + b * b) / 12]
        )

    def centre(self, k: int) -> tuple[float, float, float]:
        """Initial centre of link k."""
        return ((k + 0.5) * self.link, 0.0, 0.0)


def build_vinculo(chain: RigidChain) -> tuple[vinculo.System, list[vinculo.Point]]:
    """The chain in vinculo: rigid bodies of four particles and revolute joints at points fixed
    in them; returns the system and the links' centres."""
    system = vinculo.System(gravity=(0.0, 0.0, -GRAVITY))
    previous = None
    centres = []
    inertia = chain.inertia().tolist()
    for k in range(chain.n):
        body = system.add_rigid_body(chain.mass, chain.centre(k), inertia, particles=4)
        system.add_joint("revolute", previous, body, (k * chain.link, 0.0, 0.0), (0.0, 1.0, 0.0))
        previous = body
        centres.append(body["centre"])
    return system, centres


def build_exudyn(chain: RigidChain, exu):
    """The chain in Exudyn: ``CreateRigidBody`` (Euler parameters) per link with the same mass,
    centre and inertia, ``CreateRevoluteJoint`` per hinge; returns (main system, last node)."""
    from exudyn.utilities import RigidBodyInertia

    sc = exu.SystemContainer()
    mbs = sc.AddSystem()
    previous = mbs.CreateGround(referencePosition=[0.0, 0.0, 0.0])
    inertia = RigidBodyInertia(mass=chain.mass, inertiaTensor=chain.inertia())
    nodes = []
    for k in range(chain.n):
        body = mbs.CreateRigidBody(
            referencePosition=list(chain.centre(k)),
            inertia=inertia,
            gravity=[0.0, 0.0, -GRAVITY],
            returnDict=True,
        )
        mbs.CreateRevoluteJoint(
            itemNumbers=[previous, body["bodyNumber"]],
            position=[k * chain.link, 0.0, 0.0],
            axis=[0.0, 1.0, 0.0],
            show=False,
        )
        previous = body["bodyNumber"]
        nodes.append(body["nodeNumber"])
    mbs.Assemble()
    return sc, mbs, nodes


@dataclass(frozen=True)
class Result:
    """One code's run: wall time of the best run, the links' centres at ``t_end`` (n, 3)."""

    seconds: float
    centres: np.ndarray
    note: str


def run_vinculo(
    chain: RigidChain, repeat: int = 1, jacobian_reuse: bool | str = False
) -> Result:
    """Best of ``repeat`` vinculo runs (generalised-alpha, rho_inf 0.9, index 3; full Newton
    unless ``jacobian_reuse`` says otherwise: ``"auto"``, its default, or True)."""
    system, centres = build_vinculo(chain)
    best = None
    for _ in range(repeat):
        start = time.perf_counter()
        solution = vinculo.simulate(
            system,
            t_end=chain.t_end,
            dt=chain.dt,
            scheme="generalized-alpha",
            rho_inf=0.9,
            save_every=chain.steps,
            jacobian_reuse=jacobian_reuse,
        )
        seconds = time.perf_counter() - start
        if best is None or seconds < best.seconds:
            # Run totals (only the last state is stored).
            note = (
                f"{solution.linear_solver}, {solution.residual_evaluations / chain.steps:.2f} "
                f"residuals/step, {solution.factorisations / chain.steps:.2f} factorisations/step"
            )
            best = Result(seconds, np.array([solution.point(c)[-1] for c in centres]), note)
    assert best is not None
    return best


def run_exudyn(chain: RigidChain, exu, repeat: int = 1) -> Result:
    """Best of ``repeat`` Exudyn runs (generalised-alpha, rho_inf 0.9, index 3, sparse LU, its
    default modified Newton and tolerances, one thread)."""
    from vinculo.bench.runner import _quiet

    best = None
    for _ in range(repeat):
        _, mbs, nodes = build_exudyn(chain, exu)
        settings = exudyn_settings(chain, exu, rho_inf=0.9)
        settings.parallel.numberOfThreads = 1
        start = time.perf_counter()
        with _quiet():
            ok = mbs.SolveDynamic(settings)
        seconds = time.perf_counter() - start
        if not ok:
            raise RuntimeError("Exudyn's SolveDynamic failed on the rigid chain")
        position = exu.OutputVariableType.Position
        centres = np.array([mbs.GetNodeOutput(node, position) for node in nodes])
        if best is None or seconds < best.seconds:
            best = Result(seconds, centres, "sparse LU, modified Newton")
    assert best is not None
    return best


def largest_distance(a: np.ndarray, b: np.ndarray) -> float:
    """The largest distance between corresponding rows of two (n, 3) arrays."""
    return float(np.max(np.linalg.norm(a - b, axis=1)))


def compare(chain: RigidChain, repeat: int = 3, out=print) -> dict[str, float]:
    """Runs both codes at ``chain.dt`` and at dt/2 (for their errors) and prints the table."""
    import exudyn as exu

    half = replace(chain, dt=chain.dt / 2)
    mine, theirs = run_vinculo(chain, repeat), run_exudyn(chain, exu, repeat)
    reuse = run_vinculo(chain, repeat, jacobian_reuse=True)
    default = run_vinculo(chain, repeat, jacobian_reuse="auto")
    mine_half, theirs_half = run_vinculo(half), run_exudyn(half, exu)
    error_mine = 4 / 3 * largest_distance(mine.centres, mine_half.centres)
    error_theirs = 4 / 3 * largest_distance(theirs.centres, theirs_half.centres)
    gap = largest_distance(mine.centres, theirs.centres)
    out(
        f"chain of {chain.n} rigid links, revolute joints, dt = {chain.dt * 1e3:g} ms, "
        f"{chain.t_end:g} s simulated; errors and gap: the largest over the links' centres"
    )
    out("| code | wall time (s) | steps/s | error (m) | notes |")
    out("|---|---:|---:|---:|---|")
    for name, run, error in (
        ("vinculo, default Newton", default, float("nan")),
        ("vinculo, full Newton", mine, error_mine),
        ("vinculo, modified Newton", reuse, float("nan")),
        ("Exudyn 1.13", theirs, error_theirs),
    ):
        out(
            f"| {name} | {run.seconds:.3f} | {chain.steps / run.seconds:.0f} | {error:.2e} | "
            f"{run.note} |"
        )
    ratio = theirs.seconds / default.seconds
    default_gap = largest_distance(default.centres, mine.centres)
    out(
        f"gap between the codes' answers: {gap:.2e} m (vinculo's default to its full Newton: "
        f"{default_gap:.2e} m); Exudyn / vinculo (default) time: {ratio:.2f}x"
    )
    return {
        "vinculo_default_s": default.seconds,
        "vinculo_s": mine.seconds,
        "vinculo_modified_s": reuse.seconds,
        "exudyn_s": theirs.seconds,
        "error_vinculo": error_mine,
        "error_exudyn": error_theirs,
        "gap": gap,
    }


def main(argv: list[str] | None = None) -> int:
    """``python -m vinculo.bench rigid-chain [--bodies N] [--t-end T] [--repeat K]``."""
    parser = argparse.ArgumentParser(
        prog="python -m vinculo.bench rigid-chain", description=__doc__
    )
    parser.add_argument("--bodies", type=int, default=400, help="number of links (400)")
    parser.add_argument("--t-end", type=float, default=1.0, help="simulated time, s (1)")
    parser.add_argument("--repeat", type=int, default=3, help="timed runs per code (3)")
    args = parser.parse_args(argv)
    compare(RigidChain(n=args.bodies, t_end=args.t_end), repeat=args.repeat)
    return 0
