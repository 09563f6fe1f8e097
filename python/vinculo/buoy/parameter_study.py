"""Parameter studies of the buoy: any case parameter over a grid, in parallel, resumable.

A study is a list of points, each a set of parameter values (``drag_coefficient = 0.3``,
``frequency = 0.9``, ...) overriding a base :class:`~vinculo.buoy.case.BuoyCase` and
:class:`~vinculo.buoy.case.SweepSettings`; every point runs every requested model once
(:func:`vinculo.buoy.study.run_task`: simulate from rest, fit the steady state). Without a
``frequency`` axis, each point is swept over the settings' frequencies.

Runs go to local worker processes, or, given a scheduler address, to an existing Dask distributed
cluster (``pip install "vinculo[dask]"``). Each finished run is appended to a CSV file at once
(flushed and synced), so an interrupted study resumes where it stopped: runs already in the file
are not computed again. A failed run is a row with its parameters and error, and the others go
on.

Axes on the command line (``vinculo buoy sweep --param NAME=VALUES``)::

    drag_coefficient=0.1:0.4:7    7 values from 0.1 to 0.4 (numpy.linspace)
    frequency=0.8,0.9,1.1         a list
    attachment=bottom,centre      text parameters take lists
"""

from __future__ import annotations

import contextlib
import csv
import dataclasses
import itertools
import math
import os
import sys
import time
from collections.abc import Callable, Iterator, Mapping, Sequence
from concurrent.futures import as_completed
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass, field
from pathlib import Path
from typing import IO, Any

import numpy as np

from vinculo.buoy.case import MAX_STEPS, BuoyCase, SweepSettings
from vinculo.buoy.executors import open_executor
from vinculo.buoy.study import MODELS, run_task
from vinculo.errors import InvalidInputError, VinculoError

__all__ = [
    "RESULT_COLUMNS",
    "ParameterStudy",
    "StudyRow",
    "grid",
    "parameter_names",
    "parse_axis",
    "run_parameter_study",
]

#: Per-run settings that a study may vary besides the case's fields and the frequency.
RUN_SETTINGS = ("dt", "settle_periods", "fit_periods")
#: Most values on one axis, and most points in a grid (a study beyond them would not finish).
MAX_AXIS_VALUES = 10_000
MAX_POINTS = 1_000_000
#: Result columns of the CSV file, after the parameters and the model.
RESULT_COLUMNS = (
    "status",
    "tank_amplitude",
    "absolute_amplitude",
    "absolute_phase_deg",
    "relative_amplitude",
    "relative_phase_deg",
    "settling",
    "residual_rms",
    "elapsed_s",
    "error",
)
_NUMERIC_RESULTS = RESULT_COLUMNS[1:-1]


def parameter_names() -> tuple[str, ...]:
    """The names a study may vary: the case's fields, ``frequency``, and the run settings."""
    case = tuple(f.name for f in dataclasses.fields(BuoyCase) if f.name != "tank_size")
    return (*case, "frequency", *RUN_SETTINGS)


def _kind(name: str) -> type:
    """The Python type of a parameter's values."""
    if name == "frequency":
        return float
    for cls in (BuoyCase, SweepSettings):
        for f in dataclasses.fields(cls):
            if f.name == name:
                return type(f.default)
    raise _unknown(name)


def _unknown(name: str) -> InvalidInputError:
    return InvalidInputError(
        f"unknown study parameter {name!r}: choose from {', '.join(parameter_names())}",
        name="parameter",
        value=name,
    )


def _canonical(name: str, value: Any) -> str:
    """A parameter value as the text that identifies it in the results file."""
    kind = _kind(name)
    if kind is str:
        return str(value)
    if kind is int:
        return str(int(value))
    return repr(float(value))


def _convert(name: str, text: str) -> Any:
    """One value of an axis, from text, in the parameter's type."""
    kind = _kind(name)
    if kind is str:
        return text.strip()
    try:
        number = float(text)
    except ValueError:
        raise InvalidInputError(
            f"{name}: {text.strip()!r} is not a number", name=name, value=text
        ) from None
    if kind is int:
        if not number.is_integer():
            raise InvalidInputError(
                f"{name} takes whole numbers, got {text.strip()!r}", name=name, value=text
            )
        return int(number)
    return number


