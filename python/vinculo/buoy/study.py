"""The frequency sweep of the buoy study: every model at every frequency, in parallel processes.

Each (model, frequency) pair is one task: simulate from rest for ``SweepSettings.t_end(f)``, then
fit the steady-state amplitude and phase over the last ``fit_periods`` whole periods
(:func:`vinculo.buoy.harmonic.steady_response`), and check that the steady state is reached: the
fit over the window before must agree within the settings' tolerances, else the run is repeated
longer (up to ``max_periods``) or reported as not converged. Tasks run in worker processes (the
particle model releases the GIL, the scipy reference models do not, so processes serve both); a
task that fails is recorded with its error and the others go on.

After the sweep, each model's resonance is refined by rounds of fresh runs near its peak
(:mod:`vinculo.buoy.resonance`); those runs join the model's curve.

Time histories are kept at the history frequencies: the paper's 0.8, 0.9 and 1.1 Hz (figs.
11-13) when they lie within the sweep's range (added to it when they are not on its grid), or
the frequencies the caller asks for; :attr:`StudyResult.notes` says which were run and why.

Driven by measured tank records instead (``run_study(..., motions=[...])``, ``vinculo buoy
--tank-motion FILE.csv``), each record is one excitation: every model runs over the whole record
and is fitted over its last ``fit_periods`` periods at the record's frequency.
"""

from __future__ import annotations

import contextlib
import math
import os
import sys
import time
from collections.abc import Callable, Sequence
from concurrent.futures import Executor, as_completed
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass, field, replace
from typing import IO, Any

import numpy as np

from vinculo.buoy.case import BuoyCase, SweepSettings
from vinculo.buoy.executors import open_executor
from vinculo.buoy.harmonic import SteadyResponse, steady_response
from vinculo.buoy.model import run_particle_model
from vinculo.buoy.reference import OneDofModel, TwoDofModel
from vinculo.buoy.resonance import Resonance, bracket, parabola_vertex, round_frequencies
from vinculo.buoy.tank import MeasuredTankMotion
from vinculo.errors import InvalidInputError, VinculoError

__all__ = [
    "HISTORY_FREQUENCIES",
    "MODELS",
    "ModelResult",
    "StudyResult",
    "refine_resonances",
    "run_study",
    "run_task",
]

#: The models of the study, by name: the particle model and the two scipy references.
MODELS = ("particle", "two-dof", "one-dof")
#: Labels for plots and tables.
LABELS = {
    "particle": "particle model (vinculo)",
    "two-dof": "2-DOF string + sphere (scipy)",
    "one-dof": "1-DOF rigid pendulum, eq. 31 corrected (scipy)",
    "measured": "measurements",
}
#: Frequencies whose time histories the paper shows (its figs. 11-13): kept by default when they
#: lie within the sweep's range.
HISTORY_FREQUENCIES = (0.8, 0.9, 1.1)
#: Each round of the resonance's refinement spaces its runs this many times closer than the
#: spacing before (the sweep's grid for the first round).
REFINEMENT_FACTOR = 10.0
#: What a run is for, in :attr:`ModelResult.kind` and ``sweep.csv``.
KINDS = ("sweep", "history", "refinement")


@dataclass
class ModelResult:
    """One model at one frequency.

    Attributes:
        model: one of :data:`MODELS`.
        frequency: excitation frequency (Hz).
        response: the steady-state fit, or None when the run failed.
        error: None, or ``"ErrorClass: message"`` of the failure.
        history: time histories (``time``, ``tank``, ``buoy``, ``relative``, ``tension``) when
            kept, else None. A failed run keeps what it computed.
        elapsed: wall time of the task (s).
        record: the measured tank record that drove the run (its file name), or None for the
            harmonic excitation.
        kind: why the run was made, one of :data:`KINDS`: a frequency of the sweep, a history
            frequency off the sweep's grid, or a run of the resonance's refinement.
    """

    model: str
    frequency: float
    response: SteadyResponse | None
    error: str | None = None
    history: dict[str, np.ndarray] | None = None
    elapsed: float = 0.0
    record: str | None = None
    kind: str = "sweep"


