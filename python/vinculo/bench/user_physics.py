"""``python -m vinculo.bench.user_physics``: the cost of forces written in Python.

A chain of N particles (1 m long, 1 kg in all) released horizontally from a fixed anchor, with
quadratic drag f = -c |v| v on every particle, is run three ways at the same step and scheme
(trapezoidal rule, full Newton):

- built-in: the core's QuadraticDrag elements;
- Python, user Jacobian: one ``System.add_force_group`` over all N particles with
  ``force(t, q, v)`` and ``jacobian(t, q, v)`` in numpy;
- Python, finite differences: the same group without ``jacobian`` (6 extra force calls per
  Jacobian).

For each it reports steps per second (wall time of ``simulate``, model building excluded), and
for the Python groups the calls made, the time per call as measured by the core (taking the
GIL, copying the arrays in and out, checking the shape, and the function itself), the function's
own time per call (timed here on arrays of the same size) and the difference, the crossing
overhead. Each row also checks that the run ends where the built-in one does.
"""

from __future__ import annotations

import argparse
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

import vinculo

# Drag coefficient per particle (N s^2/m^2) and the step.
DRAG = 0.02
DT = 1e-3


def drag_functions(c: float) -> tuple[Callable, Callable]:
    """f = -c |v| v on (k, 3) velocities, and its Jacobian (0, -c (|v| I + v v^T / |v|))."""

    def force(t, q, v):
        return -c * np.sqrt(np.einsum("ij,ij->i", v, v))[:, None] * v

    def jacobian(t, q, v):
        speed = np.sqrt(np.einsum("ij,ij->i", v, v))
        safe = np.where(speed > 0.0, speed, 1.0)
        dv = -c * (
            speed[:, None, None] * np.eye(3) + v[:, :, None] * v[:, None, :] / safe[:, None, None]
        )
        return np.zeros_like(dv), dv

    return force, jacobian


def build(n: int, variant: str) -> tuple[vinculo.System, vinculo.UserGroup | None]:
    """The chain with the drag of ``variant`` ('built-in', 'jacobian' or 'fd')."""
    system = vinculo.System(gravity=(0.0, 0.0, -9.81))
    link, mass = 1.0 / n, 1.0 / n
    previous = system.add_particle(1.0, (0.0, 0.0, 0.0), fixed=True)
    ids = []
    for i in range(1, n + 1):
        p = system.add_particle(mass, (link * i, 0.0, 0.0))
        system.add_distance(previous, p, link)
        ids.append(p)
        previous = p
    if variant == "built-in":
        for p in ids:
            system.add_quadratic_drag(p, DRAG)
        return system, None
    force, jacobian = drag_functions(DRAG)
    group = system.add_force_group(
        [p.index for p in ids],
        force,
        jacobian=jacobian if variant == "jacobian" else None,
        name="drag",
    )
    return system, group


@dataclass
class Row:
    """Figures of one run."""

    n: int
    variant: str
    steps_per_second: float
    tip: np.ndarray
    force_calls: int = 0
    jacobian_calls: int = 0
    # Per call as measured by the core, and the function alone (force, jacobian).
    force_per_call: float = float("nan")
    jacobian_per_call: float = float("nan")
    force_alone: float = float("nan")
    jacobian_alone: float = float("nan")


def bare_call_times(n: int, repeat: int = 200) -> tuple[float, float]:
    """The force and Jacobian functions' own times per call on (n, 3) arrays, called from
    Python (best of three)."""
    functions = drag_functions(DRAG)
    rng = np.random.default_rng(0)
    q, v = rng.normal(size=(n, 3)), rng.normal(size=(n, 3))
    times = []
    for function in functions:
        best = float("inf")
        for _ in range(3):
            start = time.perf_counter()
            for _ in range(repeat):
                function(0.1, q, v)
            best = min(best, (time.perf_counter() - start) / repeat)
        times.append(best)
    return times[0], times[1]


def run(n: int, variant: str, steps: int) -> Row:
    """Runs ``steps`` steps of one variant."""
    system, group = build(n, variant)
    start = time.perf_counter()
    solution = vinculo.simulate(system, steps * DT, DT, save_every=steps)
    seconds = time.perf_counter() - start
    row = Row(n, variant, steps / seconds, solution.positions[-1, -1])
    if group is not None:
        row.force_calls = group.calls["force"]
        row.jacobian_calls = group.calls["jacobian"]
        row.force_per_call = group.seconds["force"] / max(row.force_calls, 1)
        if row.jacobian_calls:
            row.jacobian_per_call = group.seconds["jacobian"] / row.jacobian_calls
        row.force_alone, row.jacobian_alone = bare_call_times(n)
    return row


def table(sizes: tuple[int, ...], steps: int, out: Callable[[str], None] = print) -> list[Row]:
    """Runs every size and variant; prints the table; returns the rows."""
    out(
        f"Chain released horizontally, quadratic drag on every particle, dt = {DT} s, {steps} steps"
    )
    out(
        f"{'N':>6} {'drag':<24} {'steps/s':>8} {'force':>6} {'jac':>5} "
        f"{'force us':>9} {'alone':>7} {'jac us':>8} {'alone':>7} {'tip gap (m)':>12}"
    )
    rows = []
    labels = {
        "built-in": "built-in",
        "jacobian": "Python, user Jacobian",
        "fd": "Python, finite diff.",
    }
    for n in sizes:
        reference = None
        for variant in ("built-in", "jacobian", "fd"):
            row = run(n, variant, steps)
            rows.append(row)
            if reference is None:
                reference = row.tip
            gap = float(np.max(np.abs(row.tip - reference)))
            if variant == "built-in":
                extra = " " * 48
            else:
                jac = f"{1e6 * row.jacobian_per_call:>8.1f} {1e6 * row.jacobian_alone:>7.1f}"
                if not row.jacobian_calls:
                    jac = f"{'-':>8} {'-':>7}"
                extra = (
                    f"{row.force_calls:>6} {row.jacobian_calls:>5} "
                    f"{1e6 * row.force_per_call:>9.1f} {1e6 * row.force_alone:>7.1f} {jac}"
                )
            out(f"{n:>6} {labels[variant]:<24} {row.steps_per_second:>8.1f} {extra} {gap:>12.2e}")
    out(
        "force / jac: calls in the run; force us, jac us: time per call measured by the core "
        "(taking the GIL, copying the arrays in and out, the shape check and the function); "
        "alone: the function by itself called from Python; their difference is the crossing."
    )
    return rows


def main(argv: list[str] | None = None) -> int:
    """Print the table of the Python-force benchmark.

    Arguments:
        argv: the command-line arguments (default: ``sys.argv[1:]``); ``--sizes N ...`` and
            ``--steps K``.

    Returns:
        The exit code, 0.

    Raises:
        SystemExit: on bad arguments (from argparse).
    """
    parser = argparse.ArgumentParser(
        prog="python -m vinculo.bench.user_physics", description=__doc__
    )
    parser.add_argument("--sizes", type=int, nargs="+", default=[100, 1000], help="chain sizes N")
    parser.add_argument("--steps", type=int, default=200, help="steps per run")
    args = parser.parse_args(argv)
    table(tuple(args.sizes), args.steps)
    return 0


if __name__ == "__main__":
    sys.exit(main())
