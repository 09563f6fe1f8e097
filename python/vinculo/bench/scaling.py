"""vinculo alone: seconds per step and peak memory of hanging chains of 10^3 to 10^6 particles.

``python -m vinculo.bench.scaling [hanging|swinging] [--sizes 1000,10000] [--repeat 3]`` prints
the table. Each size runs in its own process (the same command with ``--one N``) so that the
peak resident memory (``ru_maxrss``) is that of one model: building it, the run (only the first
and last states stored) and the returned Solution. The cost of a step is measured apart from the
one-time set-up of a run (checks, consistent initial accelerations, the solver's analysis): a run
of one step and a run of ``1 + k`` steps are timed (each in its own process, the least time of
``--repeat`` such processes: one run's time varies by about 10 % here), and a step costs
``(T(1 + k) - T(1)) / k``; the set-up is ``T(1)`` less one step. Peak memory is that of the
longer run.

The last column puts each step against the machine's memory floor: the time of one read of the
iteration matrix's storage, ``MATRIX_BYTES_PER_PARTICLE`` bytes a particle of a chain (the tree
elimination's blocks: a particle and its link, 4 x 4 diagonal entries and two 3 x 4 couplings),
by numpy on as many threads as the process may use from 64 MB on (the step's own: its
assembly and, on long chains, its elimination run on every core), the least of five reads, in
the same process after the run. A factorisation and a solve each read that storage at least
once; below about 10^5 particles it fits in the caches and the "floor" is theirs.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import resource
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor

import numpy as np

import vinculo
from vinculo.bench.models import Chain, build_vinculo

SIZES = (1_000, 10_000, 100_000, 1_000_000)

#: Bytes of iteration-matrix storage a particle of a chain: a block of 4 unknowns (its three
#: coordinates and the link to its parent) keeps 16 diagonal entries and two 3 x 4 couplings.
MATRIX_BYTES_PER_PARTICLE = 8 * (16 + 12 + 12)


def memory_floor(n_bytes: int, threads: int | None = None, reads: int = 5) -> float:
    """The least time of ``reads`` reads of ``n_bytes`` of memory (a sum of float64 over it),
    split over ``threads`` threads (default: the CPUs this process may use, one below 64 MB),
    in seconds."""
    if threads is None:
        # One thread below 64 MB, where starting the others costs more than the read.
        cpus = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else 1
        threads = cpus if n_bytes >= 1 << 26 else 1
    data = np.ones(max(1, n_bytes // 8))
    parts = np.array_split(data, threads)
    best = math.inf
    with ThreadPoolExecutor(max_workers=threads) as pool:
        for _ in range(reads):
            start = time.perf_counter()
            total = sum(pool.map(np.sum, parts))
            best = min(best, time.perf_counter() - start)
    if total != data.size:  # every entry was read
        raise RuntimeError(f"memory floor: read {total} of {data.size} entries")
    return best


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
    residuals, solver = solution.residual_evaluations / count, solution.linear_solver
    del solution, system
    return {
        "floor": memory_floor(n * MATRIX_BYTES_PER_PARTICLE),
        "n": n,
        "seconds": seconds,
        # A run total (only the first and last states are stored).
        "residuals": residuals,
        "peak_mb": peak_mb,
        "solver": solver,
    }


def _measure(n: int, shape: str, repeat: int = 1) -> dict[str, float | str]:
    """One size in subprocesses of 1 and 1 + k steps, the quickest of ``repeat`` of each:
    per-step cost, set-up, peak memory."""
    results = []
    steps = steps_for(n)
    for count in (1, 1 + steps):
        args = [sys.executable, "-m", "vinculo.bench.scaling", shape, "--one", str(n),
                "--steps", str(count)]
        runs = []
        for _ in range(repeat):
            done = subprocess.run(args, capture_output=True, text=True, check=False)
            if done.returncode != 0:
                raise RuntimeError(" ".join(done.stderr.strip().splitlines()[-1:]))
            runs.append(json.loads(done.stdout.strip().splitlines()[-1]))
        results.append(min(runs, key=lambda r: r["seconds"]))
    short, long = results
    per_step = (long["seconds"] - short["seconds"]) / steps
    return {**long, "steps": steps, "seconds_per_step": per_step,
            "setup": short["seconds"] - per_step}


def run(sizes: tuple[int, ...] = SIZES, hanging: bool = True, out=print,
        repeat: int = 1) -> float:
    """Runs every size in subprocesses (the quickest of ``repeat`` of each), prints a table and
    returns the fitted exponent p of seconds per step ~ N^p."""
    shape = "hanging" if hanging else "swinging"
    out(
        f"vinculo scaling: {shape} chains, 0.1 m links, 0.1 kg, dt = 1e-3 "
        "(trapezoidal rule, the default Newton; set-up of a run apart)"
    )
    out(
        f"{'N':>9} {'steps':>6} {'s/step':>11} {'us/particle':>12} {'set-up s':>9} "
        f"{'res./step':>11} {'peak MB':>9} {'floor s':>10} {'floors':>7}  solver"
    )
    points = []
    for n in sizes:
        try:
            r = _measure(n, shape, repeat)
        except RuntimeError as error:
            out(f"{n:>9} failed: {error}")
            continue
        out(
            f"{n:>9} {r['steps']:>6} {r['seconds_per_step']:>11.4e} "
            f"{1e6 * r['seconds_per_step'] / n:>12.3f} {r['setup']:>9.3f} {r['residuals']:>11.2f} "
            f"{r['peak_mb']:>9.0f} {r['floor']:>10.2e} {r['seconds_per_step'] / r['floor']:>7.1f}"
            f"  {r['solver']}"
        )
        points.append((math.log(n), math.log(r["seconds_per_step"])))
    if len(points) < 2:
        return float("nan")
    x, y = np.array(points).T
    p = float(np.polyfit(x, y, 1)[0])
    out(f"fitted exponent: seconds per step ~ N^{p:.3f} (N = {sizes[0]:,} .. {sizes[-1]:,})")
    return p


def main(argv: list[str] | None = None) -> int:
    """The command line (``python -m vinculo.bench.scaling``).

    Arguments:
        argv: the arguments (default: ``sys.argv[1:]``).

    Returns:
        The exit code (0).
    """
    parser = argparse.ArgumentParser(prog="python -m vinculo.bench.scaling",
                                     description=__doc__.split("\n\n")[0])
    parser.add_argument("shape", nargs="?", default="hanging", choices=("hanging", "swinging"),
                        help="chains hanging at rest (default) or released swinging")
    parser.add_argument("--sizes", default=",".join(str(n) for n in SIZES),
                        help="comma-separated numbers of particles (default %(default)s)")
    parser.add_argument("--repeat", type=int, default=1, metavar="R",
                        help="time each size's runs R times and keep the quickest "
                             "(default %(default)s)")
    # One size in this process, the table's subprocesses: its figures as JSON.
    parser.add_argument("--one", type=int, metavar="N", help=argparse.SUPPRESS)
    parser.add_argument("--steps", type=int, metavar="K", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    try:
        sizes = tuple(int(x) for x in args.sizes.split(",") if x.strip())
    except ValueError:
        parser.error(f"--sizes {args.sizes!r}: give comma-separated whole numbers")
    if not sizes or min(sizes) < 1:
        parser.error(f"--sizes {args.sizes!r}: give numbers of particles >= 1")
    if args.repeat < 1:
        parser.error(f"--repeat {args.repeat}: give a number of runs >= 1")
    hanging = args.shape == "hanging"
    if args.one is not None:
        count = args.steps if args.steps is not None else 1 + steps_for(args.one)
        print(json.dumps(one(args.one, hanging, count)))
    else:
        run(sizes, hanging=hanging, repeat=args.repeat)
    return 0


if __name__ == "__main__":
    sys.exit(main())