def parse_axis(text: str) -> tuple[str, list[Any]]:
    """Parse ``NAME=START:STOP:COUNT`` or ``NAME=V1,V2,...`` into a name and its values.

    Arguments:
        text: the axis, as given to ``--param``.

    Returns:
        ``(name, values)``.

    Raises:
        InvalidInputError: an unknown name, a malformed range, a count below 1 or above
            :data:`MAX_AXIS_VALUES`, or no values.
    """
    name, sep, values = text.partition("=")
    name = name.strip().replace("-", "_")
    if not sep:
        raise InvalidInputError(
            f"a study axis reads NAME=START:STOP:COUNT or NAME=V1,V2,..., got {text!r}",
            name="parameter",
            value=text,
        )
    if name not in parameter_names():
        raise _unknown(name)
    values = values.strip()
    if ":" in values:
        parts = values.split(":")
        if len(parts) != 3 or _kind(name) is str:
            raise InvalidInputError(
                f"{name}: a range reads START:STOP:COUNT (numbers), got {values!r}",
                name=name,
                value=values,
            )
        start, stop = _convert(name, parts[0]), _convert(name, parts[1])
        count = _convert("string_beads", parts[2])  # a whole number
        if count < 1:
            raise InvalidInputError(
                f"{name}: the range {values!r} has no points (COUNT must be >= 1)",
                name=name,
                value=values,
            )
        if count > MAX_AXIS_VALUES:
            raise InvalidInputError(
                f"{name}: the range {values!r} has {count} points, more than "
                f"{MAX_AXIS_VALUES}; give a smaller COUNT",
                name=name,
                value=values,
            )
        axis = np.linspace(float(start), float(stop), count)
        result = [round(v) for v in axis] if _kind(name) is int else axis.tolist()
    else:
        result = [_convert(name, v) for v in values.split(",") if v.strip()]
    if not result:
        raise InvalidInputError(
            f"{name}: the axis {text!r} has no values", name=name, value=values
        )
    return name, result


def grid(axes: Mapping[str, Sequence[Any]]) -> list[dict[str, Any]]:
    """Every combination of the axes' values (the last axis varies fastest).

    At most :data:`MAX_POINTS` combinations.

    Arguments:
        axes: parameter name -> values.

    Returns:
        The points, each a dict name -> value.

    Raises:
        InvalidInputError: an unknown name, an axis without values (the grid has no points), or
            more than :data:`MAX_POINTS` points.
    """
    for name, values in axes.items():
        if name not in parameter_names():
            raise _unknown(name)
        if len(values) == 0:
            raise InvalidInputError(
                f"the axis {name!r} has no values: the grid has no points", name=name, value=[]
            )
    size = math.prod(len(values) for values in axes.values())
    if size > MAX_POINTS:
        raise InvalidInputError(
            f"the grid has {size} points ({' x '.join(str(len(v)) for v in axes.values())}), "
            f"more than {MAX_POINTS}; use fewer or shorter axes",
            name="points",
            value=size,
        )
    names = list(axes)
    return [dict(zip(names, combo, strict=True)) for combo in itertools.product(*axes.values())]


@dataclass
class StudyRow:
    """One run of a study: its parameters, model and results.

    Attributes:
        parameters: the point's values, name -> value.
        model: one of :data:`vinculo.buoy.study.MODELS`.
        status: ``"ok"`` or ``"failed"``.
        results: the numeric results (``RESULT_COLUMNS`` without status and error); NaN when the
            run failed.
        error: ``"ErrorClass: message"`` of a failed run, else ``""``.
    """

    parameters: dict[str, Any]
    model: str
    status: str
    results: dict[str, float]
    error: str = ""

    def key(self, names: Sequence[str]) -> tuple[str, ...]:
        """The identity of the run in the results file."""
        return (self.model, *(_canonical(n, self.parameters[n]) for n in names))


