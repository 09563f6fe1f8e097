"""``python -m vinculo.bench``: vinculo side by side with Exudyn, then vinculo's scaling run.

The same models (see ``vinculo.bench.models``) at the same fixed step dt = 1e-3 with the same
scheme in both codes: generalised-alpha, index 3, spectral radius 0.9 (Exudyn's default), and
spectral radius 0 on the 1 m chains released horizontally (the robustness rows). vinculo runs
three times: with its default Newton (the headline: the iteration matrix kept while it contracts
fast, docs/theory/newton.md), with full Newton and with modified Newton (Exudyn's default mode).
Each row checks that the codes put the chain's tip (the buoy's centre) at the same place
at t_end, within a tolerance derived from the scheme's own error on that model
(:func:`agreement_tolerance`), and gives steps per second (best of a few runs, wall time of the
integration, model building excluded). The last row is the buoy of the case study
(``vinculo.bench.buoy``). ``python -m vinculo.bench work-precision`` prints the work-precision
table of error-controlled runs instead (:mod:`vinculo.bench.work_precision`), and
``python -m vinculo.bench python-overhead`` the cost of the Python layer
(:mod:`vinculo.bench.python_overhead`), and ``python -m vinculo.bench rigid-chain`` a chain of
rigid bodies and revolute joints against Exudyn (:mod:`vinculo.bench.rigid_chain`).
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

#: The two codes' answers may differ by this share of the scheme's own error at the step used.
#: Two codes that run the same scheme at the same step compute the same discrete solution up to
#: their Newton tolerances, far inside the scheme's error; a gap of the order of that error means
#: another discrete solution (as modified Newton's stopping rule gives: before, on the pendulum
#: after 10 s it stopped 1e-4 m from Exudyn where full Newton agrees to 4e-8 m, and the fixed
#: tolerance of 1e-3 m then used could not see it).
AGREEMENT_SHARE = 0.01
#: The smallest tolerance, relative to the model's length: what the Newton tolerances allow
#: (vinculo 1e-10 of the length scale, Exudyn relative 1e-8), for models at rest, whose scheme
#: error is nil.
AGREEMENT_FLOOR = 1e-7

#: vinculo's Newton in the table's three columns: its default, full and modified Newton.
NEWTON_MODES = ("auto", False, True)


def agreement_tolerance(scheme_error: float, length: float) -> float:
    """The largest gap between the two codes' answers accepted as "same answer".

    Arguments:
        scheme_error: the scheme's own error at the step used, measured as the distance
            between vinculo's answers at dt and dt/2 (full Newton): for a second-order scheme 3/4
            of the error at dt.
        length: the model's length, m.

    Returns:
        ``max(AGREEMENT_SHARE * scheme_error, AGREEMENT_FLOOR * length)``, m.
    """
    return max(AGREEMENT_SHARE * scheme_error, AGREEMENT_FLOOR * length)


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


def _gap(mine: Run, theirs: Run | None, component: int | None) -> float:
    """Distance between two answers (or the gap in one ``component``); nan when one is missing."""
    if theirs is None or theirs.tip is None or mine.tip is None:
        return float("nan")
    if component is None:
        return float(np.linalg.norm(mine.tip - theirs.tip))
    return abs(float(mine.tip[component] - theirs.tip[component]))


def _row(
    name: str,
    runs: tuple[Run, Run, Run],
    peer: Run | None,
    tolerance: float,
    out,
    component: int | None = None,
) -> bool:
    """Prints one table row of vinculo's default, full and modified Newton ``runs``; returns
    False if the peer ran and the default or full Newton disagrees with it by more than
    ``tolerance`` (modified Newton's gap is reported, not judged)."""

    def rate(run: Run | None) -> str:
        if run is None:
            return "(no Exudyn)"
        return f"{run.steps_per_second:,.0f}" if run.tip is not None else "failed"

    default, full, modified = runs
    agree = True
    if peer is None or peer.tip is None:
        ratio, gaps = "", "diverged" if peer is not None else ""
    else:
        ratio = f"{default.steps_per_second / peer.steps_per_second:.1f}x"
        found = [_gap(run, peer, component) for run in runs]
        agree = found[0] <= tolerance and found[1] <= tolerance
        gaps = " ".join(f"{g:.1e} {'ok' if g <= tolerance else 'DIFFER':<6}" for g in found)
    out(
        f"{name:<30} {rate(default):>12} {rate(full):>12} {rate(modified):>12} {rate(peer):>12} "
        f"{ratio:>7}  {tolerance:>8.1e}  {gaps:<48} {default.detail}"
    )
    return agree


def compare(quick: bool = False, repeat: int = 3, out=print) -> bool:
    """The side-by-side table; returns True if vinculo with its default and with full Newton
    agrees with every peer run that finished."""
    exu = _import_exudyn()
    if exu is None:
        out("Exudyn is not installed (pip install exudyn): its columns are skipped.")
    else:
        out(
            f"Exudyn {exu.__version__}: index 3, its modified Newton and tolerances, sparse LU "
            "(dense if faster for <= 100 unknowns)"
        )
    out(
        f"both codes: generalised-alpha, rho_inf = {COMPARISON.rho_inf:g} (1 m chains: "
        f"{ROBUSTNESS.rho_inf:g}), dt = 1e-3; vinculo's Newton tolerance 1e-10 of the length "
        f"scale; tolerance: max({AGREEMENT_SHARE:g} |tip(dt) - tip(dt/2)|, "
        f"{AGREEMENT_FLOOR:g} x length), vinculo full Newton at dt and dt/2; gaps |tip_vinculo - "
        "tip_exudyn| at t_end, vinculo's default, full and modified Newton; ratio: default / "
        "Exudyn"
    )
    out(
        f"{'model':<30} {'default st/s':>12} {'full st/s':>12} {'modif. st/s':>12} "
        f"{'Exudyn st/s':>12} {'ratio':>7}  {'tol (m)':>8}  {'gap default (m)':<16}"
        f"{'gap full (m)':<16}{'gap modified (m)':<16} vinculo solver"
    )
    agree = True
    rows = [(m, COMPARISON) for m in comparison_models(quick)]
    rows += [(m, ROBUSTNESS) for m in robustness_models(quick)]
    for model, integration in rows:
        times = 1 if model.n >= 10_000 else repeat
        runs = tuple(
            run_vinculo(model, dataclasses.replace(integration, jacobian_reuse=mode), times)
            for mode in NEWTON_MODES
        )
        half = run_vinculo(
            dataclasses.replace(model, dt=model.dt / 2),
            dataclasses.replace(integration, jacobian_reuse=False),
        )
        error = _gap(runs[1], half, None)
        tolerance = agreement_tolerance(error, model.n * model.link)
        peer = None if exu is None else run_exudyn(model, exu, integration, repeat=times)
        agree &= _row(model.name, runs, peer, tolerance, out)
    buoy = buoy_bench(quick)
    times = 1 if quick else repeat
    runs = tuple(
        run_vinculo_buoy(buoy, dataclasses.replace(COMPARISON, jacobian_reuse=mode), times)
        for mode in NEWTON_MODES
    )
    half = run_vinculo_buoy(
        dataclasses.replace(buoy, dt=buoy.dt / 2),
        dataclasses.replace(COMPARISON, jacobian_reuse=False),
    )
    tolerance = max(agreement_tolerance(_gap(runs[1], half, 0), 1.0), CENTRE_TOLERANCE)
    peer = None if exu is None else run_exudyn_buoy(buoy, exu, COMPARISON, repeat=1)
    agree &= _row(buoy.name, runs, peer, tolerance, out, component=0)
    out(
        "buoy: the default case (X0 = 5 mm, 10-period ramp) at dt = 1e-3; gap: |x_vinculo - "
        f"x_exudyn| of the sphere's centre at t_end, tolerance at least {CENTRE_TOLERANCE:g} m; "
        "Exudyn evaluates the fluid force (drag, buoyancy, tank acceleration) in a Python load "
        "user function, which slows it down and is evaluated at its own point of the step; "
        "vinculo's Morison force is built in"
    )
    return agree


def main(argv: list[str] | None = None) -> int:
    """Command line entry point (``work-precision`` as the first argument: the work-precision
    table of :mod:`vinculo.bench.work_precision`; ``python-overhead``:
    :mod:`vinculo.bench.python_overhead`; ``rigid-chain``: :mod:`vinculo.bench.rigid_chain`)."""
    argv = sys.argv[1:] if argv is None else argv
    if argv[:1] == ["work-precision"]:
        from vinculo.bench import work_precision

        return work_precision.main(argv[1:])
    if argv[:1] == ["python-overhead"]:
        from vinculo.bench import python_overhead

        return python_overhead.main(argv[1:])
    if argv[:1] == ["rigid-chain"]:
        from vinculo.bench import rigid_chain

        return rigid_chain.main(argv[1:])
    parser = argparse.ArgumentParser(prog="python -m vinculo.bench", description=__doc__)
    parser.add_argument("--quick", action="store_true", help="small models only (smoke run)")
    parser.add_argument("--no-scaling", action="store_true", help="skip the scaling run")
    parser.add_argument("--scaling-only", action="store_true", help="only the scaling run")
    args = parser.parse_args(argv)
    start = time.perf_counter()
    ok = True
    if not args.scaling_only:
        ok = compare(quick=args.quick)
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
