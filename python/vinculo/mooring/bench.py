"""The benchmark of vinculo's mooring lines against MoorDyn on the same input files.

Three cases, each with its fairlead surging harmonically (2 m, 10 s period, a one-period smooth
start) from the static equilibrium:

- ``chain``: a studless chain from an anchor on the seabed, part of it lying on the seabed;
- ``hanging``: a 100 m chain held at both ends in water, clear of the seabed;
- ``bending``: a power cable with bending stiffness hanging between two points.

For each case and number of segments, both codes run the same MoorDyn file:

- MoorDyn (explicit RK2), every run from one initial state (its own initial-condition solve,
  saved once: :func:`vinculo.mooring.peer.moordyn_initial_state`): the range of its stable
  steps (no blow-up) by bisection on ``dtM`` from the axial-wave estimate ``l / sqrt(EA / m)``
  of a segment of length ``l``, a reference run at an eighth of it, its largest stable step
  by bisection (tensions within 5 % of the reference), and a run at 0.9 of that step (made
  to divide 0.01 s: :func:`call_step`), whose end-tension error against the reference is
  MoorDyn's accuracy. These runs call MoorDyn's Step at every step, so that the fairlead
  follows the motion as closely as MoorDyn's coupling allows (a coupled point moves at a
  constant velocity through a step: here the chord of the motion over it). MoorDyn's CPU time
  is that of the same steps with a call every 0.01 s, without the Python call at each step;
- vinculo (implicit): a reference run at a small step, then the largest step of a list whose
  end-tension error against that reference is within MoorDyn's accuracy (or 0.1 % of the peak
  tension, whichever is larger): equal accuracy in end tension.

Each row reports the step, the CPU time of the time integration (``time.process_time``, the
initial equilibrium excluded; the least of :data:`REPEATS` runs; both codes storing their state
every :data:`OUTPUT_INTERVAL`, vinculo at every step where its step does not divide that
interval), the real-time factor (CPU time
over simulated time), the error against the code's own reference, and the difference in end
tension between the two codes after the first period of the motion (:data:`DIFFERENCE_FROM`).
The end tensions compared are those of each line's first and last segments: the force on an
end point also holds the loads the two codes lump differently on the end node (MoorDyn adds the
drag and added mass of the half segment at a moving fairlead).

Run it with ``python -m vinculo.mooring.bench [--segments 20,100] [--t-end 60]``; it writes
``bench.csv`` and ``bench.md`` (the README's table) into ``--output``. With ``--per-step DT``
it measures instead the CPU time of one step of each code (:func:`per_step`: MoorDyn's
explicit step against vinculo's implicit step of DT, or of MoorDyn's own step with
``--per-step moordyn``), and with ``--scaling DT`` vinculo's
real-time factor against the number of segments.
"""

from __future__ import annotations

import argparse
import csv
import dataclasses
import math
import sys
import tempfile
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from vinculo.errors import ConvergenceError
from vinculo.mooring.line import LineType
from vinculo.mooring.moordyn_file import (
    FileLine,
    FileOptions,
    FilePoint,
    MoorDynFile,
)
from vinculo.mooring.motion import Motion
from vinculo.mooring.peer import COUPLING_STEP, PeerError, PeerRun

if TYPE_CHECKING:
    from vinculo.mooring.analysis import MooringRun

__all__ = ["CASES", "BenchRow", "bench_case", "main", "motion_for", "table"]


def _options(depth: float, dtm: float) -> FileOptions:
    return FileOptions(depth=depth, time_step=dtm,
                       settings=(("writeLog", "0"), ("dtIC", "1.0"), ("TmaxIC", "100.0"),
                                 ("threshIC", "1.0e-5")))


