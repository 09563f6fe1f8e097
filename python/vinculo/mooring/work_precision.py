"""Work against precision: CPU time against end-tension error, vinculo and MoorDyn side by side
on the mooring benchmark's cases (:mod:`vinculo.mooring.bench`).

The benchmark's table compares each code at one setting: MoorDyn at 0.9 of its largest stable
step, vinculo at the largest step of a list that is as accurate. This diagram shows the whole
curve of each code, so that "at equal accuracy" can be read at any accuracy:

- MoorDyn (explicit RK2) at 0.9 of its largest stable step and at halves of it
  (:data:`MOORDYN_HALVINGS`): a larger step blows up, so its curve ends there, however loose
  the accuracy a user needs. Its error is against its own run at 1/32 of the step where it
  stops blowing up (:data:`MOORDYN_REFERENCE_SHARE`, finer than the table's 1/8: the error of
  the smallest point here must stand clear of the reference's own);
- vinculo (implicit trapezoidal rule) at every step of :data:`vinculo.mooring.bench.STEPS` that
  converges, its error against its own run at a quarter of the smallest.

Errors are the largest end-segment tension difference from the code's own reference, relative
to the peak reference tension, also at each end apart (the anchor, end A, and the moving
fairlead, end B); CPU time is that of the time integration, the
least of :data:`vinculo.mooring.bench.REPEATS` runs, both codes storing their state every
:data:`vinculo.mooring.bench.OUTPUT_INTERVAL` and starting from the same initial state as in
the table.

At each of MoorDyn's points, vinculo's cost at equal accuracy is that of its cheapest point at
least as accurate (no interpolation between vinculo's steps: the ratio is never flattering).

``python -m vinculo.mooring.bench --work-precision [--cases chain,hanging,bending]
[--segments 20,100]`` writes ``work-precision.csv``, ``work-precision.md`` and
``work-precision.png`` into ``--output``.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from vinculo.errors import ConvergenceError, InvalidInputError
from vinculo.mooring.bench import (
    CASES,
    OUTPUT_INTERVAL,
    REPEATS,
    STEPS,
    _relative_by_end,
    moordyn_session,
    motion_for,
    vinculo_tensions,
    write_csv,
)

__all__ = ["MOORDYN_HALVINGS", "MOORDYN_REFERENCE_SHARE", "EqualAccuracy", "WorkPoint",
           "equal_accuracy", "pareto_front", "plot", "table", "work_precision", "write_points"]

#: MoorDyn's points: 0.9 of its largest stable step, then this many halvings of it.
MOORDYN_HALVINGS = 2

#: MoorDyn's reference step as a share of the step where it stops blowing up: at 1/32 its own
#: error is a sixteenth of that of the smallest point (0.9/4 of the largest stable step), whose
#: error would otherwise be half the reference's.
MOORDYN_REFERENCE_SHARE = 1 / 32


@dataclass(frozen=True)
class WorkPoint:
    """One code at one step on one case.

    Arguments:
        case: the case's name (a key of :data:`vinculo.mooring.bench.CASES`).
        segments: the number of segments.
        code: ``"moordyn"`` or ``"vinculo"``.
        step: the time step (s).
        cpu_time: the CPU time of the time integration (s).
        error: the largest end-segment tension difference from the code's own reference,
            relative to the peak reference tension (the larger of the two ends').
        error_end_a: that difference at the lines' ends A alone (the anchor of every case).
        error_end_b: at the lines' ends B alone (the moving fairlead).
        largest_stable: whether this is MoorDyn at 0.9 of its largest stable step (the end of
            its curve).
    """

    case: str
    segments: int
    code: str
    step: float
    cpu_time: float
    error: float
    error_end_a: float
    error_end_b: float
    largest_stable: bool = False


def work_precision(name: str, segments: int, t_end: float, *,
                   halvings: int = MOORDYN_HALVINGS,
                   steps: Sequence[float] = STEPS) -> list[WorkPoint]:
    """Both codes' points on one case at one number of segments.

    Arguments:
        name: a key of :data:`vinculo.mooring.bench.CASES`.
        segments: the number of segments.
        t_end: the simulated time (s).
        halvings: how many times MoorDyn's largest step is halved.
        steps: vinculo's steps (s); those at which Newton does not converge are left out.

    Returns:
        MoorDyn's points, largest step first, then vinculo's.

    Raises:
        InvalidInputError: for an unknown case or fewer than one segment.
        PeerError: when MoorDyn is not installed, or blows up at one of its points.
    """
    if name not in CASES:
        raise InvalidInputError(f"case {name!r}: not one of {', '.join(CASES)}", name="name",
                                value=name)
    if segments < 1:
        raise InvalidInputError(f"segments {segments}: give a number of segments >= 1",
                                name="segments", value=segments)
    model = CASES[name](segments)
    motion = motion_for(model)
    points = []
    with moordyn_session(model, motion, t_end, OUTPUT_INTERVAL,
                         reference_share=MOORDYN_REFERENCE_SHARE) as session:
        grid = session.reference.times
        for k in range(halvings + 1):
            measured = session.measure(0.9 * session.stable_step / 2**k)
            a, b = measured.segment_errors
            points.append(WorkPoint(name, segments, "moordyn", measured.step,
                                    measured.cpu_time, max(a, b), a, b,
                                    largest_stable=k == 0))
    # On MoorDyn's output times.
    reference, _ = vinculo_tensions(model, motion, t_end, min(steps) / 4, grid)
    for dt in sorted(steps, reverse=True):
        try:
            values, cpu = vinculo_tensions(model, motion, t_end, dt, grid,
                                           repeats=REPEATS)
        except ConvergenceError:
            continue
        a, b = _relative_by_end(values, reference)
        points.append(WorkPoint(name, segments, "vinculo", dt, cpu, max(a, b), a, b))
    return points


@dataclass(frozen=True)
class EqualAccuracy:
    """vinculo's cheapest point at least as accurate as one of MoorDyn's.

    Arguments:
        moordyn: MoorDyn's point.
        vinculo: vinculo's point (None: none of its steps was as accurate).
    """

    moordyn: WorkPoint
    vinculo: WorkPoint | None

    @property
    def ratio(self) -> float:
        """MoorDyn's CPU time over vinculo's (NaN without a vinculo point)."""
        if self.vinculo is None or self.vinculo.cpu_time <= 0.0:
            return math.nan
        return self.moordyn.cpu_time / self.vinculo.cpu_time


def equal_accuracy(points: Sequence[WorkPoint]) -> list[EqualAccuracy]:
    """For each of MoorDyn's points, vinculo's cheapest point on the same case and number of
    segments whose error is at most MoorDyn's.

    Arguments:
        points: the points of :func:`work_precision`.

    Returns:
        One entry per MoorDyn point, in the order given.
    """
    out = []
    for md in (p for p in points if p.code == "moordyn"):
        candidates = [p for p in points if p.code == "vinculo" and p.case == md.case
                      and p.segments == md.segments and p.error <= md.error]
        best = min(candidates, key=lambda p: p.cpu_time) if candidates else None
        out.append(EqualAccuracy(md, best))
    return out


def table(points: Sequence[WorkPoint]) -> str:
    """The equal-accuracy comparison at each of MoorDyn's points, as a Markdown table.

    Arguments:
        points: the points of :func:`work_precision`.

    Returns:
        The table.
    """
    lines = ["| case | segments | MoorDyn step (s) | MoorDyn error (anchor / fairlead) | "
             "MoorDyn CPU (s) | vinculo step (s) | vinculo error (anchor / fairlead) | "
             "vinculo CPU (s) | CPU ratio |",
             "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |"]

    def error(p: WorkPoint) -> str:
        return f"{p.error:.1e} ({p.error_end_a:.1e} / {p.error_end_b:.1e})"

    for match in equal_accuracy(points):
        md, vc = match.moordyn, match.vinculo
        step = f"{md.step:.3g}" + (" (largest)" if md.largest_stable else "")
        cells = [md.case, str(md.segments), step, error(md), f"{md.cpu_time:.3g}"]
        cells += ([f"{vc.step:.3g}", error(vc), f"{vc.cpu_time:.3g}",
                   f"{match.ratio:.3g}x"] if vc else ["none as accurate", "", "", ""])
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def write_points(points: Sequence[WorkPoint], path: str | Path) -> Path:
    """Write the points as CSV (one row a point, the fields of :class:`WorkPoint`).

    Arguments:
        points: the points.
        path: the CSV file.

    Returns:
        The path written.
    """
    return write_csv(points, [f.name for f in dataclasses.fields(WorkPoint)], path)


def pareto_front(points: Sequence[WorkPoint]) -> list[WorkPoint]:
    """The points no other point beats in both CPU time and error, most accurate first: a
    code's best cost at each accuracy.

    Arguments:
        points: one code's points on one case.

    Returns:
        The front, by increasing error (and decreasing CPU time).
    """
    front: list[WorkPoint] = []
    for p in sorted(points, key=lambda p: (p.cpu_time, p.error)):
        if not front or p.error < front[-1].error:
            front.append(p)
    return sorted(front, key=lambda p: p.error)


def plot(points: Sequence[WorkPoint], path: str | Path) -> Path:
    """CPU time against error, one panel per case and number of segments, both codes: each
    code's front (:func:`pareto_front`) as a line, its other points faint.

    Arguments:
        points: the points of :func:`work_precision`.
        path: the image file.

    Returns:
        The path written.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    panels = list(dict.fromkeys((p.case, p.segments) for p in points))
    columns = min(3, len(panels))
    rows = math.ceil(len(panels) / columns)
    fig, axes = plt.subplots(rows, columns, figsize=(4.6 * columns, 3.9 * rows), squeeze=False)
    for ax, (case, segments) in zip(axes.flat, panels, strict=False):
        for code, colour, marker in (("moordyn", "tab:orange", "s"), ("vinculo", "tab:blue", "o")):
            own = [p for p in points if (p.case, p.segments, p.code) == (case, segments, code)]
            if not own:
                continue
            front = pareto_front(own)
            label = "MoorDyn (RK2)" if code == "moordyn" else "vinculo (trapezoidal)"
            ax.loglog([p.error for p in front], [p.cpu_time for p in front], marker=marker,
                      color=colour, label=label)
            rest = [p for p in own if p not in front]
            ax.loglog([p.error for p in rest], [p.cpu_time for p in rest], linestyle="none",
                      marker=marker, color=colour, alpha=0.3)
            for p in front:
                text = f"{p.step:.2g} s" + (" (largest stable)" if p.largest_stable else "")
                ax.annotate(text, (p.error, p.cpu_time), textcoords="offset points",
                            xytext=(5, -9 if code == "moordyn" else 3), fontsize=7,
                            color=colour)
        ax.set_title(f"{case}, {segments} segments", fontsize=10)
        ax.set_xlabel("end-tension error (relative to the peak)")
        ax.set_ylabel("CPU time of the run (s)")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8, loc="lower left")
    for ax in list(axes.flat)[len(panels):]:
        ax.set_visible(False)
    fig.suptitle("Work against precision: each code's error against its own small-step "
                 "reference", fontsize=11)
    fig.tight_layout()
    path = Path(path)
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path
