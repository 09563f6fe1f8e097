"""A chain of beads, released horizontally and swinging; then hanging at rest.

N beads of mass m on massless links of length l hang from a fixed pivot. Released from the
horizontal at rest, the chain whips down; the trapezoidal rule (alpha = 1/2) keeps its energy
constant to the Newton tolerance, and the links hold their lengths to round-off. The constraint
graph is a tree, so every Newton step is solved by the tree elimination, in time linear in N.
Hanging at rest, link k (k = 1 at the pivot) carries the weight of the beads below it,
(N - k + 1) m g: the closed form the multipliers are compared with.

    python examples/chain.py [--beads 20] [--plot chain.png]
"""

import argparse
from itertools import pairwise

import numpy as np

import vinculo

G = 9.81


def build(beads: int, link: float, mass: float, hanging: bool):
    """A chain of ``beads`` beads from a pivot at the origin, horizontal or hanging."""
    system = vinculo.System(gravity=(0.0, 0.0, -G))
    pivot = system.add_particle(mass=1.0, position=(0.0, 0.0, 0.0), fixed=True)
    points = [(0.0, 0.0, -link * k) if hanging else (link * k, 0.0, 0.0)
              for k in range(1, beads + 1)]
    particles = [system.add_particle(mass=mass, position=p) for p in points]
    links = [system.add_distance(a, b, length=link) for a, b in pairwise([pivot, *particles])]
    return system, particles, links


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--beads", type=int, default=20, help="number of beads (default 20)")
    parser.add_argument("--plot", metavar="FILE", help="write a PNG figure to FILE")
    args = parser.parse_args()
    n, length, mass = args.beads, 1.0, 0.05
    link = length / n

    system, _, links = build(n, link, mass, hanging=False)
    solution = vinculo.simulate(system, t_end=2.0, dt=1e-3)
    print(solution.summary())
    energy = solution.energy()
    scale = n * mass * G * length
    print(f"linear solver: {solution.linear_solver}")
    print(f"largest energy change: {np.max(np.abs(energy - energy[0])) / scale:.1e} of N m g L")
    print(f"largest constraint residual: {np.max(solution.constraint_residual):.1e} m")
    top = solution.distance_tension(links[0], link)

    still, _, still_links = build(n, link, mass, hanging=True)
    rest = vinculo.simulate(still, t_end=0.1, dt=1e-2)
    tensions = np.array([rest.distance_tension(c, link)[-1] for c in still_links])
    weights = mass * G * np.arange(n, 0, -1)
    print(f"hanging: top tension {tensions[0]:.10f} N, weight {weights[0]:.10f} N, "
          f"largest error {np.max(np.abs(tensions - weights)):.1e} N")

    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, axes = plt.subplots(1, 3, figsize=(12, 3.8), layout="constrained")
        colours = plt.cm.viridis(np.linspace(0.0, 0.9, 6))
        for colour, time in zip(colours, np.linspace(0.0, 0.75, 6), strict=True):
            row = int(np.searchsorted(solution.times, time))
            xs = np.concatenate([[0.0], solution.positions[row, 1:, 0]])
            zs = np.concatenate([[0.0], solution.positions[row, 1:, 2]])
            axes[0].plot(xs, zs, "-o", ms=2, color=colour, label=f"t = {time:.2f} s")
        axes[0].set(xlabel="x (m)", ylabel="z (m)", title="snapshots", aspect="equal")
        axes[0].legend(fontsize=7)
        axes[1].plot(solution.times, top)
        axes[1].set(xlabel="t (s)", ylabel="tension (N)", title="top link tension")
        k = np.arange(1, n + 1)
        axes[2].plot(k, weights, "k-", label="(N - k + 1) m g")
        axes[2].plot(k, tensions, "o", ms=4, label="vinculo")
        axes[2].set(xlabel="link k", ylabel="tension (N)", title="hanging at rest")
        axes[2].legend(fontsize=8)
        fig.savefig(args.plot, dpi=110)
        print(f"plot: {args.plot}")


if __name__ == "__main__":
    main()