def chain_on_seabed(segments: int = 63) -> MoorDynFile:
    """315 m of studless chain from an anchor on the seabed (50 m deep) to a fairlead 40 m
    above it and 300 m away: about 240 m lie on the seabed (tests/data/moordyn/
    chain_on_seabed.txt).

    Arguments:
        segments: the number of segments.

    Returns:
        The model.
    """
    chain = LineType("chain", 0.137, 126.0, 5.0e8, -1.0, 0.0, 2.4, 1.0, 1.15, 0.5)
    return MoorDynFile(
        line_types={"chain": chain},
        points=(FilePoint(1, "fixed", (-300.0, 0.0, -50.0)),
                FilePoint(2, "coupled", (0.0, 0.0, -10.0))),
        lines=(FileLine(1, "chain", 1, 2, 315.0, segments),),
        options=_options(50.0, 5e-4), title="benchmark: a chain resting on the seabed")


def hanging_line(segments: int = 20) -> MoorDynFile:
    """A 100 m chain held at both ends in water, 80 m apart at 20 m depth, clear of the seabed
    (tests/data/moordyn/hanging_line.txt).

    Arguments:
        segments: the number of segments.

    Returns:
        The model.
    """
    chain = LineType("chain", 0.05, 20.0, 1.0e8, -1.0, 0.0, 2.4, 1.0, 1.15, 0.5)
    return MoorDynFile(
        line_types={"chain": chain},
        points=(FilePoint(1, "fixed", (-40.0, 0.0, -20.0)),
                FilePoint(2, "coupled", (40.0, 0.0, -20.0))),
        lines=(FileLine(1, "chain", 1, 2, 100.0, segments),),
        options=_options(200.0, 2e-4), title="benchmark: a chain hanging between two points")


def bending_line(segments: int = 20) -> MoorDynFile:
    """A 30 m power cable with bending stiffness (EI = 2e4 N m^2) hanging between two points
    25 m apart (tests/data/moordyn/bending_line.txt).

    Arguments:
        segments: the number of segments.

    Returns:
        The model.
    """
    cable = LineType("cable", 0.15, 40.0, 5.0e8, -1.0, 2.0e4, 1.2, 1.0, 0.01, 0.0)
    return MoorDynFile(
        line_types={"cable": cable},
        points=(FilePoint(1, "fixed", (-12.5, 0.0, -30.0)),
                FilePoint(2, "coupled", (12.5, 0.0, -30.0))),
        lines=(FileLine(1, "cable", 1, 2, 30.0, segments),),
        options=_options(100.0, 1e-4), title="benchmark: a cable with bending stiffness")


#: The benchmark cases: name -> the model for a number of segments.
CASES: dict[str, Callable[[int], MoorDynFile]] = {
    "chain": chain_on_seabed,
    "hanging": hanging_line,
    "bending": bending_line,
}


def motion_for(model: MoorDynFile, amplitude: float = 2.0, period: float = 10.0) -> Motion:
    """The benchmark's fairlead motion: a surge along x with a one-period smooth start.

    Arguments:
        model: the case.
        amplitude: the surge amplitude (m).
        period: its period (s).

    Returns:
        The motion of the coupled points.
    """
    return Motion.harmonic([p.position for p in model.coupled_points()], (amplitude, 0.0, 0.0),
                           period=period, ramp_time=period)


def wave_step(model: MoorDynFile) -> float:
    """The time an axial wave takes to cross the shortest segment, ``l / sqrt(EA / m)`` (s), the
    scale of an explicit scheme's stable step.

    Arguments:
        model: the case.

    Returns:
        The smallest such time over the lines.
    """
    steps = []
    for line in model.lines:
        kind = model.line_types[line.line_type]
        length = line.unstretched_length / line.segments
        steps.append(length / math.sqrt(kind.ea / kind.mass_per_length))
    return min(steps)


@dataclass(frozen=True)
class BenchRow:
    """One code on one case at one number of segments.

    Arguments:
        case: the case's name.
        segments: the number of segments.
        code: ``"moordyn"`` or ``"vinculo"``.
        step: the time step used (s).
        cpu_time: the CPU time of the time integration (s).
        t_end: the simulated time (s).
        error: the largest end-tension difference from the code's own small-step reference,
            relative to the peak reference tension.
        difference: the largest end-tension difference from the other code's reference,
            relative to the peak tension (NaN when not computed).
        stable_step: MoorDyn's largest stable step (s; NaN for vinculo).
    """

    case: str
    segments: int
    code: str
    step: float
    cpu_time: float
    t_end: float
    error: float
    difference: float = math.nan
    stable_step: float = math.nan

    @property
    def real_time_factor(self) -> float:
        """CPU time over simulated time (below 1: faster than real time)."""
        return self.cpu_time / self.t_end


