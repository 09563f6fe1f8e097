"""``python -m vinculo.bench python-overhead``: what calling the core from Python costs.

The same run (the 1 m, 1 kg pendulum released horizontally, 1,000 steps of 1 ms, each scheme
at its defaults) timed twice in one process: through :func:`vinculo.simulate` (argument
checks, the run, the solution converted to numpy arrays and wrapped), and in Rust alone
(``vinculo._core.time_simulate``: the core's ``simulate`` on the same model and settings,
timed inside Rust). Each time is the least wall-clock time of ``--repeat`` runs, the two kinds
alternating; the overhead is their ratio minus one.
"""

from __future__ import annotations

import argparse
import sys
import time
from dataclasses import dataclass

import vinculo
from vinculo import _core
from vinculo.run_options import RunOptions

#: The schemes timed, by label: keyword arguments of :func:`vinculo.simulate`.
SCHEMES = {
    "trapezoidal": {},
    "generalized-alpha": {"scheme": "generalized-alpha", "rho_inf": 0.9},
    "trapezoidal, modified Newton": {"jacobian_reuse": True},
}


@dataclass(frozen=True)
class Overhead:
    """One scheme's two timings.

    Arguments:
        label: the scheme's label.
        steps: the number of steps of the run.
        python: the least time of one run through :func:`vinculo.simulate` (s).
        rust: the least time of one run of the core alone (s).
    """

    label: str
    steps: int
    python: float
    rust: float

    @property
    def overhead(self) -> float:
        """``python / rust - 1``: the share of time added by the Python layer."""
        return self.python / self.rust - 1.0


def pendulum() -> vinculo.System:
    """The 1 m, 1 kg pendulum, released horizontally from rest."""
    system = vinculo.System(gravity=(0.0, 0.0, -9.81))
    pivot = system.add_particle(mass=1.0, position=(0.0, 0.0, 0.0), fixed=True)
    bob = system.add_particle(mass=1.0, position=(1.0, 0.0, 0.0))
    system.add_distance(pivot, bob, length=1.0)
    return system


def measure(steps: int = 1000, dt: float = 1e-3, repeat: int = 200) -> list[Overhead]:
    """Both timings of each scheme of :data:`SCHEMES`.

    Arguments:
        steps: the number of steps of a run.
        dt: the step (s).
        repeat: the runs of each timing (the least time is kept).

    Returns:
        One :class:`Overhead` per scheme.
    """
    system = pendulum()
    t_end = steps * dt
    rows = []
    for label, options in SCHEMES.items():
        settings = RunOptions.of("simulate", dict(options)).settings(t_end, dt, None)
        python = rust = float("inf")
        # The two timings alternate, so that a change of the machine's load meets both.
        for _ in range(repeat):
            start = time.perf_counter()
            solution = vinculo.simulate(system, t_end, dt, **options)
            python = min(python, time.perf_counter() - start)
            rust = min(rust, _core.time_simulate(system, settings, 1))
        assert solution.steps_taken == steps, solution.steps_taken
        rows.append(Overhead(label=label, steps=steps, python=python, rust=rust))
    return rows


def table(rows: list[Overhead]) -> str:
    """The Markdown table of the README.

    Arguments:
        rows: the measurements.

    Returns:
        The table.
    """
    lines = ["| scheme | steps | vinculo.simulate (ms) | core alone (ms) | overhead |",
             "| --- | ---: | ---: | ---: | ---: |"]
    for r in rows:
        lines.append(f"| {r.label} | {r.steps:,} | {1e3 * r.python:.3f} | {1e3 * r.rust:.3f} | "
                     f"{100 * r.overhead:+.1f} % |")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    """Command line entry point."""
    parser = argparse.ArgumentParser(prog="python -m vinculo.bench python-overhead",
                                     description=__doc__.split("\n\n")[0])
    parser.add_argument("--steps", type=int, default=1000, help="steps of a run (default 1000)")
    parser.add_argument("--repeat", type=int, default=200,
                        help="runs of each timing, the least time kept (default 200)")
    args = parser.parse_args(argv)
    print(table(measure(steps=args.steps, repeat=args.repeat)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
