"""The frequency sweep of the buoy study: every model at every frequency, in parallel processes.

Each (model, frequency) pair is one task: simulate from rest for ``SweepSettings.t_end(f)``, then
fit the steady-state amplitude and phase over the last ``fit_periods`` whole periods
(:func:`vinculo.buoy.harmonic.steady_response`). Tasks run in worker processes (the particle model
releases the GIL, the scipy reference models do not, so processes serve both); a task that fails
is recorded with its error and the others go on.

Driven by measured tank records instead (``run_study(..., motions=[...])``, ``vinculo buoy
--tank-motion FILE.csv``), each record is one excitation: every model runs over the whole record
and is fitted over its last ``fit_periods`` periods at the record's frequency.
"""

from __future__ import annotations

import math
import os
import sys
import time
from collections.abc import Callable, Sequence
from concurrent.futures import as_completed
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass, field
from typing import IO

import numpy as np

from vinculo.buoy.case import BuoyCase, SweepSettings
from vinculo.buoy.executors import open_executor
from vinculo.buoy.harmonic import SteadyResponse, steady_response
from vinculo.buoy.model import run_particle_model
from vinculo.buoy.reference import OneDofModel, TwoDofModel
from vinculo.buoy.tank import MeasuredTankMotion
from vinculo.errors import InvalidInputError, VinculoError

__all__ = ["MODELS", "ModelResult", "StudyResult", "run_study", "run_task"]

#: The models of the study, by name: the particle model and the two scipy references.
MODELS = ("particle", "two-dof", "one-dof")
#: Labels for plots and tables.
LABELS = {
    "particle": "particle model (vinculo)",
    "two-dof": "2-DOF string + sphere (scipy)",
    "one-dof": "1-DOF rigid pendulum, eq. 31 corrected (scipy)",
    "measured": "measurements",
}
#: Frequencies whose time histories are kept (the study's figs. 11-13).
HISTORY_FREQUENCIES = (0.8, 0.9, 1.1)


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
    """

    model: str
    frequency: float
    response: SteadyResponse | None
    error: str | None = None
    history: dict[str, np.ndarray] | None = None
    elapsed: float = 0.0
    record: str | None = None


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
        The :class:`ModelResult`; a vinculo error during the run is caught and recorded.

    Raises:
        InvalidInputError: an unknown model name.
    """
    _check_model(model, "model")
    started = time.perf_counter()
    record = None if motion is None else motion.source
    if motion is None:
        t_end = settings.t_end(frequency)
    else:
        frequency, t_end = motion.frequency, motion.duration
    error: str | None = None
    try:
        if model == "particle":
            run = run_particle_model(
                case, frequency, t_end, dt=settings.dt, save_every=2, tank=motion
            )
            history = {
                "time": run.time,
                "tank": run.tank,
                "buoy": run.buoy,
                "relative": run.relative,
                "tension": run.tension,
            }
            if run.error is not None:
                error = f"{type(run.error).__name__}: {run.error}"
        else:
            reference = TwoDofModel(case) if model == "two-dof" else OneDofModel(case)
            ref = reference.simulate(frequency, t_end, sample_dt=2.0 * settings.dt, tank=motion)
            history = {
                "time": ref.times,
                "tank": ref.x_tank,
                "buoy": ref.x_abs,
                "relative": ref.x_rel,
                "tension": ref.tension,
            }
    except VinculoError as e:
        return ModelResult(
            model, frequency, None, f"{type(e).__name__}: {e}", None,
            time.perf_counter() - started, record,
        )
    response = None
    if error is None:
        response = steady_response(
            history["time"], history["buoy"], history["tank"], frequency, settings.fit_periods
        )
    return ModelResult(
        model,
        frequency,
        response,
        error,
        history if (keep_history or error is not None) else None,
        time.perf_counter() - started,
        record,
    )