def _relative(a: np.ndarray, b: np.ndarray) -> float:
    if a.shape != b.shape:
        return math.inf
    scale = float(np.nanmax(np.abs(b)))
    return float(np.nanmax(np.abs(a - b)) / scale) if scale > 0 else math.inf


def _relative_by_end(a: np.ndarray, b: np.ndarray) -> tuple[float, float]:
    """:func:`_relative` of end-segment tensions ``(times, lines, 2)`` at ends A and B apart
    (the largest over the lines), both relative to the peak of ``b`` over both ends."""
    if a.shape != b.shape:
        return math.inf, math.inf
    scale = float(np.nanmax(np.abs(b)))
    if not scale > 0:
        return math.inf, math.inf
    ends = np.nanmax(np.abs(a - b), axis=(0, 1)) / scale
    return float(ends[0]), float(ends[1])


def _on(times: np.ndarray, values: np.ndarray, grid: np.ndarray) -> np.ndarray:
    """``values`` (times, ...) interpolated onto ``grid``."""
    flat = values.reshape(values.shape[0], -1)
    out = np.column_stack([np.interp(grid, times, flat[:, k]) for k in range(flat.shape[1])])
    return out.reshape((grid.size, *values.shape[1:]))


def call_step(step: float) -> float:
    """The step MoorDyn takes in the benchmark for the step ``step`` asked: the largest at most
    ``step`` that divides :data:`vinculo.mooring.peer.COUPLING_STEP` (0.01 s; ``step`` itself
    when longer), so that its timed runs, called every 0.01 s, take the very steps of its
    accuracy runs, called at every step. The step is smaller than asked by less than one part
    in the number of steps in 0.01 s (0.9 of MoorDyn's largest stable step on the chain on the
    seabed at 20 segments, 5.26 ms, becomes 5.0 ms; on the hanging chain at 100 segments,
    0.398 ms becomes 0.385 ms)."""
    if step >= COUPLING_STEP:
        return step
    return COUPLING_STEP / math.ceil(COUPLING_STEP / step - 1e-9)


@dataclass(frozen=True)
class MoorDynRun:
    """MoorDyn at one step on one case (:meth:`MoorDynSession.measure`).

    Arguments:
        step: the step MoorDyn took (s): the largest at most the one asked that divides
            0.01 s (:func:`call_step`).
        cpu_time: the least CPU time of :data:`REPEATS` timed runs (s).
        error: the largest end-tension difference from the reference, relative to the peak
            reference tension (the force on the end points, as the benchmark's table).
        segment_errors: the same of the end-segment tensions at ends A and B apart.
    """

    step: float
    cpu_time: float
    error: float
    segment_errors: tuple[float, float]


@dataclass(frozen=True)
class MoorDynSession:
    """MoorDyn set up on one case (:func:`moordyn_session`).

    Arguments:
        run: ``run(step, exact)``: a run from the saved initial state at the step
            (:func:`call_step`), MoorDyn called at each of its steps (``exact``, the fairlead
            following the motion as closely as MoorDyn's coupling allows) or every 0.01 s with
            the same steps (the timed runs: no Python call at each step).
        stable_step: MoorDyn's largest stable step (s).
        reference: the small-step reference run.
    """

    run: Callable[[float, bool], PeerRun]
    stable_step: float
    reference: PeerRun

    def measure(self, step: float) -> MoorDynRun:
        """MoorDyn's accuracy and CPU time at ``step`` (:func:`call_step`; the timed runs take
        the steps of the accuracy run, called every 0.01 s: a call at each step would count
        the call's own cost against MoorDyn's steps)."""
        exact = self.run(step, True)
        if exact.error is not None:
            raise PeerError(f"MoorDyn at {step:.3g} s steps: {exact.error}")
        timed = [self.run(step, False) for _ in range(REPEATS)]
        failed = [r.error for r in timed if r.error is not None]
        if failed:
            raise PeerError(f"MoorDyn's timed run at {step:.3g} s steps: {failed[0]}")
        return MoorDynRun(
            step=exact.time_step, cpu_time=min(r.cpu_time for r in timed),
            error=_relative(exact.end_tensions, self.reference.end_tensions),
            segment_errors=_relative_by_end(exact.segment_tensions,
                                            self.reference.segment_tensions))


