"""Cost per step of a hanging chain against its length: tree elimination and sparse LU.

A chain of N beads hanging from a pivot and swinging has a tree-shaped constraint graph, so vinculo
solves its Newton systems by the tree elimination, in time linear in N. The run option
``linear_solver="sparse-lu"`` solves the same chain by the general sparse LU instead. The script
times a few steps of both for N from 100 to 6400 and fits the exponent of N.
Timings depend on the machine and its load; the fitted exponents are what to look at.

    python examples/tree_scaling.py [--plot tree_scaling.png]
"""

import argparse
import time
from itertools import pairwise

import numpy as np

import vinculo

G = 9.81


def chain(beads: int) -> vinculo.System:
    """A 1 m chain of ``beads`` beads swinging from 30 degrees."""
    system = vinculo.System(gravity=(0.0, 0.0, -G))
    pivot = system.add_particle(mass=1.0, position=(0.0, 0.0, 0.0), fixed=True)
    direction = np.array([np.sin(np.pi / 6), 0.0, -np.cos(np.pi / 6)])
    particles = [system.add_particle(mass=1.0 / beads, position=tuple(direction * k / beads))
                 for k in range(1, beads + 1)]
    for a, b in pairwise([pivot, *particles]):
        system.add_distance(a, b, length=1.0 / beads)
    return system


def seconds_per_step(beads: int, linear_solver: str, steps: int = 10) -> tuple[float, str]:
    """Wall time per step (best of 2 runs) with the run option ``linear_solver``, and the linear
    solver used."""
    best, solver = np.inf, ""
    for _ in range(2):
        system = chain(beads)
        start = time.perf_counter()
        solution = vinculo.simulate(system, t_end=steps * 1e-3, dt=1e-3,
                                    linear_solver=linear_solver)
        best = min(best, (time.perf_counter() - start) / steps)
        solver = solution.linear_solver
    return best, solver


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--plot", metavar="FILE", help="write a PNG figure to FILE")
    args = parser.parse_args()

    sizes = np.array([100, 200, 400, 800, 1600, 3200, 6400])
    results = {}
    for linear_solver in ("auto", "sparse-lu"):
        timings = [seconds_per_step(n, linear_solver) for n in sizes]
        seconds = np.array([t for t, _ in timings])
        solvers = sorted({s for _, s in timings})
        exponent = np.polyfit(np.log(sizes), np.log(seconds), 1)[0]
        name = "chain (a tree)" if linear_solver == "auto" else "chain by the sparse LU"
        results[name] = seconds
        print(f"{name}: linear solver {', '.join(solvers)}; time per step grows as "
              f"N^{exponent:.2f}; {seconds[-1] * 1e3:.2f} ms per step at N = {sizes[-1]}")

    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(6.5, 4.2), layout="constrained")
        for (name, seconds), marker in zip(results.items(), ("o-", "s--"), strict=True):
            ax.loglog(sizes, seconds * 1e3, marker, ms=4, label=name)
        ax.loglog(sizes, results["chain (a tree)"][0] * 1e3 * sizes / sizes[0], "k:", lw=1,
                  label="proportional to N")
        ax.set(xlabel="beads N", ylabel="ms per step (Newton to convergence)",
               title="cost of a step against the chain's length")
        ax.legend(fontsize=8)
        fig.savefig(args.plot, dpi=110)
        print(f"plot: {args.plot}")


if __name__ == "__main__":
    main()
