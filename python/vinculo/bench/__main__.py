"""``python -m vinculo.bench``: vinculo side by side with Exudyn, then vinculo's scaling run.

The same models (see ``vinculo.bench.models``) at the same fixed step dt = 1e-3 with the same
scheme in both codes: generalised-alpha, index 3, spectral radius 0.9 (Exudyn's default) and
modified Newton (Exudyn's default; ``--full-newton`` for vinculo's full Newton), and spectral
radius 0 on the 1 m chains released horizontally (the robustness rows); each row checks that
both put the chain's tip (the buoy's centre) at the same place at t_end and gives steps per
second (best of a few runs, wall time of the integration, model building excluded). The last
row is the buoy of the case study (``vinculo.bench.buoy``).
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
import time

import numpy as np

from vinculo.bench import scaling
from vinculo.bench.buoy import CENTRE_TOLERANCE, BuoyBench, run_exudyn_buoy, run_vinculo_buoy
from vinculo.bench.models import COMPARISON, ROBUSTNESS, Chain
from vinculo.bench.runner import Run, run_exudyn, run_vinculo

# Largest distance between the two codes' tip positions at t_end accepted as "same answer", in m.
# Same scheme, different Newton stopping rules (vinculo: 1e-10 of the length scale; Exudyn:
# relative 1e-8) and modified-Newton refresh policies; the scheme's own error at dt = 1e-3 is
# about 1e-5 m on these models (the pendulum after 10 s: 7e-5 m, phase error O(dt^2)).
TIP_TOLERANCE = 1e-3


def comparison_models(quick: bool = False) -> list[Chain]:
    """The side-by-side models (``quick``: small ones only, for a smoke run)."""
    sizes = (10, 100) if quick else (10, 100, 1_000, 10_000)
    models = [Chain("pendulum, 1 m, 10 s", 1, link=1.0, mass=1.0, hanging=False, t_end=10.0)]
    models += [Chain(f"hanging chain N = {n:,}", n) for n in sizes]
    models += [Chain(f"swinging chain N = {n:,}", n, hanging=False) for n in sizes]
    return models


def robustness_models(quick: bool = False) -> list[Chain]:
    """1 m chains released horizontally: the case where a peer's Newton diverges."""
    sizes = (300,) if quick else (300, 1_000, 10_000)
    return [
        Chain(f"1 m chain N = {n:,}, 1 s", n, link=1.0 / n, mass=1.0 / n, hanging=False)
        for n in sizes
    ]


def buoy_bench(quick: bool = False) -> BuoyBench:
    """The buoy row: the default case at 0.9 Hz, 20 s (``quick``: its first 5 s)."""
    if quick:
        return BuoyBench(name="buoy, 7 particles, 0.9 Hz, 5 s", t_end=5.0)
    return BuoyBench()


def _import_exudyn():
    try:
        import exudyn
    except ImportError:
        return None
    return exudyn


def _row(
    model: Chain | BuoyBench,
    v: Run,
    e: Run | None,
    out,
    tolerance: float = TIP_TOLERANCE,
    component: int | None = None,
) -> bool:
    """Prints one table row; returns False if both ran and disagree by more than ``tolerance``
    (the distance between the tips, or the gap in one ``component`` of their positions)."""
    agree = True
    if e is None:
        peer, ratio, check = "(no Exudyn)", "", ""
    elif e.tip is None:
        peer, ratio, check = "diverged", "", ""
    else:
        peer = f"{e.steps_per_second:>12,.0f}"
        ratio = f"{v.steps_per_second / e.steps_per_second:>7.1f}x"
        if v.tip is None:
            gap = float("nan")
        elif component is None:
            gap = float(np.linalg.norm(v.tip - e.tip))
        else:
            gap = abs(float(v.tip[component] - e.tip[component]))
        agree = gap <= tolerance
        check = f"{gap:.1e} {'ok' if agree else 'DIFFER'}"
    mine = f"{v.steps_per_second:>12,.0f}" if v.tip is not None else "failed"
    out(f"{model.name:<30} {mine:>12} {peer:>12} {ratio:>8}  {check:<14} {v.detail}")
    return agree