@contextmanager
def moordyn_session(model: MoorDynFile, motion: Motion, t_end: float, dt_output: float,
                    reference_share: float = 1 / 8) -> Iterator[MoorDynSession]:
    """MoorDyn set up on one case: its initial state, its largest stable step and a reference.

    MoorDyn's initial condition is solved once (a dynamic relaxation at half the axial-wave
    step, minutes at 1,000 segments) and starts every run; the stable range is found without a
    reference (no blow-up), the reference is run at ``reference_share`` of it, and the largest
    stable step is the largest that keeps the end tensions within 5 % of the reference's.

    Arguments:
        model: the case.
        motion: the fairlead motion.
        t_end: the simulated time (s).
        dt_output: the output interval (s).
        reference_share: the reference's step as a share of the no-blow-up step.

    Yields:
        The session, valid inside the ``with`` block (the initial state lives in a temporary
        folder).
    """
    from vinculo.mooring.peer import largest_stable_step, moordyn_initial_state, run_moordyn

    estimate = wave_step(model)
    with tempfile.TemporaryDirectory(prefix="vinculo-bench-") as folder:
        state = moordyn_initial_state(model, motion, Path(folder) / "initial.state",
                                      time_step=estimate / 2)

        def moordyn(step: float, exact: bool) -> PeerRun:
            step = call_step(step)
            return run_moordyn(model, motion, t_end, dt_output=dt_output, time_step=step,
                               coupling_step=step if exact else max(step, COUPLING_STEP),
                               initial_state=state)

        rough, _ = largest_stable_step(model, motion, t_end, low=estimate / 2, high=estimate,
                                       ratio=1.5, dt_output=dt_output, initial_state=state)
        # The accuracy runs call MoorDyn at each of its steps, so that the fairlead follows the
        # motion as closely as MoorDyn's coupling allows: at the chord velocity through each
        # step (peer.run_moordyn: a call every 0.01 s moves it at one velocity through several
        # steps, whose jumps change the tensions by about 1 %).
        reference = moordyn(rough * reference_share, exact=True)
        stable, _ = largest_stable_step(model, motion, t_end, reference, low=rough / 2,
                                        high=rough * 1.5, dt_output=dt_output,
                                        exact_motion=True, initial_state=state)
        yield MoorDynSession(run=moordyn, stable_step=stable, reference=reference)


def bench_moordyn(model: MoorDynFile, motion: Motion, t_end: float,
                  dt_output: float | None = None) -> tuple[BenchRow, np.ndarray, np.ndarray]:
    """MoorDyn on one case: reference, largest stable step, timed run.

    Arguments:
        model: the case.
        motion: the fairlead motion.
        t_end: the simulated time (s).
        dt_output: the output interval (s; default :data:`OUTPUT_INTERVAL`).

    Returns:
        ``(row, times, reference end tensions)``.
    """
    dt_output = OUTPUT_INTERVAL if dt_output is None else dt_output
    with moordyn_session(model, motion, t_end, dt_output) as session:
        measured = session.measure(0.9 * session.stable_step)
        reference = session.reference
    row = BenchRow(case="", segments=model.lines[0].segments, code="moordyn",
                   step=measured.step, cpu_time=measured.cpu_time, t_end=t_end,
                   error=measured.error, stable_step=session.stable_step)
    return row, reference.times, reference.segment_tensions


#: The interval at which both codes store their state in a timed run (s): MoorDyn's output
#: interval ``dtOut`` and vinculo's output times. A state stored at every step cost vinculo a
#: fifth of its run on the chain on the seabed at 5 ms steps (100 segments: 0.096 against
#: 0.074 s for 20 s; the memory each new state fills is first touched then), where MoorDyn
#: writes one state every 0.1 s.
OUTPUT_INTERVAL = 0.1