def _check_model(model: str, name: str) -> None:
    """Raise InvalidInputError unless ``model`` is one of :data:`MODELS`."""
    if model not in MODELS:
        raise InvalidInputError(
            f"unknown model {model!r}: choose from {', '.join(MODELS)}", name=name, value=model
        )


def run_task(
    case: BuoyCase,
    settings: SweepSettings,
    model: str,
    frequency: float,
    keep_history: bool = False,
    motion: MeasuredTankMotion | None = None,
) -> ModelResult:
    """Simulate ``model`` at ``frequency`` and fit its steady state.

    Arguments:
        case: the study's parameters.
        settings: the sweep settings (step, periods).
        model: one of :data:`MODELS`.
        frequency: in Hz (ignored when ``motion`` is given).
        keep_history: keep the time histories in the result.
        motion: a measured tank record to drive the run instead of the harmonic shake; the run
            covers the whole record and is fitted at the record's frequency.

    Returns:
        The :class:`ModelResult`; a vinculo error during the run is caught and recorded. With
        the harmonic excitation, a run whose steady-state check fails (see
        :class:`~vinculo.buoy.case.SweepSettings`) is continued from its last state by
        ``fit_periods`` periods at a time until it passes or would exceed
        ``settings.max_periods``; the response records
        the outcome (``converged``) and the periods run. A measured record cannot be lengthened:
        its check is only reported.

    Raises:
        InvalidInputError: an unknown model name.
    """
    _check_model(model, "model")
    started = time.perf_counter()
    record = None if motion is None else motion.source
    if motion is not None:
        frequency = motion.frequency
    extension = 0
    history: dict[str, np.ndarray] | None = None
    state: Any = None
    t_done = 0.0
    while True:
        t_end = settings.t_end(frequency, extension) if motion is None else motion.duration
        try:
            part, error, state = _simulate(
                case, settings, model, frequency, t_done, t_end, motion, state
            )
        except VinculoError as e:
            return ModelResult(
                model, frequency, None, f"{type(e).__name__}: {e}", history,
                time.perf_counter() - started, record,
            )
        history = part if history is None else {
            key: np.concatenate([history[key], part[key][1:]]) for key in history
        }
        t_done = float(history["time"][-1])
        if error is not None:
            response = None
            break
        response = steady_response(
            history["time"], history["buoy"], history["tank"], frequency, settings.fit_periods
        )
        converged = bool(
            response.settling <= settings.amplitude_tolerance
            and response.phase_change_deg <= settings.phase_tolerance
        )  # NaN (no earlier window) compares False: not converged
        response = replace(response, converged=converged, periods=round(t_end * frequency, 9))
        if converged or motion is not None or not settings.can_extend(extension):
            break
        extension += 1
    return ModelResult(
        model,
        frequency,
        response,
        error,
        history if (keep_history or error is not None) else None,
        time.perf_counter() - started,
        record,
    )


def _simulate(
    case: BuoyCase,
    settings: SweepSettings,
    model: str,
    frequency: float,
    t_start: float,
    t_end: float,
    motion: MeasuredTankMotion | None,
    state: Any,
) -> tuple[dict[str, np.ndarray], str | None, Any]:
    """Run ``model`` from ``t_start`` (at rest, or from ``state``, the state an earlier call
    returned) to ``t_end``: its histories, its error if it failed, and its final state."""
    if model == "particle":
        run = run_particle_model(
            case, frequency, t_end, dt=settings.dt, save_every=2, tank=motion,
            t_start=t_start, state=state,
        )
        history = {
            "time": run.time,
            "tank": run.tank,
            "buoy": run.buoy,
            "relative": run.relative,
            "tension": run.tension,
        }
        error = None if run.error is None else f"{type(run.error).__name__}: {run.error}"
        final = (run.solution.positions[-1], run.solution.velocities[-1])
        return history, error, final
    reference = TwoDofModel(case) if model == "two-dof" else OneDofModel(case)
    initial = None if state is None else state
    ref = reference.simulate(
        frequency, t_end, sample_dt=2.0 * settings.dt, tank=motion, t_start=t_start,
        initial=initial,
    )
    history = {
        "time": ref.times,
        "tank": ref.x_tank,
        "buoy": ref.x_abs,
        "relative": ref.x_rel,
        "tension": ref.tension,
    }
    return history, None, np.concatenate([ref.angles[-1], ref.rates[-1]])