@dataclass
class ParameterStudy:
    """The rows of a study, those run now and those found in the file.

    Attributes:
        names: the parameters varied, in column order.
        rows: every row in the results file for this study's points, in the order they finished.
        path: the results file.
        computed: runs computed by this call.
        reused: runs found in the file and not computed again.
        elapsed: wall time of this call, in s.
        workers: how the runs were executed (``"2 local processes"``, ``"dask tcp://..."``).
    """

    names: list[str]
    rows: list[StudyRow] = field(default_factory=list)
    path: Path | None = None
    computed: int = 0
    reused: int = 0
    elapsed: float = 0.0
    workers: str = ""

    def failures(self) -> list[StudyRow]:
        """The rows of failed runs."""
        return [r for r in self.rows if r.status != "ok"]

    def column(self, name: str, model: str | None = None) -> np.ndarray:
        """One parameter or result over the rows (optionally of one model), as an array."""
        rows = [r for r in self.rows if model is None or r.model == model]
        if name in self.names:
            return np.array([r.parameters[name] for r in rows])
        return np.array([r.results.get(name, math.nan) for r in rows], dtype=np.float64)


def _point_task(
    case: dict[str, Any], settings: dict[str, Any], point: dict[str, Any], model: str
) -> StudyRow:
    """Run one point with one model (in a worker); every error becomes a failed row."""
    started = time.perf_counter()
    case_values = {**case, **{k: v for k, v in point.items() if k in _CASE_NAMES}}
    settings_values = {**settings, **{k: v for k, v in point.items() if k in RUN_SETTINGS}}
    try:
        built_case = BuoyCase.from_mapping(case_values, source="the study point")
        built_settings = SweepSettings.from_mapping(settings_values, source="the study point")
        result = run_task(built_case, built_settings, model, float(point["frequency"]))
    except VinculoError as e:
        return _failed(point, model, f"{type(e).__name__}: {e}", started)
    if result.response is None:
        return _failed(point, model, result.error or "no response", started)
    values = {k: float(getattr(result.response, k)) for k in _NUMERIC_RESULTS if k != "elapsed_s"}
    values["elapsed_s"] = time.perf_counter() - started
    return StudyRow(point, model, "ok", values)


_CASE_NAMES = frozenset(f.name for f in dataclasses.fields(BuoyCase))


def _check_points(
    points: Sequence[Mapping[str, Any]], case: BuoyCase, settings: SweepSettings
) -> None:
    """Raise before anything runs if a point's frequency or parameters are out of their domain.

    Raises:
        InvalidInputError: naming the value (each distinct combination is checked once).
    """
    base_case, base_settings = case.to_dict(), settings.to_dict()
    seen: set[tuple[str, ...]] = set()
    for point in points:
        value = point["frequency"]
        frequency = float(value)
        if not (math.isfinite(frequency) and frequency > 0.0):
            raise InvalidInputError(
                f"study point frequency = {value!r} Hz: a frequency must be a finite number "
                f"greater than 0; change the frequency axis",
                name="frequency",
                value=value,
            )
        key = tuple(f"{k}={v!r}" for k, v in point.items() if k != "frequency")
        where = "the study point " + (", ".join(key) or "(base case)")
        if key not in seen:
            seen.add(key)
            BuoyCase.from_mapping(
                {**base_case, **{k: v for k, v in point.items() if k in _CASE_NAMES}},
                source=where,
            )
        run = SweepSettings.from_mapping(
            {**base_settings, **{k: v for k, v in point.items() if k in RUN_SETTINGS}},
            source=where,
        )
        steps = run.t_end(frequency) / run.dt
        if not steps <= MAX_STEPS:
            raise InvalidInputError(
                f"{where} at frequency = {value!r} Hz would take {steps:.3g} time steps of "
                f"{run.dt!r} s, more than {MAX_STEPS:.0e}; raise the frequency or dt, or "
                f"lower the periods",
                name="frequency",
                value=value,
            )


def _failed(point: dict[str, Any], model: str, error: str, started: float) -> StudyRow:
    values = dict.fromkeys(_NUMERIC_RESULTS, math.nan)
    values["elapsed_s"] = time.perf_counter() - started
    return StudyRow(point, model, "failed", values, error.replace("\n", " "))


