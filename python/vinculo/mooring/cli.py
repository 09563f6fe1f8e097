"""``vinculo mooring``: the statics and runs of a MoorDyn input file from the command line.

Usage::

    vinculo mooring statics FILE [--output DIR] [--reference X Y Z]
    vinculo mooring offsets FILE --max M [--count N] [--heading DEG | --about x|y|z]
                            [--reference X Y Z] [--output DIR]
    vinculo mooring run FILE [--motion FILE.csv] --t-end T [--dt DT] [--output-every S]
                        [--start statics|file] [--tolerance TOL] [--check-step]
                        [--output DIR] [--no-plots] [--no-progress]

``statics`` prints each line's end tensions and laid length and writes ``DIR/statics.csv``
(columns ``line,end,point,x,y,z,fx,fy,fz,tension,laid_length``, two rows per line: end A, then
end B; ``fx fy fz`` the force the line exerts on the end point) and, when the file has
Vessel/Coupled points, the 6x6 stiffness of the mooring on a vessel carrying them
(``DIR/stiffness.csv``, about ``--reference``; a Coupled body's, about its reference point, in
``DIR/stiffness_body<k>.csv``) and their joint 3x3 blocks (``DIR/point_stiffness.csv``).
``offsets`` moves the coupled points together from -M to M along a heading (or turns them about
an axis) and writes the restoring force (or moment) and line tensions at each offset
(``DIR/offsets.csv``, ``DIR/offsets.png``; :mod:`vinculo.mooring.offsets`). ``run`` starts from
that equilibrium, moves the Vessel/Coupled points and bodies by the motion file (``time``, then
each coupled body's pose and each other coupled point's ``x, y, z``: :mod:`vinculo.mooring.motion`)
and writes ``DIR/tensions.csv``, ``DIR/run.nc``, the plots
``DIR/shapes.png`` and ``DIR/tensions.png``, and, when the file has an OUTPUTS section,
``DIR/channels.csv`` (its channels over time, :mod:`vinculo.mooring.channels`); with
``--check-step`` it runs again at half the step and prints how much the end tensions change, an
estimate of the run's time-step error (:func:`vinculo.mooring.analysis.check_step`);
``--tolerance`` sets Newton's tolerance (its cost against the end tensions' change:
docs/guide/moorings.md).
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path
from typing import Any

__all__ = ["add_mooring_parser"]


def _argument_type(name: str, convert: Any, valid: Any, hint: str) -> Any:
    """An argparse type named ``name``: ``convert(text)`` (float or int), refused with
    ``hint`` unless ``valid(value)``."""

    def parse(text: str) -> Any:
        try:
            value = convert(text)
        except ValueError:
            whole = "whole " if convert is int else ""
            raise argparse.ArgumentTypeError(f"{text!r} is not a {whole}number") from None
        if not valid(value):
            raise argparse.ArgumentTypeError(f"{text!r}: {hint}")
        return value

    parse.__name__ = name
    return parse


def _positive(value: float) -> bool:
    return math.isfinite(value) and value > 0.0


#: A finite time > 0 (s).
_positive_time = _argument_type("time", float, _positive, "give a time in s greater than 0")
#: Newton's tolerance, relative to the model's length scale.
_tolerance = _argument_type(
    "tolerance", float, lambda v: math.isfinite(v) and 0.0 < v < 1.0,
    "give a tolerance greater than 0 and below 1 (relative to the model's length scale; "
    "default 1e-10)")
#: A finite coordinate (m).
_coordinate = _argument_type("coordinate", float, math.isfinite,
                             "give a finite coordinate in m")
#: The largest offset: a finite number > 0 (m, or degrees of a rotation).
_largest_offset = _argument_type("offset", float, _positive,
                                 "give a number greater than 0 (m, or degrees with --about)")
#: A number of offsets, 2 or more.
_offset_count = _argument_type("count", int, lambda v: v >= 2, "give 2 offsets or more")


def _existing_file(text: str) -> Path:
    """An argparse type: a file that exists."""
    path = Path(text)
    if not path.is_file():
        raise argparse.ArgumentTypeError(f"{text!r} is not a file")
    return path


_existing_file.__name__ = "file"


def add_mooring_parser(commands: Any) -> None:
    """Add ``vinculo mooring`` and its ``statics`` and ``run`` commands.

    Arguments:
        commands: the subparsers of the ``vinculo`` parser.
    """
    mooring = commands.add_parser(
        "mooring",
        help="statics and runs of a MoorDyn input file",
        description=(
            "Read a MoorDyn v2 input file (LINE TYPES, BODIES, POINTS, LINES, OPTIONS) and "
            "solve its static equilibrium, or run it with the Vessel/Coupled points moved by a "
            "recorded motion (a Coupled body by its six degrees of freedom). Rods, free bodies "
            "and wave grids are not supported yet: such a file is rejected with an error "
            "naming the line and the field."
        ),
    )
    actions = mooring.add_subparsers(dest="mooring_command", metavar="ACTION")
    actions.required = True
    statics = actions.add_parser(
        "statics",
        help="static equilibrium: end tensions and laid lengths, statics.csv",
        description=(
            "Solve the static equilibrium of the mooring (Newton on the equilibrium equations, "
            "no time step), print each line's end tensions and laid length, and write "
            "DIR/statics.csv with the columns line,end,point,x,y,z,fx,fy,fz,tension,"
            "laid_length: two rows per line, end A then end B; fx fy fz is the force the line "
            "exerts on the end point (N), laid_length the length on the seabed (m). With "
            "Vessel/Coupled points, also print the 6x6 linearised stiffness of the mooring on "
            "a vessel carrying them, about --reference, and write it (DIR/stiffness.csv) with "
            "the joint 3x3 blocks of the points (DIR/point_stiffness.csv); a Coupled body's "
            "points get the body's own, about its reference point "
            "(DIR/stiffness_body<k>.csv)."
        ),
    )
    statics.add_argument("file", metavar="FILE", type=_existing_file,
                         help="the MoorDyn v2 input file")
    statics.add_argument("--output", "-o", metavar="DIR", type=Path, default=Path("output"),
                         help="folder of statics.csv (created if missing; default: output)")
    statics.add_argument("--reference", metavar=("X", "Y", "Z"), type=_coordinate, nargs=3,
                         default=(0.0, 0.0, 0.0),
                         help="the vessel's reference point, about which its rotations and "
                         "moments are taken (m; default 0 0 0, the origin of the file's "
                         "coordinates)")
    statics.set_defaults(handler=_statics)
    offsets = actions.add_parser(
        "offsets",
        help="offset curve: restoring force and tensions as the coupled points move",
        description=(
            "Move the Vessel/Coupled points together by offsets along a horizontal heading (or "
            "turn them about an axis through --reference), solve the static equilibrium at "
            "each, print the restoring force (or moment) and the lines' largest end tensions, "
            "and write DIR/offsets.csv (offset, fx, fy, fz, mx, my, mz, restoring, then each "
            "line's end tensions and laid length) and DIR/offsets.png. An offset "
            "whose equilibrium is not found is reported and left NaN; the others are kept."
        ),
    )
    offsets.add_argument("file", metavar="FILE", type=_existing_file,
                         help="the MoorDyn v2 input file")
    offsets.add_argument("--max", metavar="M", type=_largest_offset, required=True,
                         help="the largest offset (m; degrees with --about): the offsets run "
                         "from -M to M")
    offsets.add_argument("--count", metavar="N", type=_offset_count, default=21,
                         help="the number of offsets from -M to M (default 21)")
    way = offsets.add_mutually_exclusive_group()
    way.add_argument("--heading", metavar="DEG", type=_coordinate, default=None,
                     help="the offsets' heading in the horizontal plane, degrees from +x "
                     "towards +y (default 0)")
    way.add_argument("--about", choices=("x", "y", "z"), default=None,
                     help="turn the points about this axis through --reference instead, by "
                     "angles in degrees (roll, pitch, yaw)")
    offsets.add_argument("--reference", metavar=("X", "Y", "Z"), type=_coordinate, nargs=3,
                         default=(0.0, 0.0, 0.0),
                         help="the point the moments are taken about and the rotations made "
                         "about (m; default 0 0 0)")
    offsets.add_argument("--output", "-o", metavar="DIR", type=Path, default=Path("output"),
                         help="folder of offsets.csv and offsets.png (created if missing; "
                         "default: output)")
    offsets.add_argument("--no-plots", action="store_true", help="do not draw the plot")
    offsets.set_defaults(handler=_offsets)
    run = actions.add_parser(
        "run",
        help="move the coupled points by a recorded motion: tensions over time, NetCDF, plots",
        description=(
            "Start from the static equilibrium and move the Vessel/Coupled points by a recorded "
            "motion; write the end forces and tensions over time (DIR/tensions.csv), the whole "
            "run as NetCDF (DIR/run.nc), plots of the line shapes and tensions "
            "(DIR/shapes.png, DIR/tensions.png) and the file's OUTPUTS channels "
            "(DIR/channels.csv)."
        ),
    )
    run.add_argument("file", metavar="FILE", type=_existing_file,
                     help="the MoorDyn v2 input file")
    run.add_argument("--motion", metavar="FILE.csv", type=_existing_file, default=None,
                     help="the motion: a header line, then rows of time (s), x, y, z (m) and "
                     "roll, pitch, yaw (deg) of each Coupled body in the order of the BODIES "
                     "section, then x, y, z (m) of each other coupled point in the order of "
                     "the POINTS section; the columns are interpolated by natural cubic "
                     "splines (default: the points stay put)")
    run.add_argument("--t-end", metavar="T", type=_positive_time, required=True,
                     help="the end time (s)")
    run.add_argument("--dt", metavar="DT", type=_positive_time, default=0.02,
                     help="the step size (s; default 0.02): the implicit scheme has no "
                     "stability limit, so the step follows the accuracy wanted")
    run.add_argument("--output-every", metavar="S", type=_positive_time, default=None,
                     help="the interval of the stored states (s): a whole number of steps, "
                     "as MoorDyn's dtOut (default: every step)")
    run.add_argument("--output", "-o", metavar="DIR", type=Path, default=Path("output"),
                     help="folder of the results (created if missing; default: output)")
    run.add_argument("--start", choices=("statics", "file"), default="statics",
                     help="the initial state: the static equilibrium (default), or the file's "
                     "point positions and the lines' initial shapes at rest (MoorDyn with "
                     "TmaxIC 0)")
    run.add_argument("--tolerance", metavar="TOL", type=_tolerance, default=None,
                     help="Newton's tolerance, relative to the model's length scale (default "
                     "1e-10): a looser one takes fewer iterations a step; on the benchmark's "
                     "lines 1e-8 changed the end tensions by up to 2.3e-4 of the peak tension "
                     "for 1.2 to 1.6 times less CPU (docs/guide/moorings.md)")
    run.add_argument("--check-step", action="store_true",
                     help="run again at half the step and print how much the end tensions "
                     "change: an estimate of the run's time-step error (twice the CPU time)")
    run.add_argument("--no-plots", action="store_true", help="do not draw the plots")
    run.add_argument("--no-progress", action="store_true", help="do not draw a progress bar")
    run.set_defaults(handler=_run)


def _output(folder: Path, parser: argparse.ArgumentParser) -> Path:
    if folder.exists() and not folder.is_dir():
        parser.error(f"--output {str(folder)!r} exists and is not a folder")
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        parser.error(f"cannot create the output folder {str(folder)!r}: {exc.strerror}")
    return folder


def _statics(args: argparse.Namespace, parser: argparse.ArgumentParser) -> int:
    """Solve the statics, print the table and write statics.csv."""
    from vinculo.mooring.analysis import statics
    from vinculo.mooring.moordyn_file import read_moordyn

    model = read_moordyn(args.file)  # a bad file fails before the output folder is made
    folder = _output(args.output, parser)
    result = statics(model)
    print(f"{args.file}: {len(model.lines)} lines, {len(model.points)} points; static "
          f"equilibrium in {result.cpu_time:.3g} s", flush=True)
    slack = result.slack_segments()
    if slack:
        listed = ", ".join(f"line {k}: {n}" for k, n in slack.items())
        print(f"segments without tension, shorter than their length (spare length lying "
              f"slack): {listed}", flush=True)
    print(result.table(), flush=True)
    paths = [result.to_csv(folder / "statics.csv")]
    if result.coupled_points():
        paths += _stiffness(result, args.reference, folder)
    for body in result.coupled_bodies():
        paths += _body_stiffness(result, body, folder)
    print(f"results: {', '.join(str(p) for p in paths)}", flush=True)
    return 0


def _offsets(args: argparse.Namespace, parser: argparse.ArgumentParser) -> int:
    """Solve the statics over the offsets, print the table and write the curve."""
    import numpy as np

    from vinculo.mooring.moordyn_file import read_moordyn
    from vinculo.mooring.offsets import offset_curve, plot_offset_curve

    model = read_moordyn(args.file)
    if not model.coupled_points():
        parser.error(f"{args.file}: the file has no Vessel/Coupled points to move")
    folder = _output(args.output, parser)
    values = np.linspace(-args.max, args.max, args.count)
    if args.about is not None:
        axis = tuple(float(args.about == c) for c in "xyz")
        curve = offset_curve(model, values, rotation_axis=axis, reference=args.reference,
                             progress=True)
        where = ", ".join(f"{c:g}" for c in args.reference)
        how = (f"turned about {args.about} through ({where}) m, {args.count} angles from "
               f"{-args.max:g} to {args.max:g} deg")
    else:
        heading = 0.0 if args.heading is None else args.heading
        curve = offset_curve(model, values, heading=heading, reference=args.reference,
                             progress=True)
        how = (f"moved along heading {heading:g} deg, {args.count} offsets from "
               f"{-args.max:g} to {args.max:g} m")
    print(f"{args.file}: points {', '.join(map(str, curve.points))} {how}", flush=True)
    print(curve.table(), flush=True)
    for s, message in curve.failed.items():
        print(f"offset {s:g} m: no equilibrium: {message}", flush=True)
    paths = [curve.to_csv(folder / "offsets.csv")]
    if not args.no_plots:
        paths.append(plot_offset_curve(curve, folder / "offsets.png"))
    print(f"results: {', '.join(str(p) for p in paths)}", flush=True)
    return 0 if not curve.failed else 1


def _body_stiffness(result: Any, body: int, folder: Path) -> list[Path]:
    """Print the stiffness of the mooring on a coupled body about its reference point and
    write it (none, with a message, when it is infinite)."""
    from vinculo.errors import ConvergenceError

    try:
        k = result.body_stiffness(body)
    except ConvergenceError as exc:
        print(f"stiffness on body {body} not computed: {exc}", flush=True)
        return []
    reference = result.model.file.bodies[body - 1].position
    _print_stiffness(result, f"body {body}, about its reference point", reference, k)
    return [result.stiffness_to_csv(folder / f"stiffness_body{body}.csv", k)]


def _stiffness(result: Any, reference: Any, folder: Path) -> list[Path]:
    """Print the vessel stiffness of the statics ``result`` (its coupled points that are not on
    a body, which get their own) and write it with the joint stiffness of all coupled points
    (none, with a message, when it is infinite)."""
    from vinculo.errors import ConvergenceError

    own = [p.id for p in result.model.file.coupled_points() if p.body is None]
    try:
        vessel = result.vessel_stiffness(reference, own) if own else None
        joint = result.stiffness()
    except ConvergenceError as exc:
        print(f"stiffness at the coupled points not computed: {exc}", flush=True)
        return []
    paths = [result.point_stiffness_to_csv(folder / "point_stiffness.csv", joint)]
    if vessel is not None:
        carried = f"a vessel carrying points {', '.join(map(str, own))}, about"
        _print_stiffness(result, carried, reference, vessel)
        paths.insert(0, result.stiffness_to_csv(folder / "stiffness.csv", vessel))
    return paths


def _print_stiffness(result: Any, what: str, reference: Any, stiffness: Any) -> None:
    """Print a 6x6 stiffness of the mooring on ``what`` about ``reference``, as a table."""
    where = ", ".join(f"{c:g}" for c in reference)
    print(f"stiffness of the mooring on {what} ({where}) m (N/m, N/rad; N m/m, N m/rad):",
          flush=True)
    print(result.stiffness_table(reference, stiffness), flush=True)


def _run(args: argparse.Namespace, parser: argparse.ArgumentParser) -> int:
    """Run the mooring with the motion and write its results."""
    from vinculo.mooring.analysis import _whole_steps, run
    from vinculo.mooring.moordyn_file import read_moordyn
    from vinculo.mooring.motion import read_motion

    model = read_moordyn(args.file)
    motion = read_motion(model, args.motion) if args.motion is not None else None
    if args.output_every is not None and _whole_steps(args.output_every, args.dt) is None:
        parser.error(f"--output-every {args.output_every:g}: give a whole number of steps "
                     f"of --dt {args.dt:g} s")
    folder = _output(args.output, parser)
    newton = {} if args.tolerance is None else {"tolerance": args.tolerance}
    result = run(model, motion, args.t_end, dt=args.dt, output_every=args.output_every,
                 output=folder, plots=not args.no_plots, progress=not args.no_progress,
                 start=args.start, **newton)
    tensions = result.end_tensions
    print(f"{args.file}: t = 0 to {result.times[-1]:g} s in {result.solution.steps_taken} steps "
          f"of {args.dt:g} s, {result.cpu_time:.3g} s CPU", flush=True)
    for k, row in enumerate(model.lines):
        print(f"line {row.id}: end B tension {tensions[:, k, 1].min():.6g} to "
              f"{tensions[:, k, 1].max():.6g} N, end A {tensions[:, k, 0].min():.6g} to "
              f"{tensions[:, k, 0].max():.6g} N", flush=True)
    if args.check_step:
        from vinculo.mooring.analysis import check_step

        check = check_step(result, start=args.start, **newton)
        print(check.summary(), flush=True)
    print(f"results: {', '.join(str(p) for p in result.files.values())}", file=sys.stdout,
          flush=True)
    return 0