@dataclass
class StudyResult:
    """Every model over the sweep.

    Attributes:
        case: the parameters used.
        settings: the sweep settings used.
        results: one :class:`ModelResult` per (model, frequency), sorted by model then frequency:
            the sweep's runs, the history runs and the refinement's runs.
        elapsed: wall time of the sweep (s).
        workers: number of worker processes used.
        resonances: the refined resonance of each model (:mod:`vinculo.buoy.resonance`); empty
            when driven by measured records or when refinement is off.
        notes: sentences for the summary: which history frequencies were run and why.
    """

    case: BuoyCase
    settings: SweepSettings
    results: list[ModelResult] = field(default_factory=list)
    elapsed: float = 0.0
    workers: int = 1
    resonances: dict[str, Resonance] = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)

    def of(self, model: str) -> list[ModelResult]:
        """The results of one model, by increasing frequency."""
        return [r for r in self.results if r.model == model]

    def failures(self) -> list[ModelResult]:
        """The runs that failed."""
        return [r for r in self.results if r.error is not None]

    def unconverged(self) -> list[ModelResult]:
        """The runs whose steady-state check failed (their fit may still hold a transient).

        Returns:
            Those results, in the order of :attr:`results`.
        """
        return [r for r in self.results if r.response is not None and r.response.converged is False]

    def curve(
        self, model: str, quantity: str, kinds: Sequence[str] = KINDS
    ) -> tuple[np.ndarray, np.ndarray]:
        """Frequencies and one field of :class:`SteadyResponse` for the successful runs of a model.

        Arguments:
            model: one of :data:`MODELS`.
            quantity: a field name, e.g. ``"absolute_amplitude"`` or ``"relative_phase_deg"``.
            kinds: which runs (:data:`KINDS`; default all: the curve passes through the refined
                points near the peak).

        Returns:
            ``(frequencies, values)``, by increasing frequency.
        """
        ok = sorted(
            (r for r in self.of(model) if r.response is not None and r.kind in kinds),
            key=lambda r: r.frequency,
        )
        return (
            np.array([r.frequency for r in ok]),
            np.array([getattr(r.response, quantity) for r in ok]),
        )

    def resonance(self, model: str, quantity: str = "relative_amplitude") -> tuple[float, float]:
        """Frequency and value of the peak of ``quantity``.

        For the relative amplitude with a refined resonance, that resonance
        (:attr:`resonances`); otherwise the vertex of the parabola through the largest sample
        and its two neighbours (the grid's estimate, when the largest is not at an end).

        Returns:
            ``(frequency in Hz, peak value)``; NaNs when the model has no successful run.
        """
        refined = self.resonances.get(model)
        if quantity == "relative_amplitude" and refined is not None:
            return refined.frequency, refined.peak
        f, y = self.curve(model, quantity)
        if len(f) == 0:
            return math.nan, math.nan
        k, inside = bracket(f, y)
        if inside:
            vertex, value, a = parabola_vertex(f[k - 1 : k + 2], y[k - 1 : k + 2])
            if a < 0:
                return vertex, value
        return float(f[k]), float(y[k])


def _cost(model: str, frequency: float) -> float:
    """Relative cost of a task, to start the longest first (duration ~ 1/f)."""
    return (2.0 if model != "particle" else 1.0) / frequency