@dataclass
class StudyResult:
    """Every model over the sweep.

    Attributes:
        case: the parameters used.
        settings: the sweep settings used.
        results: one :class:`ModelResult` per (model, frequency), sorted by model then frequency.
        elapsed: wall time of the sweep (s).
        workers: number of worker processes used.
    """

    case: BuoyCase
    settings: SweepSettings
    results: list[ModelResult] = field(default_factory=list)
    elapsed: float = 0.0
    workers: int = 1

    def of(self, model: str) -> list[ModelResult]:
        """The results of one model, by increasing frequency."""
        return [r for r in self.results if r.model == model]

    def failures(self) -> list[ModelResult]:
        """The runs that failed."""
        return [r for r in self.results if r.error is not None]

    def curve(self, model: str, quantity: str) -> tuple[np.ndarray, np.ndarray]:
        """Frequencies and one field of :class:`SteadyResponse` for the successful runs of a model.

        Arguments:
            model: one of :data:`MODELS`.
            quantity: a field name, e.g. ``"absolute_amplitude"`` or ``"relative_phase_deg"``.

        Returns:
            ``(frequencies, values)``.
        """
        ok = [r for r in self.of(model) if r.response is not None]
        return (
            np.array([r.frequency for r in ok]),
            np.array([getattr(r.response, quantity) for r in ok]),
        )

    def resonance(self, model: str, quantity: str = "relative_amplitude") -> tuple[float, float]:
        """Frequency and value of the peak of ``quantity`` over the sweep.

        The peak is refined by the vertex of the parabola through the largest sample and its two
        neighbours (when it is not at an end of the sweep).

        Returns:
            ``(frequency in Hz, peak value)``; NaNs when the model has no successful run.
        """
        f, y = self.curve(model, quantity)
        if len(f) == 0:
            return math.nan, math.nan
        k = int(np.argmax(y))
        if 0 < k < len(f) - 1:
            a, b, c = np.polyfit(f[k - 1 : k + 2], y[k - 1 : k + 2], 2)
            if a < 0:
                vertex = -b / (2 * a)
                return float(vertex), float(np.polyval((a, b, c), vertex))
        return float(f[k]), float(y[k])


def _cost(model: str, frequency: float) -> float:
    """Relative cost of a task, to start the longest first (duration ~ 1/f)."""
    return (2.0 if model != "particle" else 1.0) / frequency


def run_study(
    case: BuoyCase,
    settings: SweepSettings,
    *,
    models: Sequence[str] = MODELS,
    history_frequencies: Sequence[float] = HISTORY_FREQUENCIES,
    workers: int | None = None,
    progress: bool | Callable[[int, int, ModelResult], None] = True,
    stream: IO[str] | None = None,
    motions: Sequence[MeasuredTankMotion] = (),
) -> StudyResult:
    """Run every model at every frequency of the sweep (and at the history frequencies).

    With measured tank records (``motions``), every model runs once per record instead, over the
    whole record, and every record's time histories are kept; the sweep's frequencies are not
    used.

    Arguments:
        case: the study's parameters.
        settings: the sweep settings.
        models: which of :data:`MODELS` to run.
        history_frequencies: frequencies whose time histories are kept; they are added to the
            sweep if not already in it.
        workers: worker processes (default: the number of CPUs); 1 runs in this process.
        progress: True draws a progress bar on ``stream`` (standard error); a callable is called
            as ``progress(done, total, result)`` after each task.
        stream: where the bar is drawn.
        motions: measured tank records (:func:`vinculo.buoy.tank.read_tank_motion`) to drive
            the models instead of the harmonic sweep.

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
    tasks: list[tuple[str, float, bool, MeasuredTankMotion | None]]
    if motions:
        for motion in motions:
            _check_record(motion, settings)
        tasks = [(m, motion.frequency, True, motion) for m in models for motion in motions]
        tasks.sort(key=lambda x: -(x[3].duration if x[3] else 0.0))
    else:
        sweep = [float(f) for f in settings.frequencies]
        extra = [f for f in history_frequencies if not any(abs(f - g) < 1e-9 for g in sweep)]
        frequencies = sorted(sweep + [float(f) for f in extra])
        keep = {f for f in frequencies if any(abs(f - h) < 1e-9 for h in history_frequencies)}
        tasks = [(m, f, f in keep, None) for m in models for f in frequencies]
        tasks.sort(key=lambda x: -_cost(x[0], x[1]))
    stream = stream if stream is not None else sys.stderr
    started = time.perf_counter()
    results: list[ModelResult] = []

    def report(result: ModelResult) -> None:
        results.append(result)
        if callable(progress):
            progress(len(results), len(tasks), result)
        elif progress:
            _draw(stream, len(results), len(tasks), result, time.perf_counter() - started)

    try:
        if workers == 1:
            for m, f, k, motion in tasks:
                report(run_task(case, settings, m, f, k, motion))
        else:
            # Workers die with this process and ignore Ctrl-C, which stops them (executors).
            with open_executor(workers, None) as (pool, _):
                assert pool is not None  # workers > 1
                futures = {
                    pool.submit(run_task, case, settings, m, f, k, motion): (m, f, motion)
                    for m, f, k, motion in tasks
                }
                for future in as_completed(futures):
                    m, f, motion = futures[future]
                    try:
                        report(future.result())
                    except (BrokenProcessPool, OSError) as e:  # a worker died: record, go on
                        record = None if motion is None else motion.source
                        report(ModelResult(m, f, None, f"{type(e).__name__}: {e}", record=record))
    finally:
        if progress is True and results:
            stream.write("\n")
            stream.flush()
    order = {m: i for i, m in enumerate(MODELS)}
    results.sort(key=lambda r: (order[r.model], r.frequency, r.record or ""))
    return StudyResult(case, settings, results, time.perf_counter() - started, workers)


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