#: The time from which the two codes' end tensions are compared (s): one period of the motion.
DIFFERENCE_FROM = 10.0

#: Each code's timed run is the best (least CPU) of this many runs: single runs of a few
#: milliseconds vary by a factor of two on a loaded machine.
REPEATS = 3

#: vinculo's steps tried, largest first (s). The smallest ones serve the chain on the seabed,
#: whose touchdown impacts both codes must resolve.
STEPS = (0.5, 0.3, 0.2, 0.15, 0.1, 0.07, 0.05, 0.03, 0.02, 0.01, 0.007, 0.005, 0.003, 0.002)


def vinculo_run(model: MoorDynFile, motion: Motion, t_end: float, dt: float,
                every: float | None = None) -> MooringRun:
    """A timed run of vinculo on one case: steps of ``dt``, the state stored every ``every``.

    Arguments:
        model: the case.
        motion: the fairlead motion.
        t_end: the simulated time (s).
        dt: the step (s).
        every: the output interval (s). Default: :data:`OUTPUT_INTERVAL`, as MoorDyn's, where
            that is a whole number of steps, else every step (a state between step ends would
            be interpolated, and a segment's tension from interpolated positions is less
            accurate than the tensions at the steps' ends interpolated onto the comparison
            grid).

    Returns:
        The run (its ``cpu_time`` is that of the time integration).
    """
    from vinculo.mooring.analysis import _output_grid, _whole_steps, run

    if every is None:
        grid = _output_grid(t_end, dt, _whole_steps(OUTPUT_INTERVAL, dt) or 1)
    else:
        steps = _whole_steps(every, dt)
        grid = _output_grid(t_end, dt, steps) if steps else _output_grid(t_end, every)
    return run(model, motion, t_end, dt=dt, plots=False, t_eval=grid)


def vinculo_tensions(model: MoorDynFile, motion: Motion, t_end: float, dt: float,
                     grid: np.ndarray, repeats: int = 1) -> tuple[np.ndarray, float]:
    """vinculo's end-segment tensions on one case at the step ``dt``, interpolated onto
    ``grid``, and the least CPU time of ``repeats`` runs (s).

    Raises:
        ConvergenceError: when the step is too large for Newton to converge.
    """
    result = vinculo_run(model, motion, t_end, dt)
    cpu = min([result.cpu_time] + [vinculo_run(model, motion, t_end, dt).cpu_time
                                   for _ in range(repeats - 1)])
    return _on(result.times, result.segment_tensions, grid), cpu


def bench_vinculo(model: MoorDynFile, motion: Motion, t_end: float, target: float,
                  grid: np.ndarray, steps: Sequence[float] = STEPS,
                  ) -> tuple[BenchRow, np.ndarray]:
    """vinculo on one case: a small-step reference, then the largest step within ``target``.

    Arguments:
        model: the case.
        motion: the fairlead motion.
        t_end: the simulated time (s).
        target: the accuracy to meet (relative end-tension error).
        grid: the output times to compare on (s).
        steps: the steps to try, largest first (s).

    Returns:
        ``(row, end-segment tensions on the grid at the chosen step)``.
    """
    def tensions(dt: float, repeats: int = 1) -> tuple[np.ndarray, float]:
        return vinculo_tensions(model, motion, t_end, dt, grid, repeats)

    reference, _ = tensions(min(steps) / 4)
    chosen = None
    for dt in sorted(steps, reverse=True):
        try:
            values, cpu = tensions(dt)
        except ConvergenceError:
            continue  # a step too large to converge (stops with an error): a smaller one
        error = _relative(values, reference)
        if error <= target:
            chosen = (dt, cpu, error, values)
            break
    if chosen is None:
        dt = min(steps)
        values, cpu = tensions(dt)
        chosen = (dt, cpu, _relative(values, reference), values)
    dt, cpu, error, values = chosen
    cpu = min(cpu, tensions(dt, REPEATS - 1)[1]) if REPEATS > 1 else cpu
    row = BenchRow(case="", segments=model.lines[0].segments, code="vinculo", step=dt,
                   cpu_time=cpu, t_end=t_end, error=error)
    return row, values


