"""Calibration of the buoy's fluid coefficients against measured amplitude and phase curves.

The study's authors attribute their mismatch with experiment to the drag and added-mass
coefficients they chose; :func:`calibrate` fits them (and optionally the string length and the
table amplitude X0) to measured steady-state amplitude and phase by weighted nonlinear least
squares (:func:`scipy.optimize.least_squares`, trust-region reflective, parameters kept
non-negative):

    minimise  sum_i ((A_i(p) - A_i) / sA_i)^2 + ((phi_i(p) - phi_i) / sphi_i)^2

over the measured frequencies f_i, where ``A_i(p)`` and ``phi_i(p)`` come from the chosen model
run at f_i (all frequencies of one evaluation in parallel) and the phase difference is wrapped to
(-180, 180]. The weights are the data's standard uncertainties (``amplitude_sd``, ``phase_sd``
columns) when given; otherwise 2 % of the largest measured amplitude and 2 degrees.

Uncertainties: with ``J`` the Jacobian of the weighted residuals at the optimum (forward
differences), the covariance is ``(J^T J)^-1`` when the data give their uncertainties (absolute
weights); otherwise it is scaled by the reduced chi-square ``chi2 / (m - p)``, which estimates
the unknown scale of the weights (the usual convention of weighted least squares). Each
parameter's standard uncertainty is the square root of its diagonal entry.
"""

from __future__ import annotations

import dataclasses
import math
import os
import sys
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import IO, Any

import numpy as np
from scipy.optimize import least_squares

from vinculo.buoy.case import BuoyCase, SweepSettings
from vinculo.buoy.data import Measurements
from vinculo.buoy.executors import open_executor
from vinculo.buoy.study import MODELS, run_task
from vinculo.errors import ConvergenceError, InvalidInputError

__all__ = ["CALIBRATABLE", "Calibration", "calibrate", "model_curve", "wrap_phase_difference"]

#: Parameters :func:`calibrate` can fit.
CALIBRATABLE = ("drag_coefficient", "added_mass_coefficient", "string_length", "amplitude")
#: Default weights when the data give no uncertainties: a fraction of the largest measured
#: amplitude, and degrees of phase.
DEFAULT_AMPLITUDE_FRACTION = 0.02
DEFAULT_PHASE_SD = 2.0
#: Relative step of the forward differences of the Jacobian (the fitted steady state is smooth
#: in the parameters; 1e-3 stays far above its round-off, about 1e-9).
DIFF_STEP = 1e-3


@dataclass
class Calibration:
    """The result of :func:`calibrate`.

    Attributes:
        names: the fitted parameters.
        initial: their starting values.
        values: their fitted values.
        uncertainties: standard uncertainties of the fitted values.
        correlation: correlation matrix of the fitted values, shape (p, p).
        chi_square: weighted sum of squared residuals at the optimum.
        degrees_of_freedom: residuals minus parameters.
        absolute_weights: True when the data gave their uncertainties (the covariance is then
            not scaled by the reduced chi-square).
        case: the case with the fitted values.
        model: the model used.
        data: the measurements.
        fitted_amplitude, fitted_phase_deg: the fitted model at the measured frequencies.
        initial_amplitude, initial_phase_deg: the starting model there.
        curve_frequency, curve_amplitude, curve_phase_deg: the fitted model on an even grid over
            the measured range (for the plot; empty when ``curve_points`` was 0).
        evaluations: model sweeps run (each: one run per frequency), the fitted curve included.
        success: whether the optimiser reported convergence; ``message`` says why it stopped.
        elapsed: wall time, in s.
    """

    names: list[str]
    initial: np.ndarray
    values: np.ndarray
    uncertainties: np.ndarray
    correlation: np.ndarray
    chi_square: float
    degrees_of_freedom: int
    absolute_weights: bool
    case: BuoyCase
    model: str
    data: Measurements
    fitted_amplitude: np.ndarray
    fitted_phase_deg: np.ndarray
    initial_amplitude: np.ndarray
    initial_phase_deg: np.ndarray
    evaluations: int = 0
    success: bool = True
    message: str = ""
    elapsed: float = 0.0
    log: list[str] = field(default_factory=list)
    curve_frequency: np.ndarray = field(default_factory=lambda: np.zeros(0))
    curve_amplitude: np.ndarray = field(default_factory=lambda: np.zeros(0))
    curve_phase_deg: np.ndarray = field(default_factory=lambda: np.zeros(0))

    @property
    def reduced_chi_square(self) -> float:
        """``chi_square / degrees_of_freedom`` (NaN without degrees of freedom)."""
        dof = self.degrees_of_freedom
        return self.chi_square / dof if dof > 0 else math.nan

    def summary(self) -> str:
        """A printable table of the fitted values with their uncertainties."""
        lines = [
            f"calibration of the {self.model} model against {self.data.path} "
            f"({self.data.frequency.size} frequencies, {self.data.motion} motion)",
        ]
        for name, start, value, sd in zip(
            self.names, self.initial, self.values, self.uncertainties, strict=True
        ):
            lines.append(f"  {name:24s} {value:.5g} +- {sd:.2g}   (from {start:.5g})")
        weights = "given uncertainties" if self.absolute_weights else "default weights, scaled"
        lines.append(
            f"  chi-square {self.chi_square:.4g} for {self.degrees_of_freedom} degrees of "
            f"freedom (reduced {self.reduced_chi_square:.3g}; {weights})"
        )
        if len(self.names) > 1:
            pairs = [
                f"{self.names[i]}/{self.names[j]} {self.correlation[i, j]:+.2f}"
                for i in range(len(self.names))
                for j in range(i + 1, len(self.names))
            ]
            lines.append("  correlation: " + ", ".join(pairs))
        lines.append(
            f"  {self.evaluations} model sweeps in {self.elapsed:.1f} s; "
            f"{'converged' if self.success else 'NOT converged'}: {self.message}"
        )
        return "\n".join(lines)


