"""``python -m vinculo.bench work-precision``: error against CPU time of error-controlled runs.

For each problem of :mod:`vinculo.bench.problems` (pendulum, chain of three, two-particle
mechanism with a moving plane) and each tolerance rtol = atol from 1e-3 to 1e-10: vinculo's
error-controlled trapezoidal rule and generalised-alpha (rho_inf = 0.5), index 3, and scipy's
Radau (order 5, implicit) on the same motion in minimal coordinates (the angles of the links:
an ODE, the easiest form for a peer). The error is the largest distance of a bob from the
reference (DOP853 at 1e-13) over 201 output times; CPU time is the process time of the
integration alone (model building and reference excluded), best of ``repeat`` runs.
"""

from __future__ import annotations

import argparse
import sys
import time
from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp

import vinculo
from vinculo.bench.problems import PROBLEMS, Problem

#: The tolerances of the table (rtol = atol).
TOLERANCES = tuple(10.0**-k for k in range(3, 11))
#: vinculo's schemes of the table, by column label.
SCHEMES = {
    "vinculo trapezoidal": {"scheme": "trapezoidal"},
    "vinculo gen.-alpha 0.5": {"scheme": "generalized-alpha", "rho_inf": 0.5},
}
#: The peer's column label.
RADAU = "scipy Radau (ODE)"
#: Output times of every run (evenly spaced over the run, ends included).
OUTPUTS = 201


@dataclass(frozen=True)
class Point:
    """One run of the table.

    Attributes:
        problem: the problem's key in :data:`vinculo.bench.problems.PROBLEMS`.
        method: the column label.
        tol: rtol = atol.
        error: largest position error of a bob over the output times, m (nan: the run failed).
        cpu: CPU time of the integration, s.
        steps: steps taken (vinculo: attempted steps; Radau: its steps).
    """

    problem: str
    method: str
    tol: float
    error: float
    cpu: float
    steps: int


def _times(problem: Problem) -> np.ndarray:
    return np.linspace(0.0, problem.t_end, OUTPUTS)


def run_vinculo(key: str, method: str, tol: float, repeat: int = 1) -> Point:
    """The point of vinculo's ``method`` on problem ``key`` at ``tol``.

    Arguments:
        key: the problem's key.
        method: a key of :data:`SCHEMES`.
        tol: rtol = atol.
        repeat: runs to take the best CPU time of.

    Returns:
        The point (error nan when the run stopped with an error).
    """
    problem = PROBLEMS[key]
    times = _times(problem)
    best, solution, bobs = float("inf"), None, None
    for _ in range(repeat):
        system, bobs = problem.build()
        start = time.process_time()
        try:
            solution = vinculo.simulate(
                system, problem.t_end, 1e-3, adaptive=True, rtol=tol, atol=tol, t_eval=times,
                **SCHEMES[method],
            )
        except vinculo.VinculoError:
            return Point(key, method, tol, float("nan"), float("nan"), 0)
        best = min(best, time.process_time() - start)
    assert solution is not None and bobs is not None
    q = np.stack([solution.particle(b) for b in bobs], axis=1)
    reference, _ = problem.reference(times)
    error = float(np.max(np.linalg.norm(q - reference, axis=2)))
    return Point(key, method, tol, error, best, solution.steps_taken)


def run_radau(key: str, tol: float, repeat: int = 1) -> Point:
    """The point of scipy's Radau on the minimal-coordinate ODE of problem ``key`` at ``tol``.

    Arguments:
        key: the problem's key.
        tol: rtol = atol (on the angles, rad, and their rates, rad/s).
        repeat: runs to take the best CPU time of.

    Returns:
        The point.
    """
    problem = PROBLEMS[key]
    times = _times(problem)
    rhs, y0 = problem.rhs(), problem.initial()
    best, result = float("inf"), None
    for _ in range(repeat):
        start = time.process_time()
        result = solve_ivp(
            rhs, (0.0, problem.t_end), y0, method="Radau", rtol=tol, atol=tol, t_eval=times
        )
        best = min(best, time.process_time() - start)
    assert result is not None
    if not result.success:
        return Point(key, RADAU, tol, float("nan"), float("nan"), 0)
    q, _ = problem.cartesian(times, result.y.T)
    reference, _ = problem.reference(times)
    error = float(np.max(np.linalg.norm(q - reference, axis=2)))
    return Point(key, RADAU, tol, error, best, int(result.nfev))