class _Runner:
    """Runs batches of tasks in this process or in a pool of worker processes kept open."""

    def __init__(self, workers: int, report: Callable[[ModelResult], None]) -> None:
        self.workers = workers
        self.report = report
        self.pool: Executor | None = None
        self._stack = contextlib.ExitStack()

    def __enter__(self) -> _Runner:
        # Workers die with this process and ignore Ctrl-C, which stops them (executors).
        self.pool, _ = self._stack.enter_context(open_executor(self.workers, None))
        return self

    def __exit__(self, *exc: Any) -> bool | None:
        return self._stack.__exit__(*exc)

    def run(
        self,
        case: BuoyCase,
        settings: SweepSettings,
        tasks: Sequence[tuple[str, float, bool, MeasuredTankMotion | None, str]],
    ) -> list[ModelResult]:
        """Run ``(model, frequency, keep_history, motion, kind)`` tasks; return their results."""
        done: list[ModelResult] = []

        def finish(result: ModelResult, kind: str) -> None:
            result.kind = kind
            done.append(result)
            self.report(result)

        if self.pool is None:
            for m, f, k, motion, kind in tasks:
                finish(run_task(case, settings, m, f, k, motion), kind)
            return done
        futures = {
            self.pool.submit(run_task, case, settings, m, f, k, motion): (m, f, motion, kind)
            for m, f, k, motion, kind in tasks
        }
        for future in as_completed(futures):
            m, f, motion, kind = futures[future]
            try:
                finish(future.result(), kind)
            except (BrokenProcessPool, OSError) as e:  # a worker died: record, go on
                record = None if motion is None else motion.source
                finish(ModelResult(m, f, None, f"{type(e).__name__}: {e}", record=record), kind)
        return done


def _history_plan(
    settings: SweepSettings, history_frequencies: Sequence[float] | None
) -> tuple[list[float], list[float], list[str]]:
    """Which history frequencies to run: ``(on the grid, added, notes)``."""
    sweep = [float(f) for f in settings.frequencies]
    low, high = min(sweep), max(sweep)
    asked = history_frequencies is not None
    wanted = [float(f) for f in (HISTORY_FREQUENCIES if not asked else history_frequencies)]
    on_grid, added, outside = [], [], []
    for f in wanted:
        if any(abs(f - g) < 1e-9 for g in sweep):
            on_grid.append(f)
        elif asked or low - 1e-9 <= f <= high + 1e-9:
            added.append(f)
        else:
            outside.append(f)
    notes = []
    listed = ", ".join(f"{f:g}" for f in sorted(on_grid + added))
    source = "as asked" if asked else "the paper's figs. 11-13"
    if listed:
        extra = (
            f"; {', '.join(f'{f:g}' for f in added)} Hz run in addition to the sweep's grid"
            if added
            else ""
        )
        notes.append(f"time histories at {listed} Hz ({source}){extra}")
    if outside:
        notes.append(
            f"no time history at {', '.join(f'{f:g}' for f in outside)} Hz (the paper's): "
            f"outside the sweep {low:g}-{high:g} Hz; ask for it with --history-frequencies"
        )
    return on_grid, added, notes