def compare(quick: bool = False, repeat: int = 3, out=print, full_newton: bool = False) -> bool:
    """The side-by-side table; returns True if every pair that ran agrees."""
    exu = _import_exudyn()
    comparison = dataclasses.replace(COMPARISON, jacobian_reuse=not full_newton)
    robustness = dataclasses.replace(ROBUSTNESS, jacobian_reuse=not full_newton)
    if exu is None:
        out("Exudyn is not installed (pip install exudyn): its columns are skipped.")
    else:
        out(
            f"Exudyn {exu.__version__}: index 3, its modified Newton and tolerances, sparse LU "
            "(dense if faster for <= 100 unknowns)"
        )
    out(
        f"both codes: {comparison.describe()} (1 m chains: {robustness.describe()}); vinculo's "
        f"Newton tolerance 1e-10 of the length scale; dt = 1e-3; tip check: |tip_vinculo - "
        f"tip_exudyn| <= {TIP_TOLERANCE:g} m"
    )
    out(
        f"{'model':<30} {'vinculo st/s':>12} {'Exudyn st/s':>12} {'ratio':>8}  "
        f"{'tip gap (m)':<14} vinculo solver"
    )
    agree = True
    rows = [(m, comparison) for m in comparison_models(quick)]
    rows += [(m, robustness) for m in robustness_models(quick)]
    for model, integration in rows:
        times = 1 if model.n >= 1_000 else repeat
        v = run_vinculo(model, integration, repeat=times)
        e = None if exu is None else run_exudyn(model, exu, integration, repeat=times)
        agree &= _row(model, v, e, out)
    buoy = buoy_bench(quick)
    v = run_vinculo_buoy(buoy, comparison, repeat=1 if quick else repeat)
    e = None if exu is None else run_exudyn_buoy(buoy, exu, comparison, repeat=1)
    agree &= _row(buoy, v, e, out, tolerance=CENTRE_TOLERANCE, component=0)
    out(
        "buoy: the default case (X0 = 5 mm, 10-period ramp) at dt = 1e-3; gap: |x_vinculo - "
        f"x_exudyn| of the sphere's centre at t_end <= {CENTRE_TOLERANCE:g} m; Exudyn evaluates "
        "the fluid force (drag, buoyancy, tank acceleration) in a Python load user function, "
        "which slows it down; vinculo's Morison force is built in"
    )
    return agree


def main(argv: list[str] | None = None) -> int:
    """Command line entry point (``work-precision`` as the first argument: the work-precision
    table of :mod:`vinculo.bench.work_precision`)."""
    argv = sys.argv[1:] if argv is None else argv
    if argv[:1] == ["work-precision"]:
        from vinculo.bench import work_precision

        return work_precision.main(argv[1:])
    parser = argparse.ArgumentParser(prog="python -m vinculo.bench", description=__doc__)
    parser.add_argument("--quick", action="store_true", help="small models only (smoke run)")
    parser.add_argument("--no-scaling", action="store_true", help="skip the scaling run")
    parser.add_argument("--scaling-only", action="store_true", help="only the scaling run")
    parser.add_argument(
        "--full-newton", action="store_true",
        help="vinculo with full Newton (default: modified Newton, as Exudyn)",
    )
    args = parser.parse_args(argv)
    start = time.perf_counter()
    ok = True
    if not args.scaling_only:
        ok = compare(quick=args.quick, full_newton=args.full_newton)
        print()
    if not args.no_scaling:
        sizes = (1_000, 10_000) if args.quick else scaling.SIZES
        scaling.run(sizes)
        print()
        scaling.run(sizes, hanging=False)
    print(f"\ntotal {time.perf_counter() - start:.0f} s")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