def measure(
    problems: tuple[str, ...] = tuple(PROBLEMS),
    tolerances: tuple[float, ...] = TOLERANCES,
    repeat: int = 1,
) -> list[Point]:
    """Every point of the table.

    Arguments:
        problems: keys of the problems.
        tolerances: the tolerances.
        repeat: runs per point to take the best CPU time of.

    Returns:
        The points, by problem, tolerance and method.
    """
    points = []
    for key in problems:
        for tol in tolerances:
            for method in SCHEMES:
                points.append(run_vinculo(key, method, tol, repeat))
            points.append(run_radau(key, tol, repeat))
    return points


def table(points: list[Point], out=print) -> None:
    """Prints the table: per problem and tolerance, each method's error (m), error / tol and CPU
    time (ms); Radau's steps column counts its right-hand-side evaluations."""
    methods = list(dict.fromkeys(p.method for p in points))
    header = f"{'problem':<13} {'tol':>6} " + " ".join(f"{m:>34}" for m in methods)
    out(header)
    columns = f"{'error (m)  err/tol  CPU ms  steps':>34}"
    out(f"{'':<13} {'':>6} " + " ".join(columns for _ in methods))
    rows: dict[tuple[str, float], dict[str, Point]] = {}
    for p in points:
        rows.setdefault((p.problem, p.tol), {})[p.method] = p
    for (key, tol), by_method in rows.items():
        cells = []
        for m in methods:
            p = by_method.get(m)
            if p is None or np.isnan(p.error):
                cells.append(f"{'failed':>34}")
            else:
                cells.append(
                    f"{p.error:>9.1e} {p.error / tol:>7.1f} {1e3 * p.cpu:>8.1f} {p.steps:>7d}"
                    .rjust(34)
                )
        out(f"{key:<13} {tol:>6.0e} " + " ".join(cells))


def plot(points: list[Point], path: str) -> None:
    """Writes the work-precision diagram (error against CPU time, log-log, one panel per
    problem) to ``path``."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    problems = list(dict.fromkeys(p.problem for p in points))
    methods = list(dict.fromkeys(p.method for p in points))
    fig, axes = plt.subplots(1, len(problems), figsize=(4.5 * len(problems), 4), squeeze=False)
    for ax, key in zip(axes[0], problems, strict=True):
        for m in methods:
            mine = [p for p in points if p.problem == key and p.method == m and p.error > 0]
            ax.loglog([p.cpu for p in mine], [p.error for p in mine], "o-", label=m)
        ax.set_title(PROBLEMS[key].name)
        ax.set_xlabel("CPU time (s)")
        ax.set_ylabel("max position error (m)")
        ax.grid(True, which="both", alpha=0.3)
    axes[0][0].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main(argv: list[str] | None = None) -> int:
    """Command line entry point."""
    parser = argparse.ArgumentParser(
        prog="python -m vinculo.bench work-precision", description=__doc__
    )
    parser.add_argument("--plot", default="work-precision.png", help="where to write the plot")
    parser.add_argument("--repeat", type=int, default=3, help="runs per point (best CPU time)")
    parser.add_argument("--quick", action="store_true", help="tolerances 1e-3, 1e-6 only")
    args = parser.parse_args(argv)
    tolerances = (1e-3, 1e-6) if args.quick else TOLERANCES
    points = measure(tolerances=tolerances, repeat=args.repeat)
    table(points)
    plot(points, args.plot)
    print(f"plot written to {args.plot}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