def run_study(
    case: BuoyCase,
    settings: SweepSettings,
    *,
    models: Sequence[str] = MODELS,
    history_frequencies: Sequence[float] | None = None,
    workers: int | None = None,
    progress: bool | Callable[[int, int, ModelResult], None] = True,
    stream: IO[str] | None = None,
    motions: Sequence[MeasuredTankMotion] = (),
    refine: bool = True,
) -> StudyResult:
    """Run every model at every frequency of the sweep, then refine each model's resonance.

    With measured tank records (``motions``), every model runs once per record instead, over the
    whole record, and every record's time histories are kept; the sweep's frequencies are not
    used and nothing is refined.

    Arguments:
        case: the study's parameters.
        settings: the sweep settings.
        models: which of :data:`MODELS` to run.
        history_frequencies: frequencies whose time histories are kept, each run (added to the
            sweep when it is not on its grid); default (None): the paper's
            :data:`HISTORY_FREQUENCIES` that lie within the sweep's range; ``()``: none.
        workers: worker processes (default: the number of CPUs); 1 runs in this process.
        progress: True draws a progress bar on ``stream`` (standard error); a callable is called
            as ``progress(done, total, result)`` after each task.
        stream: where the bar is drawn.
        motions: measured tank records (:func:`vinculo.buoy.tank.read_tank_motion`) to drive
            the models instead of the harmonic sweep.
        refine: refine each model's resonance (:func:`refine_resonances`).

    Returns:
        The :class:`StudyResult`; failed runs are in it with their errors.

    Raises:
        InvalidInputError: an unknown model, a bad worker count, or a record shorter than the
            fit window (``fit_periods`` periods of its frequency).
    """
    for m in models:
        _check_model(m, "models")
    workers = (os.cpu_count() or 1) if workers is None else workers
    if not (isinstance(workers, int) and workers >= 1):
        raise InvalidInputError(
            f"workers must be an integer >= 1, got {workers!r}", name="workers", value=workers
        )
    tasks: list[tuple[str, float, bool, MeasuredTankMotion | None, str]]
    notes: list[str] = []
    if motions:
        for motion in motions:
            _check_record(motion, settings)
        tasks = [(m, motion.frequency, True, motion, "sweep") for m in models for motion in motions]
        tasks.sort(key=lambda x: -(x[3].duration if x[3] else 0.0))
    else:
        on_grid, added, notes = _history_plan(settings, history_frequencies)
        kept = on_grid + added

        def keep(f: float) -> bool:
            return any(abs(f - h) < 1e-9 for h in kept)

        sweep = [(float(f), "sweep") for f in settings.frequencies]
        points = sweep + [(f, "history") for f in added]
        tasks = [(m, f, keep(f), None, kind) for m in models for f, kind in points]
        tasks.sort(key=lambda x: -_cost(x[0], x[1]))
    stream = stream if stream is not None else sys.stderr
    started = time.perf_counter()
    results: list[ModelResult] = []
    total = [len(tasks)]

    def report(result: ModelResult) -> None:
        results.append(result)
        if callable(progress):
            progress(len(results), total[0], result)
        elif progress:
            _draw(stream, len(results), total[0], result, time.perf_counter() - started)

    resonances: dict[str, Resonance] = {}
    try:
        with _Runner(workers, report) as runner:
            runner.run(case, settings, tasks)
            if refine and not motions:

                def run_batch(batch: Sequence[tuple[str, float]]) -> list[ModelResult]:
                    total[0] += len(batch)
                    jobs = [(m, f, False, None, "refinement") for m, f in batch]
                    return runner.run(case, settings, sorted(jobs, key=lambda x: -_cost(*x[:2])))

                resonances = refine_resonances(results, settings, run_batch, models)
    finally:
        if progress is True and results:
            stream.write("\n")
            stream.flush()
    order = {m: i for i, m in enumerate(MODELS)}
    results.sort(key=lambda r: (order[r.model], r.frequency, r.record or ""))
    return StudyResult(
        case, settings, results, time.perf_counter() - started, workers, resonances, notes
    )