def _responses(
    rows: Sequence[Any], motion: str
) -> tuple[np.ndarray, np.ndarray]:
    """Amplitudes and phases of the model results for the measured motion."""
    amplitude = np.array([getattr(r.response, f"{motion}_amplitude") for r in rows])
    phase = np.array([getattr(r.response, f"{motion}_phase_deg") for r in rows])
    return amplitude, phase


def model_curve(
    case: BuoyCase,
    settings: SweepSettings,
    frequencies: Sequence[float],
    *,
    model: str = "particle",
    motion: str = "absolute",
    pool: Any = None,
) -> tuple[np.ndarray, np.ndarray]:
    """The model's steady amplitude and phase at each frequency (runs in ``pool`` if given).

    Returns:
        ``(amplitudes in m, phases in degrees)`` of the ``motion`` (absolute or relative).

    Raises:
        ConvergenceError: if a run fails (the message names the frequency and the error).
    """
    if pool is None:
        rows = [run_task(case, settings, model, float(f)) for f in frequencies]
    else:
        futures = [pool.submit(run_task, case, settings, model, float(f)) for f in frequencies]
        rows = [f.result() for f in futures]
    for r in rows:
        if r.response is None:
            raise ConvergenceError(
                f"the {model} model failed at {r.frequency:g} Hz with {_describe(case)}: "
                f"{r.error}",
                frequency=r.frequency,
            )
    return _responses(rows, motion)


def _describe(case: BuoyCase) -> str:
    return ", ".join(f"{n} = {getattr(case, n):.6g}" for n in CALIBRATABLE)


