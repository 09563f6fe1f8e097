"""vinculo alone: seconds per step and peak memory of hanging chains of 10^3 to 10^6 particles.

Each size runs in its own process (``python -m vinculo.bench.scaling N``) so that the peak
resident memory (``ru_maxrss``) is that of one model: building it, the run (only the first and
last states stored) and the returned Solution. The cost of a step is measured apart from the
one-time set-up of a run (checks, consistent initial accelerations, the solver's analysis): a run
of one step and a run of ``1 + k`` steps are timed (each in its own process), and a step costs
``(T(1 + k) - T(1)) / k``; the set-up is ``T(1)`` less one step. Peak memory is that of the
longer run.
"""

from __future__ import annotations

import json
import math
import resource
import subprocess
import sys
import time

import numpy as np

import vinculo
from vinculo.bench.models import Chain, build_vinculo

SIZES = (1_000, 10_000, 100_000, 1_000_000)


def steps_for(n: int) -> int:
    """Timed steps at size n (beyond the first): about two million particle-steps, 12 to 200."""
    return min(200, max(12, 2_000_000 // n))


def one(n: int, hanging: bool = True, count: int = 1) -> dict[str, float | str]:
    """Runs ``count`` steps of one size in this process; returns its figures."""
    model = Chain(f"chain {n}", n, hanging=hanging, t_end=count * 1e-3)
    system, _ = build_vinculo(model)
    start = time.perf_counter()
    solution = vinculo.simulate(system, t_end=model.t_end, dt=model.dt, save_every=count)
    seconds = time.perf_counter() - start
    peak_mb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    return {
        "n": n,
        "seconds": seconds,
        # A run total (only the first and last states are stored).
        "residuals": solution.residual_evaluations / count,
        "peak_mb": peak_mb,
        "solver": solution.linear_solver,
    }


def _measure(n: int, shape: str) -> dict[str, float | str]:
    """One size in two subprocesses (1 and 1 + k steps): per-step cost, set-up, peak memory."""
    results = []
    steps = steps_for(n)
    for count in (1, 1 + steps):
        args = [sys.executable, "-m", "vinculo.bench.scaling", str(n), shape, str(count)]
        done = subprocess.run(args, capture_output=True, text=True, check=False)
        if done.returncode != 0:
            raise RuntimeError(" ".join(done.stderr.strip().splitlines()[-1:]))
        results.append(json.loads(done.stdout.strip().splitlines()[-1]))
    short, long = results
    per_step = (long["seconds"] - short["seconds"]) / steps
    return {**long, "steps": steps, "seconds_per_step": per_step,
            "setup": short["seconds"] - per_step}


def run(sizes: tuple[int, ...] = SIZES, hanging: bool = True, out=print) -> float:
    """Runs every size in a subprocess, prints a table and returns the fitted exponent p of
    seconds per step ~ N^p."""
    shape = "hanging" if hanging else "swinging"
    out(
        f"vinculo scaling: {shape} chains, 0.1 m links, 0.1 kg, dt = 1e-3 "
        "(trapezoidal rule, the default Newton; set-up of a run apart)"
    )
    out(
        f"{'N':>9} {'steps':>6} {'s/step':>11} {'us/particle':>12} {'set-up s':>9} "
        f"{'res./step':>11} {'peak MB':>9}  solver"
    )
    points = []
    for n in sizes:
        try:
            r = _measure(n, shape)
        except RuntimeError as error:
            out(f"{n:>9} failed: {error}")
            continue
        out(
            f"{n:>9} {r['steps']:>6} {r['seconds_per_step']:>11.4e} "
            f"{1e6 * r['seconds_per_step'] / n:>12.3f} {r['setup']:>9.3f} {r['residuals']:>11.2f} "
            f"{r['peak_mb']:>9.0f}  {r['solver']}"
        )
        points.append((math.log(n), math.log(r["seconds_per_step"])))
    if len(points) < 2:
        return float("nan")
    x, y = np.array(points).T
    p = float(np.polyfit(x, y, 1)[0])
    out(f"fitted exponent: seconds per step ~ N^{p:.3f} (N = {sizes[0]:,} .. {sizes[-1]:,})")
    return p


if __name__ == "__main__":
    # No argument: the table of hanging chains; "swinging": of swinging ones; N [swinging
    # [steps]]: one size, in this process (the table's subprocesses).
    if len(sys.argv) > 1 and sys.argv[1] != "swinging":
        count = int(sys.argv[3]) if len(sys.argv) > 3 else 1 + steps_for(int(sys.argv[1]))
        print(json.dumps(one(int(sys.argv[1]), sys.argv[2:3] != ["swinging"], count)))
    else:
        run(hanging=sys.argv[1:2] != ["swinging"])
