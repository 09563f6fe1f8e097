"""``python -m vinculo.bench.sweep``: a 200-run parameter study on one process and on all CPUs.

The study is the particle model of the buoy over 10 drag coefficients (0.1 to 0.4) and 20
frequencies (0.5 to 1.5 Hz) with the default run settings (30 settling and 10 fitted periods,
dt = 2e-3), run twice through :func:`vinculo.buoy.parameter_study.run_parameter_study`: in this
process, then on local worker processes (one per CPU). It prints both wall times, the speed-up,
and checks that both give the same amplitudes (the runs are deterministic).
"""

from __future__ import annotations

import argparse
import os
import sys

import numpy as np

from vinculo.buoy.parameter_study import grid, run_parameter_study


def points(cd_count: int = 10, frequency_count: int = 20) -> list[dict[str, float]]:
    """The study's grid: ``cd_count`` drag coefficients times ``frequency_count`` frequencies."""
    return grid({
        "drag_coefficient": np.linspace(0.1, 0.4, cd_count).tolist(),
        "frequency": np.linspace(0.5, 1.5, frequency_count).tolist(),
    })


def main(argv: list[str] | None = None) -> int:
    """Run the study on one process and on every CPU; print the times and the speed-up."""
    parser = argparse.ArgumentParser(prog="python -m vinculo.bench.sweep", description=__doc__)
    parser.add_argument("--cd-count", type=int, default=10, help="drag coefficients (10)")
    parser.add_argument("--frequency-count", type=int, default=20, help="frequencies (20)")
    parser.add_argument("--workers", type=int, default=os.cpu_count() or 1,
                        help="worker processes of the parallel run (default: one per CPU)")
    args = parser.parse_args(argv)
    grid_points = points(args.cd_count, args.frequency_count)
    print(f"parameter study: {len(grid_points)} runs of the particle model (default settings)")
    serial = run_parameter_study(grid_points, workers=1, progress=False)
    print(f"  1 process:    {serial.elapsed:7.1f} s  ({serial.elapsed / len(grid_points):.3f} "
          f"s per run)")
    parallel = run_parameter_study(grid_points, workers=args.workers, progress=False)
    print(f"  {args.workers} processes: {parallel.elapsed:7.1f} s  "
          f"speed-up {serial.elapsed / parallel.elapsed:.2f}x on {os.cpu_count()} CPUs")

    def amplitudes(study):
        return {tuple(r.parameters.values()): r.results["relative_amplitude"] for r in study.rows}

    same = amplitudes(serial) == amplitudes(parallel)
    failed = len(serial.failures()) + len(parallel.failures())
    print(f"  same amplitudes in both: {'yes' if same else 'NO'}; failed runs: {failed}")
    return 0 if same and not failed else 1


if __name__ == "__main__":
    sys.exit(main())
