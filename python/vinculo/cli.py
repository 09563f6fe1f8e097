"""The ``vinculo`` command line.

Usage::

    vinculo demo [--output DIR]

``demo`` runs the four demo models (pendulum, double pendulum, hanging chain, inclined plane),
prints one line per model comparing the simulation with its reference value, and writes one PNG
plot per model into DIR (default ``output``).

Exit codes: 0 on success, 1 when a simulation fails, 2 on bad arguments.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from vinculo import __version__, demos
from vinculo.errors import VinculoError

__all__ = ["main"]


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
    return parser


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


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line.

    Arguments:
        argv: the arguments (default: ``sys.argv[1:]``).

    Returns:
        The exit code: 0 on success, 1 if a simulation failed.

    Raises:
        SystemExit: with code 2 on bad arguments (from argparse), or 0 after ``--help``.
    """
    parser = _build_parser()
    args = parser.parse_args(argv)
    try:
        return int(args.handler(args, parser))
    except VinculoError as exc:
        print(f"vinculo: error: {exc}", file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
