"""``vinculo moored-buoy``: a buoy moored in the sea, from a TOML case file.

Usage::

    vinculo moored-buoy CASE.toml [--output DIR] [--t-end T] [--dt DT] [--rao] [--no-plots]
                        [--no-progress]

Builds the case (:mod:`vinculo.ocean.moored_buoy`), puts it in static equilibrium, prints the
fairlead tensions there, runs it in the case's sea and writes ``DIR/run.csv``, ``DIR/run.nc``,
``DIR/spectra.nc`` and the plots ``DIR/motions.png`` and ``DIR/spectra.png``; with ``--rao``
also the regular-wave sweep of the case's ``[rao]`` table (``DIR/rao.csv``, ``DIR/rao.png``).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

from vinculo.mooring.cli import _existing_file, _output, _positive_time

__all__ = ["add_moored_buoy_parser"]


def add_moored_buoy_parser(commands: Any) -> None:
    """Add ``vinculo moored-buoy``.

    Arguments:
        commands: the subparsers of the ``vinculo`` parser.
    """
    parser = commands.add_parser(
        "moored-buoy",
        help="a buoy moored in waves and currents: motions, tensions, spectra, RAOs",
        description=(
            "Read a moored-buoy case (TOML: the buoy and its hull, a MoorDyn file of the "
            "mooring lines, the sea), solve its static equilibrium, run it in the case's waves "
            "and current, and write the motions, fairlead and anchor tensions and the surface "
            "elevation (DIR/run.csv, DIR/run.nc), their spectra (DIR/spectra.nc) and plots "
            "(DIR/motions.png, DIR/spectra.png); --rao adds the response amplitude operators "
            "from a regular-wave sweep (DIR/rao.csv, DIR/rao.png). Examples: "
            "examples/moored_buoy/."
        ),
    )
    parser.add_argument("case", metavar="CASE.toml", type=_existing_file,
                        help="the case file")
    parser.add_argument("--output", "-o", metavar="DIR", type=Path, default=Path("output"),
                        help="folder of the results (created if missing; default: output)")
    parser.add_argument("--t-end", metavar="T", type=_positive_time, default=None,
                        help="the run's length (s; default the case's [run] t_end)")
    parser.add_argument("--dt", metavar="DT", type=_positive_time, default=None,
                        help="the step size (s; default the case's [run] dt)")
    parser.add_argument("--rao", action="store_true",
                        help="also sweep the case's [rao] periods in regular waves")
    parser.add_argument("--no-plots", action="store_true", help="do not draw the plots")
    parser.add_argument("--no-progress", action="store_true", help="do not draw a progress bar")
    parser.set_defaults(handler=_moored_buoy)


def _moored_buoy(args: argparse.Namespace, parser: argparse.ArgumentParser) -> int:
    from vinculo.ocean import moored_buoy as mb

    case = mb.read_case(args.case)  # a bad file fails before the output folder is made
    folder = _output(args.output, parser)
    built = mb.build(case)
    print(f"{args.case}: {case.title}", flush=True)
    q = built.statics.positions[built.body["centre"].index]
    print(f"equilibrium: centre of gravity at ({q[0]:.3f}, {q[1]:.3f}, {q[2]:.3f}) m "
          f"({built.statics.method}, {built.statics.iterations} iterations)", flush=True)
    for line, end in zip(built.lines, built.fairleads, strict=True):
        t = line.tensions(built.statics)[0]
        fair = t[-1] if end != 0 else t[0]
        print(f"  {line.name}: fairlead tension {fair:.6g} N", flush=True)
    result = mb.run(built, t_end=args.t_end, dt=args.dt, progress=not args.no_progress)
    print(f"run: t = 0 to {result.times[-1]:g} s, {result.solution.num_steps} steps, "
          f"{result.cpu_time:.3g} s CPU", flush=True)
    after = result.times >= case.sea.ramp
    if not after.any():  # a run shorter than the waves' ramp: all of it
        after[:] = True
    names = ("surge", "heave", "pitch")
    for k, name in zip((0, 2, 4), names, strict=True):
        series = result.motions[after, k]
        unit, scale = ("deg", 57.29577951308232) if name == "pitch" else ("m", 1.0)
        print(f"  {name}: {scale * series.min():.4g} to {scale * series.max():.4g} {unit}, "
              f"significant {4 * scale * series.std():.4g} {unit}", flush=True)
    for k, line in enumerate(built.lines):
        t = result.tensions[after, k, 0]
        print(f"  {line.name}: fairlead tension {t.min():.6g} to {t.max():.6g} N", flush=True)
    table = None
    if args.rao:
        table = mb.rao(case)
        print("RAO (amplitude per m of wave): period, surge, heave, pitch (deg/m)", flush=True)
        for i, period in enumerate(table.periods):
            a = table.amplitude[i]
            print(f"  {period:6.2f} s  {a[0]:.4f}  {a[2]:.4f}  {57.29577951308232 * a[4]:.4f}",
                  flush=True)
    files = mb.write(result, folder, rao_table=table, plots=not args.no_plots)
    print(f"results: {', '.join(str(p) for p in files.values())}", file=sys.stdout, flush=True)
    return 0