def refine_resonances(
    results: Sequence[ModelResult],
    settings: SweepSettings,
    run_batch: Callable[[Sequence[tuple[str, float]]], list[ModelResult]],
    models: Sequence[str] = MODELS,
) -> dict[str, Resonance]:
    """Locate each model's peak of relative amplitude by successive parabolic refinement.

    See :mod:`vinculo.buoy.resonance`: from the largest sample of each model's runs and its
    neighbours, rounds of three fresh runs around the current estimate, each round's spacing a
    tenth of the one before (:data:`REFINEMENT_FACTOR`), until the estimate moves by less than
    ``settings.resonance_tolerance`` or ``settings.refine_rounds`` rounds have run. The models
    are refined together: each round is one batch of ``3 x models`` runs.

    Arguments:
        results: the sweep's results (the refinement's are appended to it by ``run_batch``'s
            caller, not here).
        settings: the run settings (and ``resonance_tolerance``, ``refine_rounds``).
        run_batch: runs ``[(model, frequency), ...]`` and returns their results.
        models: the models to refine.

    Returns:
        ``{model: Resonance}`` for each model with a successful run.
    """
    states: dict[str, dict[str, Any]] = {}
    resonances: dict[str, Resonance] = {}
    for model in models:
        ok = sorted(
            (r for r in results if r.model == model and r.response is not None),
            key=lambda r: r.frequency,
        )
        if not ok:
            resonances[model] = Resonance(model, math.nan, math.nan)
            continue
        f = np.array([r.frequency for r in ok])
        y = np.array([r.response.relative_amplitude for r in ok])
        k, inside = bracket(f, y)
        if not inside:
            resonances[model] = Resonance(model, float(f[k]), float(y[k]), status="edge")
            continue
        vertex, value, a = parabola_vertex(f[k - 1 : k + 2], y[k - 1 : k + 2])
        if not a < 0.0:  # pragma: no cover - a strict maximum between two samples curves down
            vertex, value = float(f[k]), float(y[k])
        spacing = min(f[k + 1] - f[k], f[k] - f[k - 1]) / REFINEMENT_FACTOR
        settling = max(_settling(ok[j]) for j in range(k - 1, k + 2))
        resonances[model] = Resonance(
            model, vertex, value, status="unrefined", estimates=[vertex],
            frequency_uncertainty=spacing * REFINEMENT_FACTOR / 2.0,
            peak_uncertainty=max(abs(value - y[k]), settling * value),
        )
        if settings.refine_rounds > 0:
            states[model] = {"centre": vertex, "spacing": spacing,
                             "low": float(f[k - 1]), "high": float(f[k + 1])}
    for _ in range(settings.refine_rounds):
        if not states:
            break
        batch = [
            (model, fr)
            for model, st in states.items()
            for fr in round_frequencies(st["centre"], st["spacing"], st["low"], st["high"])
        ]
        done = run_batch(batch)
        for model in list(states):
            st, res = states[model], resonances[model]
            runs = sorted((r for r in done if r.model == model), key=lambda r: r.frequency)
            res.rounds += 1
            res.runs += [r.frequency for r in runs]
            if len(runs) != 3 or any(r.response is None for r in runs):
                del states[model]  # a run failed: keep the estimate so far, "unrefined"
                continue
            f = np.array([r.frequency for r in runs])
            y = np.array([r.response.relative_amplitude for r in runs])
            vertex, value, a = parabola_vertex(f, y)
            k = int(np.argmax(y))
            if not a < 0.0 or k != 1:
                # the peak lies beyond the three points: move there at the same spacing
                st["centre"] = float(f[k]) if not a < 0.0 else vertex
                continue
            moved = abs(vertex - res.estimates[-1])
            settling = max(_settling(r) for r in runs)
            res.estimates.append(vertex)
            res.peak_uncertainty = max(abs(value - res.peak), settling * value)
            res.frequency, res.peak = vertex, value
            res.frequency_uncertainty = moved
            st["centre"], st["spacing"] = vertex, st["spacing"] / REFINEMENT_FACTOR
            st["low"], st["high"] = float(f[0]), float(f[2])
            if moved < settings.resonance_tolerance:
                res.status = "refined"
                del states[model]
    return resonances


def _settling(result: ModelResult) -> float:
    """The relative amplitude change of a run's steady-state check (its amplitude's scatter);
    the largest finite value a run can report when the check could not be made."""
    value = result.response.settling if result.response is not None else math.nan
    return value if math.isfinite(value) else 1.0


def _check_record(motion: MeasuredTankMotion, settings: SweepSettings) -> None:
    """Raise unless ``motion`` is long enough for the fit window at its frequency."""
    needed = settings.fit_periods / motion.frequency
    if motion.duration < needed:
        raise InvalidInputError(
            f"{motion.source}: the record lasts {motion.duration:g} s, shorter than the fit "
            f"window of {settings.fit_periods} periods at {motion.frequency:.4g} Hz "
            f"({needed:g} s); give a longer record (the transient must also die out before the "
            f"window) or fewer fit periods",
            name="tank_motion",
            value=motion.source,
        )


def _draw(stream: IO[str], done: int, total: int, result: ModelResult, elapsed: float) -> None:
    """One-line progress bar of the sweep."""
    width = 30
    filled = round(width * done / total)
    status = "failed" if result.error else "ok"
    stream.write(
        f"\rvinculo buoy [{'#' * filled}{'-' * (width - filled)}] {done}/{total} runs  "
        f"({elapsed:.1f} s; last: {result.model} at {result.frequency:.3g} Hz {status})   "
    )
    stream.flush()
