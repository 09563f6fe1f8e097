"""The ``vinculo`` command line.

Usage::

    vinculo demo [--output DIR]
    vinculo buoy [--output DIR] [--case FILE.toml] [--data FILE.csv] [--tank-motion FILE.csv]
                 [--PARAMETER VALUE ...]
    vinculo buoy --animate FREQ [--animation-file FILE.gif|FILE.mp4] [--animation-frames N]
                 [--output DIR] [--case FILE.toml] [--PARAMETER VALUE ...]
    vinculo buoy sweep --param NAME=VALUES [...] [--scheduler ADDRESS] [--output DIR]
    vinculo buoy calibrate --data FILE.csv [--fit NAMES] [--output DIR]
    vinculo mooring statics FILE [--output DIR]
    vinculo mooring run FILE [--motion FILE.csv] --t-end T [--dt DT] [--output-every S]
                        [--output DIR]

``demo`` runs the four demo models (pendulum, double pendulum, hanging chain, inclined plane),
prints one line per model comparing the simulation with its reference value, and writes one PNG
plot per model into DIR (default ``output``).

``buoy`` runs the buoy study (see :mod:`vinculo.buoy`): every model over the frequency sweep, in
parallel, and writes CSV tables, figures and a summary into DIR; ``vinculo buoy --help`` lists
every parameter. With ``--animate FREQ`` it runs only the particle model at FREQ Hz (for the
sweep's duration at that frequency, ``(settle_periods + fit_periods) / FREQ``) and writes a side
view of the run as an animation (default ``DIR/buoy_<FREQ>Hz.gif``). ``buoy sweep`` runs a
parameter study (:mod:`vinculo.buoy.parameter_study`) and ``buoy calibrate`` fits the fluid
coefficients to measurements (:mod:`vinculo.buoy.calibration`).

``mooring statics`` solves the static equilibrium of a MoorDyn v2 input file and writes
``statics.csv``; ``mooring run`` moves its coupled points by a recorded motion and writes the end
tensions over time, a NetCDF file and plots (see :mod:`vinculo.mooring.cli`).

Exit codes: 0 on success, 1 when a simulation fails, 2 on bad arguments (an option, a value or an
input file), 130 after Ctrl-C (``vinculo buoy`` first writes the runs that finished).
"""

from __future__ import annotations

import argparse
import contextlib
import math
import os
import signal
import sys
import time
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path
from typing import Any

from vinculo import __version__, demos
from vinculo.errors import InvalidInputError, VinculoError

__all__ = ["main"]


def _count(low: int, high: int) -> Callable[[str], int]:
    """An argparse type: a whole number from ``low`` to ``high`` (a usage error otherwise)."""

    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r} is not a whole number") from None
        if not low <= value <= high:
            raise argparse.ArgumentTypeError(
                f"{text} is out of range: give a whole number from {low} to {high}"
            )
        return value

    parse.__name__ = "whole number"  # argparse names the type in its messages
    return parse


_workers = _count(1, 1024)


def _models(text: str) -> tuple[str, ...]:
    """An argparse type: a comma-separated list of one or more of the study's models."""
    from vinculo.buoy.study import MODELS

    models = tuple(m.strip() for m in text.split(",") if m.strip())
    unknown = [m for m in models if m not in MODELS]
    if unknown or not models:
        raise argparse.ArgumentTypeError(
            f"{text!r}: give one or more of {', '.join(MODELS)}, separated by commas"
        )
    return models