def bench_case(name: str, segments: int, t_end: float, *, with_vinculo: bool = True,
               tolerance: float = 1e-3) -> list[BenchRow]:
    """Both codes on one case at one number of segments.

    Arguments:
        name: a key of :data:`CASES`.
        segments: the number of segments.
        t_end: the simulated time (s).
        with_vinculo: also run vinculo (False: MoorDyn alone).
        tolerance: the smallest accuracy target of vinculo (relative end-tension error).

    Returns:
        The MoorDyn row, then the vinculo row.
    """
    model = CASES[name](segments)
    motion = motion_for(model)
    md, grid, md_reference = bench_moordyn(model, motion, t_end)
    rows = [dataclasses.replace(md, case=name)]
    if with_vinculo:
        vc, values = bench_vinculo(model, motion, t_end, max(md.error, tolerance), grid)
        # After the first period: MoorDyn's initial condition of a chain lying on the seabed
        # is not settled at t = 0 (its dynamic relaxation stops at TmaxIC; 2.9 % of the peak
        # tension from vinculo's equilibrium at 100 segments, which the two runs share again
        # from about t = 5 s on).
        later = grid >= min(DIFFERENCE_FROM, 0.5 * t_end)
        difference = _relative(values[later], md_reference[later])
        rows[0] = dataclasses.replace(rows[0], difference=difference)
        rows.append(dataclasses.replace(vc, case=name, difference=difference))
    return rows


def scaling(name: str, segments: Sequence[int], dt: float,
            t_end: float) -> list[tuple[int, float]]:
    """vinculo's real-time factor (CPU time over simulated time) on one case against the number
    of segments, at one step.

    Arguments:
        name: a key of :data:`CASES`.
        segments: the numbers of segments.
        dt: the step (s).
        t_end: the simulated time (s).

    Returns:
        ``(segments, real-time factor)`` pairs.
    """
    rows = []
    for n in segments:
        model = CASES[name](n)
        result = vinculo_run(model, motion_for(model), t_end, dt)
        rows.append((n, result.cpu_time / t_end))
    return rows


def table(rows: Sequence[BenchRow]) -> str:
    """The benchmark as a Markdown table, one line per case and number of segments.

    Arguments:
        rows: the rows of :func:`bench_case`.

    Returns:
        The table.
    """
    lines = [
        "| case | segments | MoorDyn step (largest stable) | MoorDyn CPU (s) | vinculo step | "
        "vinculo CPU (s) | CPU ratio | vinculo real-time factor | error MoorDyn / vinculo | "
        "difference |",
        "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |",
    ]
    groups: dict[tuple[str, int], dict[str, BenchRow]] = {}
    for row in rows:
        groups.setdefault((row.case, row.segments), {})[row.code] = row
    for (case, segments), by_code in groups.items():
        md, vc = by_code.get("moordyn"), by_code.get("vinculo")
        cells = [case, str(segments)]
        cells += [f"{md.step:.3g} s ({md.stable_step:.3g})", f"{md.cpu_time:.3g}"] if md \
            else ["", ""]
        cells += [f"{vc.step:.3g} s", f"{vc.cpu_time:.3g}"] if vc else ["", ""]
        cells.append(f"{md.cpu_time / vc.cpu_time:.3g}x" if md and vc and vc.cpu_time > 0
                     else "")
        cells.append(f"{vc.real_time_factor:.3g}" if vc else "")
        cells.append(f"{md.error:.1e} / {vc.error:.1e}" if md and vc else
                     (f"{md.error:.1e} / -" if md else ""))
        diff = (vc or md).difference if (vc or md) else math.nan
        cells.append(f"{diff:.1e}" if math.isfinite(diff) else "")
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def write_rows(rows: Sequence[BenchRow], path: str | Path) -> Path:
    """Write the rows as CSV.

    Arguments:
        rows: the rows.
        path: the CSV file.

    Returns:
        The path written.
    """
    names = [f.name for f in dataclasses.fields(BenchRow)] + ["real_time_factor"]
    return write_csv(rows, names, path)