class _ResultsFile:
    """The study's CSV file: read back on resume, appended to (and synced) row by row."""

    def __init__(self, path: Path, names: list[str]) -> None:
        self.path = path
        self.names = names
        self.header = [*names, "model", *RESULT_COLUMNS]

    def read(self) -> list[StudyRow]:
        """The complete rows already in the file (a cut-off last line is dropped)."""
        if not self.path.exists():
            return []
        try:
            text = self.path.read_text(encoding="utf-8")
        except OSError as e:
            raise InvalidInputError(
                f"cannot read the study file {self.path}: {e.strerror}", name="output",
                value=str(self.path),
            ) from None
        if text and not text.endswith("\n"):  # interrupted while writing a row
            text = text[: text.rfind("\n") + 1]
            self.path.write_text(text, encoding="utf-8")
        lines = list(csv.reader(text.splitlines()))
        if not lines:
            return []
        if lines[0] != self.header:
            raise InvalidInputError(
                f"{self.path} holds a study of the columns {', '.join(lines[0])}, not this "
                f"one's ({', '.join(self.header)}); choose another --output folder",
                name="output",
                value=str(self.path),
            )
        rows = []
        n = len(self.names)
        for fields in lines[1:]:
            if len(fields) != len(self.header):
                continue
            point = {name: _convert(name, fields[k]) for k, name in enumerate(self.names)}
            model, status = fields[n], fields[n + 1]
            numbers = {
                k: float(v) if v else math.nan
                for k, v in zip(_NUMERIC_RESULTS, fields[n + 2 : -1], strict=True)
            }
            rows.append(StudyRow(point, model, status, numbers, fields[-1]))
        return rows

    @contextlib.contextmanager
    def appender(self) -> Iterator[Callable[[StudyRow], None]]:
        """A function that appends one row and syncs the file."""
        new = not self.path.exists() or self.path.stat().st_size == 0
        with self.path.open("a", newline="", encoding="utf-8") as handle:
            writer = csv.writer(handle)
            if new:
                writer.writerow(self.header)

            def append(row: StudyRow) -> None:
                writer.writerow([
                    *(_canonical(n, row.parameters[n]) for n in self.names),
                    row.model,
                    row.status,
                    *(repr(row.results[k]) for k in _NUMERIC_RESULTS),
                    row.error,
                ])
                handle.flush()
                os.fsync(handle.fileno())

            yield append