def _smoothing(text: str) -> float:
    """An argparse type: a finite number >= 0 (a smoothing penalty)."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
    if not (math.isfinite(value) and value >= 0.0):
        raise argparse.ArgumentTypeError(f"{text!r}: give a finite number >= 0")
    return value
_frames = _count(1, 100_000)


def _number(kind: type, option: str) -> Callable[[str], Any]:
    """An argparse type for a case or sweep option: a finite float, or a whole number that fits
    in 64 bits (the fields check their own ranges)."""

    def parse(text: str) -> Any:
        if kind is int:
            try:
                value = int(text)
            except ValueError:
                raise argparse.ArgumentTypeError(f"{text!r} is not a whole number") from None
            if abs(value) >= 2**63:
                raise argparse.ArgumentTypeError(f"{text} is out of range")
            return value
        if kind is float:
            try:
                value = float(text)
            except ValueError:
                raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
            if not math.isfinite(value):
                raise argparse.ArgumentTypeError(f"{text!r} is not a finite number")
            return value
        return text

    parse.__name__ = "number" if kind in (int, float) else "text"
    return parse


def _unit_text(unit: str) -> str:
    """How a help text states a unit: ``"in m"``, or ``"a count"`` and ``"dimensionless"``."""
    return {"count": "a count", "dimensionless": "dimensionless"}.get(unit, f"in {unit}")


def _build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="vinculo",
        description="Simulate systems of point masses linked by constraints.",
    )
    parser.add_argument("--version", action="version", version=f"vinculo {__version__}")
    commands = parser.add_subparsers(dest="command", metavar="COMMAND")
    commands.required = True
    demo = commands.add_parser(
        "demo",
        help="run the demo models and write their plots",
        description=(
            "Run the pendulum, double pendulum, hanging chain and inclined plane models, print "
            "each one's result against its reference, and write one PNG plot per model."
        ),
    )
    demo.add_argument(
        "--output",
        "-o",
        metavar="DIR",
        type=Path,
        default=Path("output"),
        help="folder for the plots (created if missing; default: output)",
    )
    demo.set_defaults(handler=_demo)
    _add_buoy_parser(commands)
    from vinculo.mooring.cli import add_mooring_parser

    add_mooring_parser(commands)
    from vinculo.ocean.cli import add_moored_buoy_parser

    add_moored_buoy_parser(commands)
    return parser


def _add_buoy_parser(commands: Any) -> None:
    """``vinculo buoy``: every case and sweep parameter as an option."""
    buoy = commands.add_parser(
        "buoy",
        help="the tethered buoy in a shaken tank: amplitude and phase against frequency",
        description=(
            "Simulate the submerged sphere tied to the floor of a shaken water tank with the "
            "particle model and the 1-DOF and 2-DOF reference models over a frequency sweep; "
            "write time histories, amplitude and phase curves, CSV tables and a summary. "
            "Defaults are the paper's parameters; the table amplitude X0 is an assumption. "
            "See also 'vinculo buoy sweep --help' (parameter studies) and 'vinculo buoy "
            "calibrate --help' (fitting Cd and Ca to measurements)."
        ),
    )
    buoy.add_argument("--output", "-o", metavar="DIR", type=Path, default=Path("output"),
                      help="folder for the results (default: output)")
    buoy.add_argument("--data", metavar="FILE.csv", type=Path,
                      help="measured frequency, amplitude (m), phase (deg) to plot beside the "
                      "models")
    buoy.add_argument("--data-motion", choices=("absolute", "relative"), default="absolute",
                      help="whether the measured amplitude is of the absolute or the relative "
                      "motion (default: absolute)")
    buoy.add_argument("--tank-motion", metavar="FILE.csv", type=Path, action="append",
                      default=[],
                      help="a measured tank displacement record (time (s), displacement (m)) to "
                      "drive the models instead of the harmonic sweep; repeat for several "
                      "records. Each is smoothed by a spline and fitted at its dominant "
                      "frequency over its last fit-periods periods")
    buoy.add_argument("--tank-smoothing", metavar="LAM", type=_smoothing, default=None,
                      help="penalty lam (s^3) of the records' smoothing spline (0 interpolates; "
                      "default: fit within the noise estimated from the record)")
    buoy.add_argument("--models", type=_models, default="particle,two-dof,one-dof",
                      help="comma-separated models to run, from: particle, two-dof, one-dof "
                      "(default: all three)")
    buoy.add_argument("--history-frequencies", metavar="F1,F2,...", default=None,
                      help="frequencies (Hz) whose time histories to keep and plot, each run "
                      "(added to the sweep when not on its grid; 'none' for none). Default: the "
                      "paper's 0.8, 0.9 and 1.1 Hz that lie within the sweep's range")
    buoy.add_argument("--workers", metavar="N", type=_workers, default=None,
                      help="worker processes, a count from 1 to 1024 (default: one per CPU)")
    buoy.add_argument("--no-progress", action="store_true", help="do not draw a progress bar")
    buoy.add_argument("--animate", metavar="FREQ", type=float, default=None,
                      help="instead of the sweep, run the particle model at FREQ (Hz) and write a "
                      "side view of the run as an animation")
    buoy.add_argument("--animation-file", metavar="PATH", type=Path, default=None,
                      help="the animation's file, .gif or .mp4 (mp4 needs ffmpeg; default: "
                      "DIR/buoy_<FREQ>Hz.gif)")
    buoy.add_argument("--animation-frames", metavar="N", type=_frames, default=250,
                      help="the most frames (a count from 1 to 100000), at 25 per simulated "
                      "second: the animation shows the last N/25 s of the run (default: 250)")
    _add_case_options(buoy)
    buoy.set_defaults(handler=_buoy)


def _add_case_options(parser: argparse.ArgumentParser) -> None:
    """``--case FILE.toml`` and every case and sweep parameter as an option."""
    import dataclasses

    from vinculo.buoy import ATTACHMENTS, VISCOUS_FORCES, BuoyCase, SweepSettings
    from vinculo.buoy.case import UNITS

    parser.add_argument("--case", metavar="FILE.toml", type=Path,
                        help="TOML file (UTF-8) with a [case] and/or [sweep] table; options "
                        "override it")
    # The text-valued fields: their valid values and what they mean.
    choices = {
        "attachment": (ATTACHMENTS, f"where the string is tied: {ATTACHMENTS[0]} (the sphere's "
                       f"lowest point) or {ATTACHMENTS[1]}"),
        "viscous_force": (VISCOUS_FORCES, "viscous force on the sphere besides Morison's: none, "
                          "or stokes-layer (oscillatory boundary layer, Stokes 1851)"),
    }
    for cls, table in [(BuoyCase, "case"), (SweepSettings, "sweep")]:
        group = parser.add_argument_group(
            f"{table} parameters (override the TOML [{table}] table)"
        )
        for f in dataclasses.fields(cls):
            if f.name == "tank_size":
                continue
            kind = type(f.default)
            option = "--" + f.name.replace("_", "-")
            if f.name in choices:
                values, meaning = choices[f.name]
                group.add_argument(option, dest=f"{table}__{f.name}", choices=values,
                                   default=None, help=f"{meaning} (default: {f.default})")
                continue
            group.add_argument(option, dest=f"{table}__{f.name}", metavar=f.name.upper(),
                               type=_number(kind, option), default=None,
                               help=f"{_unit_text(UNITS[f.name])} (default: {f.default})")


def _case_and_settings(args: argparse.Namespace) -> tuple[Any, Any]:
    """The BuoyCase and SweepSettings of ``--case`` and the parameter options."""
    from vinculo.buoy import BuoyCase, SweepSettings, load_study

    case_values: dict[str, Any] = {}
    sweep_values: dict[str, Any] = {}
    if args.case is not None:
        case, sweep = load_study(args.case)
        case_values, sweep_values = case.to_dict(), sweep.to_dict()
    for key, value in vars(args).items():
        if value is None or "__" not in key:
            continue
        table, name = key.split("__", 1)
        (case_values if table == "case" else sweep_values)[name] = value
    return (
        BuoyCase.from_mapping(case_values, source="the command line"),
        SweepSettings.from_mapping(sweep_values, source="the command line"),
    )


def _study_parser() -> argparse.ArgumentParser:
    """``vinculo buoy sweep``: a parameter study over a grid."""
    parser = argparse.ArgumentParser(
        prog="vinculo buoy sweep",
        description=(
            "Run the buoy models over a grid of any case parameters (and the frequency) in "
            "parallel, on local processes or on a Dask cluster. Each run is appended to "
            "DIR/study.csv as it finishes; running the same command again resumes the study "
            "without recomputing finished runs. Without a frequency axis every point is swept "
            "over --f-min/--f-max/--count."
        ),
    )
    parser.add_argument("--param", "-p", metavar="NAME=VALUES", action="append", default=[],
                        required=True,
                        help="an axis: NAME=START:STOP:COUNT or NAME=V1,V2,... (repeat for a "
                        "grid); NAME is a case parameter (drag_coefficient, amplitude, ...), "
                        "frequency, dt, settle_periods or fit_periods")
    parser.add_argument("--models", type=_models, default="particle",
                        help="comma-separated models to run at each point, from: particle, "
                        "two-dof, one-dof (default: particle)")
    parser.add_argument("--retry-failed", action="store_true",
                        help="run again the points whose earlier run failed")
    _add_execution_options(parser, "study", "study.csv and the plot")
    _add_case_options(parser)
    parser.set_defaults(handler=_buoy_sweep)
    return parser


def _calibrate_parser() -> argparse.ArgumentParser:
    """``vinculo buoy calibrate``: fit Cd and Ca (and more) to measured curves."""
    parser = argparse.ArgumentParser(
        prog="vinculo buoy calibrate",
        description=(
            "Fit the drag and added-mass coefficients (optionally the string length and the "
            "table amplitude) so that a buoy model reproduces measured amplitude and phase "
            "curves, by weighted least squares; report the values with uncertainties and plot "
            "the fitted curves over the data."
        ),
    )
    parser.add_argument("--data", metavar="FILE.csv", type=Path, required=True,
                        help="measured frequency (Hz), amplitude (m), phase (deg), optionally "
                        "amplitude_sd and phase_sd columns (standard uncertainties)")
    parser.add_argument("--data-motion", choices=("absolute", "relative"), default="absolute",
                        help="whether the data are of the absolute or the relative motion")
    parser.add_argument("--fit", default="drag_coefficient,added_mass_coefficient",
                        help="comma-separated parameters to fit (default: "
                        "drag_coefficient,added_mass_coefficient; also string_length, "
                        "amplitude)")
    parser.add_argument("--model", default="particle",
                        help="the model to fit: particle, two-dof or one-dof (default: particle)")
    parser.add_argument("--max-evaluations", metavar="N", type=_count(1, 100_000), default=60,
                        help="most model sweeps the calibration runs, a count: the optimiser's "
                        "steps, its finite differences and the fitted curve all count "
                        "(default: 60)")
    parser.add_argument("--curve-points", metavar="N", type=_count(0, 10_000), default=21,
                        help="frequencies of the fitted curve drawn over the data (default: 21; "
                        "0: only at the measured frequencies)")
    _add_execution_options(parser, "calibration", "the results")
    _add_case_options(parser)
    parser.set_defaults(handler=_buoy_calibrate)
    return parser


def _add_execution_options(parser: argparse.ArgumentParser, folder: str, holds: str) -> None:
    """``--output``, ``--workers``, ``--scheduler`` and ``--no-progress`` of a study command."""
    parser.add_argument("--output", "-o", metavar="DIR", type=Path,
                        default=Path("output") / folder,
                        help=f"folder of {holds} (default: output/{folder})")
    parser.add_argument("--workers", metavar="N", type=_workers, default=None,
                        help="local worker processes, a count from 1 to 1024 (default: one per "
                        "CPU)")
    parser.add_argument("--scheduler", metavar="ADDRESS",
                        help="run on an existing Dask distributed cluster (tcp://host:8786)")
    parser.add_argument("--no-progress", action="store_true", help="show no progress")


def _output_folder(output: Path, parser: argparse.ArgumentParser) -> Path:
    """Create the output folder, or stop with a usage error naming it."""
    if output.exists() and not output.is_dir():
        parser.error(f"--output {str(output)!r} exists and is not a folder")
    try:
        output.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        parser.error(f"cannot create the output folder {str(output)!r}: {exc.strerror}")
    return output


def _buoy_sweep(args: argparse.Namespace, parser: argparse.ArgumentParser) -> int:
    """Run a parameter study and write its table and plot."""
    from vinculo.buoy.parameter_study import grid, parse_axis, run_parameter_study
    from vinculo.buoy.report import plot_parameter_study

    case, settings = _case_and_settings(args)
    axes = dict(parse_axis(text) for text in args.param)
    points = grid(axes)
    models = args.models
    output = _output_folder(args.output, parser)
    try:
        study = run_parameter_study(
            points, case=case, settings=settings, models=models, output=output,
            workers=args.workers, scheduler=args.scheduler, retry_failed=args.retry_failed,
            progress=not args.no_progress,
        )
    except KeyboardInterrupt:
        print(
            f"\ninterrupted: the finished runs are in {output / 'study.csv'}; run the same "
            f"command again to resume",
            file=sys.stderr,
        )
        return 130
    plot = plot_parameter_study(study, output / "study.png")
    failed = study.failures()
    print(
        f"{len(study.rows)} runs ({study.computed} computed, {study.reused} reused from "
        f"{study.path}) in {study.elapsed:.1f} s on {study.workers}; {len(failed)} failed",
        flush=True,
    )
    for row in failed:
        print(f"FAILED {row.model} {row.parameters}: {row.error}", flush=True)
    print(f"results: {study.path}" + (f", {plot}" if plot else ""), flush=True)
    return 1 if failed else 0


def _buoy_calibrate(args: argparse.Namespace, parser: argparse.ArgumentParser) -> int:
    """Fit the requested parameters to the data and write the results."""
    from vinculo.buoy import read_measurements
    from vinculo.buoy.calibration import calibrate
    from vinculo.buoy.report import write_calibration

    case, settings = _case_and_settings(args)
    data = read_measurements(args.data, motion=args.data_motion)
    names = [n.strip() for n in args.fit.split(",") if n.strip()]
    output = _output_folder(args.output, parser)
    try:
        result = calibrate(
            data, case=case, settings=settings, parameters=names, model=args.model,
            workers=args.workers, scheduler=args.scheduler, max_evaluations=args.max_evaluations,
            curve_points=args.curve_points, progress=not args.no_progress,
        )
    except KeyboardInterrupt:
        print("vinculo buoy calibrate: interrupted; nothing written (a calibration does not "
              "resume: run it again)", file=sys.stderr, flush=True)
        return 130
    paths = write_calibration(result, output)
    print(result.summary(), flush=True)
    print(f"results: {len(paths)} files in {output}", flush=True)
    return 0 if result.success else 1


def _demo(args: argparse.Namespace, parser: argparse.ArgumentParser) -> int:
    """Run the four demo models, print a line for each, and plot them into args.output."""
    output: Path = args.output
    if output.exists() and not output.is_dir():
        parser.error(f"--output {str(output)!r} exists and is not a folder")
    try:
        output.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        parser.error(f"cannot create the output folder {str(output)!r}: {exc.strerror}")

    from vinculo import plotting  # matplotlib is imported only when plots are drawn

    runs: list[tuple[str, Callable[[], Any], Callable[[Any, Path], Path]]] = [
        ("pendulum", demos.run_pendulum, plotting.plot_pendulum),
        ("double_pendulum", demos.run_double_pendulum, plotting.plot_double_pendulum),
        ("hanging_chain", demos.run_hanging_chain, plotting.plot_hanging_chain),
        ("inclined_plane", demos.run_inclined_plane, plotting.plot_inclined_plane),
    ]
    for name, run, plot in runs:
        result = run()
        print(result.summary_line(), flush=True)
        path = plot(result, output / f"{name}.png")
        print(f"  plot: {path}", flush=True)
    return 0


def _buoy(args: argparse.Namespace, parser: argparse.ArgumentParser) -> int:
    """Run the buoy study and write its report into args.output."""
    from vinculo.buoy import read_measurements, read_tank_motion
    from vinculo.buoy.report import summary, write_report
    from vinculo.buoy.study import _draw, run_study

    case, settings = _case_and_settings(args)
    data = read_measurements(args.data, motion=args.data_motion) if args.data else None
    motions = [read_tank_motion(p, smoothing=args.tank_smoothing) for p in args.tank_motion]
    models = args.models
    output: Path = args.output
    if output.exists() and not output.is_dir():
        parser.error(f"--output {str(output)!r} exists and is not a folder")
    if args.animate is not None:
        return _buoy_animation(args, parser, case, settings)
    history = _history_frequencies(args.history_frequencies, parser)
    sources = _parameter_sources(args)
    _output_folder(output, parser)  # before the runs, so that a bad folder costs nothing
    finished: list[Any] = []
    started = time.perf_counter()

    def collect(done: int, total: int, result: Any) -> None:
        finished.append(result)
        if not args.no_progress:
            _draw(sys.stderr, done, total, result, time.perf_counter() - started)

    try:
        study = run_study(case, settings, models=models, workers=args.workers,
                          progress=collect, motions=motions, history_frequencies=history)
    except KeyboardInterrupt:
        if finished and not args.no_progress:
            print(file=sys.stderr, flush=True)  # end the progress bar's line
        return _buoy_interrupted(finished, case, settings, output, data, started, sources)
    if finished and not args.no_progress:
        print(file=sys.stderr, flush=True)
    paths = write_report(study, output, data, sources)
    print(summary(study, sources), flush=True)
    print(f"results: {len(paths)} files in {output}", flush=True)
    return 1 if study.failures() else 0


def _history_frequencies(
    text: str | None, parser: argparse.ArgumentParser
) -> tuple[float, ...] | None:
    """The frequencies of ``--history-frequencies`` (None when not given)."""
    import math

    if text is None:
        return None
    if text.strip().lower() == "none":
        return ()
    try:
        values = tuple(float(v) for v in text.split(",") if v.strip())
    except ValueError:
        parser.error(f"--history-frequencies {text!r}: give frequencies in Hz separated by "
                     f"commas, e.g. 0.8,0.9,1.1, or 'none'")
    bad = [v for v in values if not (math.isfinite(v) and v > 0.0)]
    if bad or not values:
        parser.error(f"--history-frequencies {text!r}: every frequency must be a finite number "
                     f"of Hz greater than 0")
    return values


def _parameter_sources(args: argparse.Namespace) -> dict[str, str]:
    """Where each case and sweep parameter given by the user came from: the ``--case`` file or
    an option (options override the file), for parameters.csv."""
    from vinculo.buoy.case import _read_toml

    sources: dict[str, str] = {}
    if args.case is not None:
        data = _read_toml(args.case)
        for table, prefix in (("case", ""), ("sweep", "sweep.")):
            for name in data.get(table, {}):
                sources[prefix + name] = f"case file {args.case}"
    for key, value in vars(args).items():
        if value is None or "__" not in key:
            continue
        table, name = key.split("__", 1)
        prefix = "" if table == "case" else "sweep."
        sources[prefix + name] = f"option --{name.replace('_', '-')}"
    return sources


def _buoy_interrupted(
    finished: list[Any],
    case: Any,
    settings: Any,
    output: Path,
    data: Any,
    started: float,
    sources: dict[str, str],
) -> int:
    """After Ctrl-C of the study: write the runs that finished, say so in one line, exit 130."""
    from vinculo.buoy.report import write_report
    from vinculo.buoy.study import MODELS, StudyResult

    order = {m: i for i, m in enumerate(MODELS)}
    runs = sorted(finished, key=lambda r: (order[r.model], r.frequency, r.record or ""))
    kept = ""
    if any(r.response is not None for r in runs):
        partial = StudyResult(case, settings, runs, time.perf_counter() - started, 0)
        try:
            with _deferred_interrupts():
                paths = write_report(partial, output, data, sources)
            kept = f"; the {len(runs)} finished runs are in {len(paths)} files in {output}"
        except (VinculoError, OSError, ValueError) as error:
            kept = f"; writing the {len(runs)} finished runs failed: {error}"
    print(f"vinculo buoy: interrupted{kept or ' before any run finished; nothing written'}",
          file=sys.stderr, flush=True)
    return 130


@contextlib.contextmanager
def _deferred_interrupts() -> Iterator[None]:
    """Ignore further Ctrl-C while the partial results are written (a second one would leave
    the report half-written; every file is written under a temporary name, then renamed)."""
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)


def _buoy_animation(
    args: argparse.Namespace, parser: argparse.ArgumentParser, case: Any, settings: Any
) -> int:
    """Run the particle model at args.animate Hz and write the animation of the run."""
    import math

    from vinculo.buoy.animation import animate_frequency
    from vinculo.errors import InvalidInputError

    frequency = float(args.animate)
    if args.tank_motion:
        parser.error("--animate runs the harmonic excitation; it cannot be combined with "
                     "--tank-motion")
    if not (math.isfinite(frequency) and frequency > 0):
        parser.error(f"--animate {args.animate!r}: give a frequency in Hz greater than 0")
    if args.animation_frames < 1:
        parser.error(f"--animation-frames {args.animation_frames}: give a whole number >= 1")
    path: Path = args.animation_file
    if path is None:
        path = args.output / f"buoy_{frequency:g}Hz.gif"
        try:
            args.output.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            parser.error(f"cannot create the output folder {str(args.output)!r}: {exc.strerror}")
    show = not args.no_progress

    def simulated(t: float, t_end: float) -> None:
        print(f"\rsimulating: t = {t:7.2f} of {t_end:.2f} s", end="", file=sys.stderr,
              flush=True)

    def rendered(done: int, total: int) -> None:
        start = "\n" if done == 1 else "\r"
        end = "\n" if done == total else ""
        print(f"{start}rendering: frame {done} of {total}", end=end, file=sys.stderr, flush=True)

    t_end = settings.t_end(frequency)
    try:
        written, run = animate_frequency(
            case, frequency, path, t_end=t_end, dt=settings.dt,
            simulation_progress=simulated if show else None,
            progress=rendered if show else None,
            max_frames=args.animation_frames,
        )
    except InvalidInputError as exc:
        parser.error(str(exc))
    if run.error is not None:
        print(f"run stopped early at t = {run.time[-1]:.3f} s: {run.error}", flush=True)
    print(f"animation: {written} ({run.frequency:g} Hz, t = 0 to {run.time[-1]:.2f} s)",
          flush=True)
    return 1 if run.error is not None else 0


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line.

    Arguments:
        argv: the arguments (default: ``sys.argv[1:]``).

    Returns:
        The exit code: 0 on success, 1 if a simulation failed, 2 for a bad argument or input
        file (an :class:`~vinculo.errors.InvalidInputError`), 130 after Ctrl-C, 141 when the
        reader of its output closed it (a pipe into `head`).

    Raises:
        SystemExit: with code 2 on bad arguments (from argparse), or 0 after ``--help``.
    """
    argv = list(sys.argv[1:] if argv is None else argv)
    if argv[:2] in (["buoy", "sweep"], ["buoy", "calibrate"]):
        parser = _study_parser() if argv[1] == "sweep" else _calibrate_parser()
        argv = argv[2:]
    else:
        parser = _build_parser()
    args = parser.parse_args(argv)
    try:
        return int(args.handler(args, parser))
    except InvalidInputError as exc:  # a bad argument, option value or input file
        print(f"{parser.prog}: error: {exc}", file=sys.stderr)
        return 2
    except VinculoError as exc:
        print(f"{parser.prog}: error: {exc}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print(f"{parser.prog}: interrupted", file=sys.stderr, flush=True)
        return 130
    except BrokenPipeError:
        # The reader of the output went away (``vinculo ... | head``): the rest of the output
        # goes nowhere, and the interpreter's last flush of stdout must not fail again.
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 141


if __name__ == "__main__":
    sys.exit(main())