def write_csv(rows: Sequence[object], names: Sequence[str], path: str | Path) -> Path:
    """Write ``rows`` as CSV, a column per attribute in ``names`` (the header).

    Arguments:
        rows: the rows (dataclass instances).
        names: the attributes to write, in order.
        path: the CSV file.

    Returns:
        The path written.
    """
    path = Path(path)
    with path.open("w", newline="", encoding="utf-8") as handle:
        writer = csv.writer(handle)
        writer.writerow(names)
        for row in rows:
            writer.writerow([getattr(row, n) for n in names])
    return path


def per_step(name: str, segments: int, dt: float | None, t_end: float
             ) -> tuple[float, float, float, float]:
    """The CPU time of one step of each code on one case: MoorDyn's at half its axial-wave step
    (:func:`wave_step`, within its stable range: an explicit step costs the same whatever its
    size), vinculo's at the step ``dt`` (its Newton iterations, and so its step's cost, depend
    on the step), or at MoorDyn's step; both storing their state every
    :data:`OUTPUT_INTERVAL`; the least of :data:`REPEATS` runs each, from MoorDyn's initial
    state.

    Arguments:
        name: a key of :data:`CASES`.
        segments: the number of segments.
        dt: vinculo's step (s; None: MoorDyn's).
        t_end: the simulated time (s).

    Returns:
        ``(MoorDyn's step (s), MoorDyn's CPU time a step (s), vinculo's step (s), vinculo's CPU
        time a step (s))``.
    """
    from vinculo.mooring.peer import moordyn_initial_state, run_moordyn

    model = CASES[name](segments)
    motion = motion_for(model)
    step = wave_step(model) / 2
    with tempfile.TemporaryDirectory(prefix="vinculo-bench-") as folder:
        state = moordyn_initial_state(model, motion, Path(folder) / "initial.state",
                                      time_step=step)
        # Called every 0.01 s with whole steps, as the benchmark's timed runs (call_step); the
        # time a step is that of the steps MoorDyn took.
        step = call_step(step)
        timed = [run_moordyn(model, motion, t_end, dt_output=OUTPUT_INTERVAL, time_step=step,
                             coupling_step=max(step, COUPLING_STEP), initial_state=state)
                 for _ in range(REPEATS)]
    step = timed[0].time_step
    moordyn = min(r.cpu_time / r.steps for r in timed)
    dt = step if dt is None else dt
    runs = [vinculo_run(model, motion, t_end, dt, every=OUTPUT_INTERVAL) for _ in range(REPEATS)]
    vinculo = min(r.cpu_time / r.solution.steps_taken for r in runs)
    return step, moordyn, dt, vinculo