def run_parameter_study(
    points: Sequence[Mapping[str, Any]],
    *,
    case: BuoyCase | None = None,
    settings: SweepSettings | None = None,
    models: Sequence[str] = ("particle",),
    output: str | Path | None = None,
    workers: int | None = None,
    scheduler: str | None = None,
    retry_failed: bool = False,
    scheduler_timeout: float = 10.0,
    progress: bool | Callable[[int, int, StudyRow], None] = True,
    stream: IO[str] | None = None,
) -> ParameterStudy:
    """Run every model at every point, in parallel, appending each run to ``output`` as it ends.

    Arguments:
        points: parameter values per run (see :func:`grid`); without ``frequency`` in the points,
            each is swept over ``settings.frequencies``.
        case: the base case (default: the study's defaults).
        settings: the base sweep and run settings.
        models: which of :data:`~vinculo.buoy.study.MODELS` to run at each point.
        output: the results CSV file (or a folder, which gets ``study.csv``); runs already in it
            are reused, not recomputed. None keeps the results in memory only.
        workers: local worker processes (default: one per CPU); ignored with ``scheduler``.
        scheduler: address of a Dask distributed scheduler (``tcp://host:8786``) to run on.
        retry_failed: run again the points whose earlier run failed.
        scheduler_timeout: seconds to wait for the scheduler to answer.
        progress: True draws a progress bar on ``stream`` (standard error); a callable is called
            as ``progress(done, total, row)`` after each run.
        stream: where the bar is drawn.

    Returns:
        The :class:`ParameterStudy` (rows of this study's points only).

    Raises:
        InvalidInputError: no points, an unknown parameter, points with different parameters,
            an unknown model, a bad worker count, or a results file of another study.
        SchedulerError: the scheduler cannot be reached (or distributed is not installed).
    """
    started = time.perf_counter()
    case = case if case is not None else BuoyCase()
    settings = settings if settings is not None else SweepSettings()
    if not points:
        raise InvalidInputError("the study has no points", name="points", value=[])
    names = list(points[0])
    for point in points:
        if list(point) != names:
            raise InvalidInputError(
                f"every point must set the same parameters ({', '.join(names)}), got "
                f"{', '.join(point)}",
                name="points",
                value=dict(point),
            )
    for name in names:
        _kind(name)  # raises for an unknown name
    full = [dict(p) for p in points]
    if "frequency" not in names:
        full = [{**p, "frequency": float(f)} for p in full for f in settings.frequencies]
        names.append("frequency")
    for m in models:
        if m not in MODELS:
            raise InvalidInputError(
                f"unknown model {m!r}: choose from {', '.join(MODELS)}", name="models", value=m
            )
    _check_points(full, case, settings)
    workers = (os.cpu_count() or 1) if workers is None else workers
    if not (isinstance(workers, int) and workers >= 1):
        raise InvalidInputError(
            f"workers must be an integer >= 1, got {workers!r}", name="workers", value=workers
        )
    results_file = None
    if output is not None:
        path = Path(output)
        if path.is_dir() or path.suffix.lower() != ".csv":
            path.mkdir(parents=True, exist_ok=True)
            path = path / "study.csv"
        results_file = _ResultsFile(path, names)
    study = ParameterStudy(names, path=None if results_file is None else results_file.path)
    wanted = {StudyRow(p, m, "", {}).key(names): (p, m) for m in models for p in full}
    done: dict[tuple[str, ...], StudyRow] = {}
    if results_file is not None:
        for row in results_file.read():
            key = row.key(names)
            if key in wanted and (row.status == "ok" or not retry_failed):
                done[key] = row
    study.rows = list(done.values())
    study.reused = len(done)
    todo = [(p, m) for key, (p, m) in wanted.items() if key not in done]
    todo.sort(key=lambda pm: -1.0 / float(pm[0]["frequency"]))  # longest runs first
    stream = stream if stream is not None else sys.stderr
    base_case, base_settings = case.to_dict(), settings.to_dict()
    total = len(todo)

    def report(row: StudyRow, append: Callable[[StudyRow], None] | None) -> None:
        study.rows.append(row)
        study.computed += 1
        if append is not None:
            append(row)
        if callable(progress):
            progress(study.computed, total, row)
        elif progress:
            _draw(stream, study.computed, total, row, time.perf_counter() - started)

    appender = results_file.appender() if results_file else contextlib.nullcontext(None)
    executor = open_executor(workers, scheduler, scheduler_timeout)
    try:
        with executor as (pool, how), appender as append:
            study.workers = how
            if pool is None:
                for p, m in todo:
                    report(_point_task(base_case, base_settings, p, m), append)
            else:
                futures = {
                    pool.submit(_point_task, base_case, base_settings, p, m): (p, m)
                    for p, m in todo
                }
                for future in as_completed(futures):
                    p, m = futures[future]
                    try:
                        row = future.result()
                    except (BrokenProcessPool, OSError) as e:  # a worker died: record, go on
                        row = _failed(p, m, f"{type(e).__name__}: {e}", time.perf_counter())
                    report(row, append)
    finally:
        if progress is True and study.computed:
            stream.write("\n")
            stream.flush()
    study.elapsed = time.perf_counter() - started
    return study


def _draw(stream: IO[str], done: int, total: int, row: StudyRow, elapsed: float) -> None:
    """One-line progress bar of the study."""
    width = 30
    filled = round(width * done / total) if total else width
    point = ", ".join(f"{k}={v:g}" if isinstance(v, float) else f"{k}={v}"
                      for k, v in row.parameters.items())
    stream.write(
        f"\rvinculo buoy sweep [{'#' * filled}{'-' * (width - filled)}] {done}/{total} runs "
        f"({elapsed:.1f} s; last: {row.model} {point} {row.status})   "
    )
    stream.flush()