def calibrate(
    data: Measurements,
    *,
    case: BuoyCase | None = None,
    settings: SweepSettings | None = None,
    parameters: Sequence[str] = ("drag_coefficient", "added_mass_coefficient"),
    model: str = "particle",
    workers: int | None = None,
    scheduler: str | None = None,
    max_evaluations: int = 60,
    curve_points: int = 21,
    progress: bool | Callable[[str], None] = True,
    stream: IO[str] | None = None,
) -> Calibration:
    """Fit ``parameters`` of ``case`` so that ``model`` reproduces the measured curves.

    Arguments:
        data: measured amplitude and phase over frequency
            (:func:`vinculo.buoy.data.read_measurements`).
        case: the starting case (default: the study's defaults).
        settings: run settings (step, settling and fit periods); its frequency range is unused.
        parameters: which of :data:`CALIBRATABLE` to fit.
        model: one of :data:`~vinculo.buoy.study.MODELS`.
        workers: local worker processes (default: one per CPU).
        scheduler: a Dask distributed scheduler address to run on instead.
        max_evaluations: most model sweeps the whole calibration runs: the starting point, the
            optimiser's steps, the forward differences of its Jacobian (one sweep per parameter)
            and the fitted curve (one sweep when ``curve_points > 0``) all count. When the budget
            runs out, the best point found is returned with ``success`` False. At least
            ``len(parameters) + 1`` (+1 with a curve) are needed for one Jacobian.
        curve_points: frequencies of the fitted curve drawn over the data, evenly spread over
            the measured range (one more sweep; 0: none).
        progress: True prints one line per model sweep on ``stream`` (standard error); a
            callable receives each line.
        stream: where progress goes.

    Returns:
        The :class:`Calibration`.

    Raises:
        InvalidInputError: an unknown or repeated parameter, an unknown model, fewer measured
            values than parameters, or a non-positive starting value of a parameter that must be
            positive.
        ConvergenceError: a model run failed during the fit.
        SchedulerError: the scheduler cannot be reached.
    """
    started = time.perf_counter()
    case = case if case is not None else BuoyCase()
    settings = settings if settings is not None else SweepSettings()
    names = list(parameters)
    for name in names:
        if name not in CALIBRATABLE:
            raise InvalidInputError(
                f"cannot calibrate {name!r}: choose from {', '.join(CALIBRATABLE)}",
                name="parameters",
                value=name,
            )
    if len(set(names)) != len(names) or not names:
        raise InvalidInputError(
            f"parameters must be distinct and at least one, got {names!r}",
            name="parameters",
            value=names,
        )
    if model not in MODELS:
        raise InvalidInputError(
            f"unknown model {model!r}: choose from {', '.join(MODELS)}", name="model", value=model
        )
    m = 2 * data.frequency.size
    if m <= len(names):
        raise InvalidInputError(
            f"{data.frequency.size} measured frequencies give {m} values, not enough to fit "
            f"{len(names)} parameters with uncertainties; measure more frequencies",
            name="data",
            value=data.path,
        )
    curve_sweeps = 1 if curve_points > 0 else 0
    needed = len(names) + 1 + curve_sweeps
    if not (isinstance(max_evaluations, int) and max_evaluations >= needed):
        raise InvalidInputError(
            f"max_evaluations = {max_evaluations!r} model sweeps is too few: fitting "
            f"{len(names)} parameter(s) needs at least {needed} (the starting point, one per "
            f"parameter for the Jacobian" + (", and the fitted curve)" if curve_sweeps else ")")
            + f"; give max_evaluations >= {needed}",
            name="max_evaluations",
            value=max_evaluations,
        )
    budget = max_evaluations - curve_sweeps
    initial = np.array([float(getattr(case, n)) for n in names])
    for name, value in zip(names, initial, strict=True):
        if name in ("string_length", "amplitude") and value <= 0.0:
            raise InvalidInputError(
                f"the starting {name} must be positive, got {value!r}", name=name, value=value
            )
    given = ~np.isnan(data.amplitude_sd) & ~np.isnan(data.phase_sd)
    absolute_weights = bool(np.all(given))
    amplitude_sd = np.where(
        np.isnan(data.amplitude_sd),
        DEFAULT_AMPLITUDE_FRACTION * float(np.max(data.amplitude)),
        data.amplitude_sd,
    )
    phase_sd = np.where(np.isnan(data.phase_sd), DEFAULT_PHASE_SD, data.phase_sd)
    stream = stream if stream is not None else sys.stderr
    log: list[str] = []

    def say(line: str) -> None:
        log.append(line)
        if callable(progress):
            progress(line)
        elif progress:
            stream.write(line + "\n")
            stream.flush()

    # Parameters are optimised in units of their starting values (zero starts: absolute).
    scale = np.where(initial > 0.0, initial, 1.0)
    cache: dict[tuple[float, ...], tuple[np.ndarray, np.ndarray]] = {}

    def case_at(x: np.ndarray) -> BuoyCase:
        return dataclasses.replace(case, **dict(zip(names, (x * scale).tolist(), strict=True)))

    # Every sweep goes through evaluate(), which refuses to run more than the budget; the
    # Jacobian is computed here (forward differences through evaluate) rather than by scipy,
    # whose max_nfev does not count the sweeps of its finite differences.
    costs: dict[tuple[float, ...], tuple[float, np.ndarray]] = {}
    jacobians: list[tuple[np.ndarray, np.ndarray]] = []

    with open_executor(_workers(workers), scheduler) as (pool, how):

        def evaluate(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
            key = tuple(np.round(x, 15))
            if key not in cache:
                if len(cache) >= budget:
                    raise _OutOfSweeps
                trial = case_at(x)
                cache[key] = model_curve(
                    trial, settings, data.frequency, model=model, motion=data.motion, pool=pool
                )
                values = ", ".join(f"{n} = {v:.6g}" for n, v in zip(names, x * scale, strict=True))
                say(f"calibrate: sweep {len(cache)} of at most {budget} ({how}): {values}")
            return cache[key]

        def residuals(x: np.ndarray) -> np.ndarray:
            amplitude, phase = evaluate(x)
            r = np.concatenate([
                (amplitude - data.amplitude) / amplitude_sd,
                wrap_phase_difference(phase - data.phase_deg) / phase_sd,
            ])
            costs[tuple(np.round(x, 15))] = (float(np.sum(r**2)), np.array(x, dtype=float))
            return r

        def jacobian(x: np.ndarray) -> np.ndarray:
            f0 = residuals(x)
            columns = []
            for j in range(x.size):
                shifted = np.array(x, dtype=float)
                shifted[j] += DIFF_STEP * max(1.0, abs(float(x[j])))
                columns.append((residuals(shifted) - f0) / (shifted[j] - x[j]))
            jac = np.column_stack(columns)
            jacobians.append((np.array(x, dtype=float), jac))
            return jac

        x0 = initial / scale
        start_amplitude, start_phase = evaluate(x0)
        try:
            result = least_squares(
                residuals,
                x0,
                jac=jacobian,
                bounds=(np.zeros_like(x0), np.full_like(x0, np.inf)),
                max_nfev=budget,
                x_scale=1.0,
            )
            best, jac = result.x, result.jac
            success, message = bool(result.success), str(result.message)
        except _OutOfSweeps:
            best = min(costs.values(), key=lambda item: item[0])[1]
            jac = jacobians[-1][1] if jacobians else None
            success = False
            message = (
                f"stopped after {len(cache)} model sweeps (max_evaluations = "
                f"{max_evaluations}); the best point found is reported, with uncertainties "
                f"from the last Jacobian"
            )
        if jac is None:  # pragma: no cover - the budget check above leaves room for one
            raise InvalidInputError(
                "the sweep budget ran out before a Jacobian; raise max_evaluations",
                name="max_evaluations", value=max_evaluations,
            )
        fitted_amplitude, fitted_phase = evaluate(best)
        fitted_residuals = residuals(best)
        curve_frequency = np.linspace(
            float(np.min(data.frequency)), float(np.max(data.frequency)), max(curve_points, 0)
        )
        curve_amplitude, curve_phase = (
            model_curve(case_at(best), settings, curve_frequency, model=model,
                        motion=data.motion, pool=pool)
            if curve_points > 0
            else (np.zeros(0), np.zeros(0))
        )
    values = best * scale
    chi_square = float(np.sum(fitted_residuals**2))
    dof = m - len(names)
    # Covariance of x from the weighted Jacobian, by SVD (robust to a near-singular J).
    _, singular, vt = np.linalg.svd(jac, full_matrices=False)
    keep = singular > singular[0] * 1e-12
    covariance_x = (vt[keep].T / singular[keep] ** 2) @ vt[keep]
    if not absolute_weights:
        covariance_x *= chi_square / dof
    covariance = covariance_x * np.outer(scale, scale)
    sd = np.sqrt(np.diag(covariance))
    with np.errstate(invalid="ignore", divide="ignore"):
        correlation = covariance / np.outer(sd, sd)
    return Calibration(
        names=names,
        initial=initial,
        values=values,
        uncertainties=sd,
        correlation=correlation,
        chi_square=chi_square,
        degrees_of_freedom=dof,
        absolute_weights=absolute_weights,
        case=case_at(best),
        model=model,
        data=data,
        fitted_amplitude=fitted_amplitude,
        fitted_phase_deg=fitted_phase,
        initial_amplitude=start_amplitude,
        initial_phase_deg=start_phase,
        evaluations=len(cache) + curve_sweeps,
        success=success,
        message=message,
        elapsed=time.perf_counter() - started,
        log=log,
        curve_frequency=curve_frequency,
        curve_amplitude=curve_amplitude,
        curve_phase_deg=curve_phase,
    )


class _OutOfSweeps(Exception):
    """Raised inside the optimiser when the next model sweep would exceed the budget."""


def _workers(workers: int | None) -> int:
    """The worker count (default: one per CPU), validated."""
    count = (os.cpu_count() or 1) if workers is None else workers
    if not (isinstance(count, int) and count >= 1):
        raise InvalidInputError(
            f"workers must be an integer >= 1, got {workers!r}", name="workers", value=workers
        )
    return count


def wrap_phase_difference(difference: np.ndarray) -> np.ndarray:
    """Phase differences in degrees, wrapped to (-180, 180]."""
    return 180.0 - np.mod(180.0 - np.asarray(difference, dtype=np.float64), 360.0)