def main(argv: Sequence[str] | None = None) -> int:
    """Run the benchmark from the command line (``python -m vinculo.mooring.bench``).

    Arguments:
        argv: the arguments (default: ``sys.argv[1:]``).

    Returns:
        The exit code (0).
    """
    parser = argparse.ArgumentParser(prog="python -m vinculo.mooring.bench",
                                     description=__doc__.split("\n\n")[0])
    parser.add_argument("--cases", default=",".join(CASES),
                        help=f"comma-separated cases from {', '.join(CASES)}")
    parser.add_argument("--segments", default="20,100",
                        help="comma-separated numbers of segments (default 20,100)")
    parser.add_argument("--t-end", type=float, default=60.0, help="simulated time (s)")
    parser.add_argument("--moordyn-only", action="store_true",
                        help="run MoorDyn alone (no vinculo rows)")
    parser.add_argument("--scaling", type=float, metavar="DT", default=None,
                        help="instead: vinculo's real-time factor against the number of segments "
                        "at the step DT (s), on each case")
    parser.add_argument("--per-step", metavar="DT", default=None,
                        help="instead: the CPU time of one step of each code on each case, "
                        "vinculo's at the step DT (s), or at MoorDyn's step with "
                        "'--per-step moordyn'")
    parser.add_argument("--work-precision", action="store_true",
                        help="instead: CPU time against end-tension error of both codes over "
                        "a range of steps on each case (vinculo.mooring.work_precision)")
    parser.add_argument("--output", "-o", type=Path, default=Path("output") / "mooring-bench")
    args = parser.parse_args(argv)
    per_step_dt = None
    if args.per_step not in (None, "moordyn"):
        try:
            per_step_dt = float(args.per_step)
        except ValueError:
            parser.error(f"--per-step {args.per_step!r}: give a step in s or 'moordyn'")
        if not (math.isfinite(per_step_dt) and per_step_dt > 0.0):
            parser.error(f"--per-step {args.per_step!r}: give a step > 0 s or 'moordyn'")
    args.output.mkdir(parents=True, exist_ok=True)
    segment_list = [int(s) for s in args.segments.split(",") if s.strip()]
    cases = [c.strip() for c in args.cases.split(",") if c.strip()]
    unknown = [c for c in cases if c not in CASES]
    if unknown:
        parser.error(f"--cases: {', '.join(map(repr, unknown))} not among {', '.join(CASES)}")
    if args.scaling is not None:
        print("| case | segments | step (s) | vinculo real-time factor |\n"
              "| --- | ---: | ---: | ---: |")
        for name in cases:
            for n, factor in scaling(name, segment_list, args.scaling, args.t_end):
                print(f"| {name} | {n} | {args.scaling:g} | {factor:.3g} |", flush=True)
        return 0
    if args.work_precision:
        return _work_precision_main(cases, segment_list, args.t_end, args.output)
    if args.per_step is not None:
        print("| case | segments | MoorDyn step (s) | MoorDyn (us a step) | vinculo step (s) | "
              "vinculo (us a step) | vinculo / MoorDyn |\n"
              "| --- | ---: | ---: | ---: | ---: | ---: | ---: |")
        for name in cases:
            for n in segment_list:
                step, moordyn, dt, vinculo = per_step(name, n, per_step_dt, args.t_end)
                print(f"| {name} | {n} | {step:.3g} | {1e6 * moordyn:.1f} | {dt:.3g} | "
                      f"{1e6 * vinculo:.1f} | {vinculo / moordyn:.2f} |", flush=True)
        return 0
    rows: list[BenchRow] = []
    for name in cases:
        for segments in segment_list:
            new = bench_case(name, segments, args.t_end, with_vinculo=not args.moordyn_only)
            rows += new
            for row in new:
                print(f"{row.case:8s} N={row.segments:<5d} {row.code:8s} step {row.step:.3g} s "
                      f"CPU {row.cpu_time:.3g} s (x{row.real_time_factor:.3g} real time) "
                      f"error {row.error:.1e} difference {row.difference:.1e}", flush=True)
    write_rows(rows, args.output / "bench.csv")
    (args.output / "bench.md").write_text(table(rows) + "\n", encoding="utf-8")
    print(table(rows))
    return 0


def _work_precision_main(cases: Sequence[str], segments: Sequence[int], t_end: float,
                         output: Path) -> int:
    """``--work-precision``: the points, case by case, then the table, CSV and plot."""
    from vinculo.mooring import work_precision as wp

    points: list[wp.WorkPoint] = []
    for name in cases:
        for n in segments:
            new = wp.work_precision(name, n, t_end)
            points += new
            for p in new:
                print(f"{p.case:8s} N={p.segments:<5d} {p.code:8s} step {p.step:.3g} s "
                      f"CPU {p.cpu_time:.3g} s error {p.error:.1e} (anchor {p.error_end_a:.1e}, "
                      f"fairlead {p.error_end_b:.1e})", flush=True)
            # Written after each case, so that an interrupted run keeps the cases done.
            wp.write_points(points, output / "work-precision.csv")
    (output / "work-precision.md").write_text(wp.table(points) + "\n", encoding="utf-8")
    image = wp.plot(points, output / "work-precision.png")
    print(wp.table(points))
    print(f"wrote {output / 'work-precision.csv'}, {output / 'work-precision.md'}, {image}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
