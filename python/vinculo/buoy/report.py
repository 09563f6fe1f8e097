"""Files and plots of the buoy study: CSV tables of every plotted number, the parameters with
their sources, the figures of the study (time histories, amplitude and phase against frequency)
and a printed summary."""

from __future__ import annotations

import csv
import os
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from vinculo.buoy.calibration import Calibration
from vinculo.buoy.case import ASSUMPTIONS
from vinculo.buoy.data import Measurements
from vinculo.buoy.harmonic import PHASE_CONVENTION
from vinculo.buoy.parameter_study import ParameterStudy
from vinculo.buoy.reference import OneDofModel, TwoDofModel
from vinculo.buoy.study import LABELS, MODELS, StudyResult

__all__ = ["plot_parameter_study", "summary", "write_calibration", "write_report"]

#: Most curves a parameter-study plot draws (the CSV holds every run).
_MAX_CURVES = 12

_STYLE = {
    "particle": {"color": "C0", "marker": "o", "linestyle": "-"},
    "two-dof": {"color": "C1", "marker": "", "linestyle": "--"},
    "one-dof": {"color": "C2", "marker": "", "linestyle": ":"},
}
_RECORD_MARKERS = {"particle": "o", "two-dof": "s", "one-dof": "^"}
_FIELDS = [
    "tank_amplitude",
    "absolute_amplitude",
    "absolute_ratio",
    "absolute_phase_deg",
    "relative_amplitude",
    "relative_ratio",
    "relative_phase_deg",
    "settling",
    "residual_rms",
]


def summary(study: StudyResult) -> str:
    """A printable summary: linear natural frequencies and, per model, the resonance frequency
    and peak amplitude of the relative motion, plus the failures."""
    case = study.case
    lines = [
        f"buoy study: D = {case.diameter} m, rho_s = {case.sphere_density} kg/m^3, string "
        f"{case.string_length} m ({case.attachment}), Cd = {case.drag_coefficient}, "
        f"Ca = {case.added_mass_coefficient}, X0 = {case.amplitude * 1e3:g} mm (assumed)",
        f"linear natural frequency: 1-DOF {OneDofModel(case).natural_frequency():.4f} Hz; "
        f"2-DOF {', '.join(f'{f:.4f}' for f in TwoDofModel(case).natural_frequencies())} Hz",
    ]
    records = sorted({(r.frequency, r.record) for r in study.results if r.record is not None})
    if records:
        lines[0] = lines[0].split(", X0 =")[0]
        lines.append(
            f"tank driven by {len(records)} measured record(s): "
            + ", ".join(f"{name} ({f:.4f} Hz)" for f, name in records)
        )
        for r in study.results:
            if r.response is not None:
                lines.append(
                    f"{LABELS[r.model]:48s} {r.record} at {r.frequency:.4f} Hz: tank "
                    f"{r.response.tank_amplitude * 1e3:.3f} mm, relative amplitude "
                    f"{r.response.relative_amplitude * 1e3:.3f} mm, phase "
                    f"{r.response.relative_phase_deg:.1f} deg"
                )
    for model in MODELS if not records else ():
        runs = study.of(model)
        if not runs:
            continue
        f, peak = study.resonance(model)
        ok = sum(r.response is not None for r in runs)
        lines.append(
            f"{LABELS[model]:48s} resonance {f:.4f} Hz, peak relative amplitude "
            f"{peak * 1e3:.3f} mm ({peak / case.amplitude:.3f} X0); {ok}/{len(runs)} runs ok"
        )
    for r in study.failures():
        source = f" ({r.record})" if r.record else ""
        lines.append(f"FAILED {r.model} at {r.frequency:g} Hz{source}: {r.error}")
    lines.append(f"{len(study.results)} runs in {study.elapsed:.1f} s on {study.workers} workers")
    return "\n".join(lines)


def _write_parameters(study: StudyResult, path: Path) -> None:
    case, settings = study.case, study.settings
    derived = {
        "radius": (case.radius, "m"),
        "volume": (case.volume, "m^3"),
        "frontal_area": (case.frontal_area, "m^2"),
        "sphere_mass": (case.sphere_mass, "kg"),
        "displaced_mass": (case.displaced_mass, "kg"),
        "added_mass": (case.added_mass, "kg"),
        "centre_inertia": (case.centre_inertia, "kg m^2"),
        "pendulum_length": (case.pendulum_length, "m"),
    }
    with path.open("w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["parameter", "value", "unit", "source"])
        for name, value in case.to_dict().items():
            if name in ASSUMPTIONS:
                source = f"ASSUMPTION: {ASSUMPTIONS[name]}"
            elif name in ("string_beads", "string_mass"):
                source = "option"
            else:
                source = "paper"
            w.writerow([name, value, _UNITS.get(name, ""), source])
        for name, (value, unit) in derived.items():
            w.writerow([name, value, unit, "derived"])
        for name, value in settings.to_dict().items():
            w.writerow([f"sweep.{name}", value, _UNITS.get(name, ""), "sweep setting"])


_UNITS = {
    "diameter": "m",
    "sphere_density": "kg/m^3",
    "fluid_density": "kg/m^3",
    "string_length": "m",
    "gravity": "m/s^2",
    "amplitude": "m",
    "ramp_periods": "periods",
    "string_mass": "kg",
    "tank_size": "m",
    "f_min": "Hz",
    "f_max": "Hz",
    "dt": "s",
    "settle_periods": "periods",
    "fit_periods": "periods",
}


def _write_sweep(study: StudyResult, data: Measurements | None, path: Path) -> None:
    with path.open("w", newline="") as f:
        w = csv.writer(f)
        w.writerow(
            ["model", "frequency_hz", *_FIELDS, "window_start_s", "window_end_s", "error",
             "tank_record"]
        )
        for r in study.results:
            record = r.record or ""
            if r.response is None:
                w.writerow([r.model, r.frequency, *([""] * (len(_FIELDS) + 2)), r.error, record])
                continue
            values = [getattr(r.response, k) for k in _FIELDS]
            w.writerow([r.model, r.frequency, *values, *r.response.window, "", record])
        if data is not None:
            for fr, amp, ph in zip(data.frequency, data.amplitude, data.phase_deg, strict=True):
                row = dict.fromkeys(_FIELDS, "")
                row[f"{data.motion}_amplitude"] = amp
                row[f"{data.motion}_phase_deg"] = ph
                w.writerow(["measured", fr, *row.values(), "", "", "", ""])


def _write_histories(study: StudyResult, path: Path) -> None:
    with path.open("w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["model", "frequency_hz", "time_s", "tank_m", "buoy_m", "relative_m",
                    "tension_n", "tank_record"])
        for r in study.results:
            if r.history is None:
                continue
            h = r.history
            columns = (h["time"], h["tank"], h["buoy"], h["relative"], h["tension"])
            for row in zip(*columns, strict=True):
                w.writerow([r.model, r.frequency, *(f"{x:.9g}" for x in row), r.record or ""])


def write_report(
    study: StudyResult, output: Path, data: Measurements | None = None
) -> list[Path]:
    """Write the study's tables and figures into ``output``.

    Files: ``parameters.csv`` (every parameter with its unit and source; assumptions marked),
    ``sweep.csv`` (amplitude and phase of every model at every frequency, fit windows, errors, and
    the measurements if given), ``histories.csv`` (the kept time histories),
    ``history_<f>Hz.png`` (figs. 11-13; ``history_<record>.png`` for a measured tank record),
    ``amplitude.png`` (fig. 14), ``phase.png`` (fig. 15), ``summary.txt``.

    Arguments:
        study: the result of :func:`vinculo.buoy.study.run_study`.
        output: the folder (created if missing).
        data: the user's measurements, plotted beside the models.

    Returns:
        The paths written.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    output.mkdir(parents=True, exist_ok=True)
    written = []
    for name, writer in (
        ("parameters.csv", lambda p: _write_parameters(study, p)),
        ("sweep.csv", lambda p: _write_sweep(study, data, p)),
        ("histories.csv", lambda p: _write_histories(study, p)),
    ):
        writer(output / name)
        written.append(output / name)
    x0_mm = study.case.amplitude * 1e3
    measured_tank = any(r.record is not None for r in study.results)

    # Figs. 11-13: time histories, one figure per frequency (or per measured record).
    by_excitation: dict[tuple[float, str], list] = {}
    for r in study.results:
        if r.history is not None:
            by_excitation.setdefault((round(r.frequency, 9), r.record or ""), []).append(r)
    for (f, record), runs in sorted(by_excitation.items()):
        fig, ax = plt.subplots(figsize=(9, 4))
        first = runs[0].history
        ax.plot(first["time"], first["tank"] * 1e3, color="0.5", lw=1.0, label="tank")
        for r in runs:
            ax.plot(r.history["time"], r.history["buoy"] * 1e3, lw=1.0,
                    color=_STYLE[r.model]["color"], linestyle=_STYLE[r.model]["linestyle"],
                    label=f"buoy: {LABELS[r.model]}" + (" (FAILED)" if r.error else ""))
        ax.set_xlabel("time (s)")
        ax.set_ylabel("horizontal displacement (mm)")
        if record:
            ax.set_title(f"buoy and tank displacement, tank record {record} ({f:.4g} Hz)")
            path = output / f"history_{Path(record).stem}.png"
        else:
            ax.set_title(f"buoy and tank displacement at {f:g} Hz (X0 = {x0_mm:g} mm, assumed)")
            path = output / f"history_{f:.2f}Hz.png"
        ax.legend(fontsize=8, loc="upper right")
        ax.grid(alpha=0.3)
        fig.tight_layout()
        fig.savefig(path, dpi=120)
        plt.close(fig)
        written.append(path)

    # Figs. 14-15: amplitude and phase against frequency, absolute and relative to the tank.
    for kind, unit in (("amplitude", "mm"), ("phase", "deg")):
        fig, axes = plt.subplots(2, 1, figsize=(8, 7), sharex=True)
        for ax, motion in zip(axes, ("absolute", "relative"), strict=True):
            quantity = f"{motion}_amplitude" if kind == "amplitude" else f"{motion}_phase_deg"
            scale = 1e3 if kind == "amplitude" else 1.0
            for model in MODELS:
                f, y = study.curve(model, quantity)
                if len(f):
                    style = dict(_STYLE[model])
                    if measured_tank:  # a few scattered records: mark every point
                        style["marker"] = style["marker"] or _RECORD_MARKERS[model]
                    ax.plot(f, y * scale, label=LABELS[model], **style, ms=4)
            if data is not None and data.motion == motion:
                y = data.amplitude * 1e3 if kind == "amplitude" else data.phase_deg
                ax.plot(data.frequency, y, "ks", ms=5, label=LABELS["measured"])
            what = "buoy displacement" if motion == "absolute" else "buoy relative to tank"
            ax.set_ylabel(f"{kind} ({unit})")
            ax.set_title(f"{what}", fontsize=10)
            ax.grid(alpha=0.3)
            ax.legend(fontsize=8)
        axes[-1].set_xlabel("excitation frequency (Hz)")
        tank = "measured tank records" if measured_tank else f"X0 = {x0_mm:g} mm, assumed"
        title = (
            f"amplitude of the buoy's horizontal displacement ({tank})"
            if kind == "amplitude"
            else f"phase: {PHASE_CONVENTION}"
        )
        fig.suptitle(title, fontsize=10)
        fig.tight_layout()
        path = output / f"{kind}.png"
        fig.savefig(path, dpi=120)
        plt.close(fig)
        written.append(path)
    text = summary(study)
    (output / "summary.txt").write_text(text + "\n")
    written.append(output / "summary.txt")
    return written


def _replace_atomically(path: Path, write: Callable[[Path], None]) -> Path:
    """Write ``path`` through a temporary file in the same folder, renamed when complete, so
    that an interrupted write never leaves a file that looks finished."""
    temporary = path.with_name(f".{path.name}.partial")
    try:
        write(temporary)
        os.replace(temporary, path)
    finally:
        temporary.unlink(missing_ok=True)
    return path


def plot_parameter_study(study: ParameterStudy, path: Path) -> Path | None:
    """Relative amplitude and phase against frequency, one curve per combination of the other
    parameters (and model), for a study with a frequency axis and successful runs.

    Arguments:
        study: the result of :func:`vinculo.buoy.parameter_study.run_parameter_study`.
        path: the PNG file.

    Returns:
        The path written, or None when there is nothing to plot.
    """
    ok = [r for r in study.rows if r.status == "ok"]
    if "frequency" not in study.names or not ok:
        return None
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    others = [n for n in study.names if n != "frequency"]
    curves: dict[tuple[Any, ...], list[Any]] = {}
    for r in ok:
        curves.setdefault((r.model, *(r.parameters[n] for n in others)), []).append(r)
    fig, axes = plt.subplots(2, 1, figsize=(8, 7), sharex=True)
    shown = sorted(curves.items(), key=lambda kv: tuple(map(str, kv[0])))[:_MAX_CURVES]
    for key, rows in shown:
        rows.sort(key=lambda r: r.parameters["frequency"])
        f = [r.parameters["frequency"] for r in rows]
        label = ", ".join(
            [key[0]] + [f"{n} = {v:g}" if isinstance(v, float) else f"{n} = {v}"
                        for n, v in zip(others, key[1:], strict=True)]
        )
        axes[0].plot(f, [r.results["relative_amplitude"] * 1e3 for r in rows], "o-", ms=3,
                     label=label)
        axes[1].plot(f, [r.results["relative_phase_deg"] for r in rows], "o-", ms=3)
    axes[0].set_ylabel("relative amplitude (mm)")
    axes[1].set_ylabel("relative phase (deg)")
    axes[1].set_xlabel("excitation frequency (Hz)")
    for ax in axes:
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=7)
    more = len(curves) - len(shown)
    fig.suptitle(
        f"parameter study: {len(ok)} runs" + (f" ({more} more curves not drawn)" if more else ""),
        fontsize=10,
    )
    fig.tight_layout()
    _replace_atomically(path, lambda p: fig.savefig(p, dpi=120, format="png"))
    plt.close(fig)
    return path


def write_calibration(result: Calibration, output: Path) -> list[Path]:
    """Write a calibration's tables, plot and summary into ``output``.

    Files: ``calibration.csv`` (each parameter's start, fitted value and uncertainty),
    ``calibration_curves.csv`` (the data with their weights and the starting and fitted model at
    each measured frequency), ``calibration_fitted_curve.csv`` (the fitted model on an even
    frequency grid, when computed), ``calibration.png`` (both over the data, with error bars),
    ``calibration.txt`` (the printed summary). Each file is written whole or not at all.

    Returns:
        The paths written.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    output.mkdir(parents=True, exist_ok=True)

    def parameters(path: Path) -> None:
        with path.open("w", newline="") as f:
            w = csv.writer(f)
            w.writerow(["parameter", "initial", "fitted", "standard_uncertainty"])
            for row in zip(result.names, result.initial, result.values, result.uncertainties,
                           strict=True):
                w.writerow([row[0], *(repr(float(x)) for x in row[1:])])

    data = result.data
    motion = data.motion

    def curves(path: Path) -> None:
        with path.open("w", newline="") as f:
            w = csv.writer(f)
            w.writerow([
                "frequency_hz", f"measured_{motion}_amplitude_m", "amplitude_sd_m",
                f"measured_{motion}_phase_deg", "phase_sd_deg", "initial_amplitude_m",
                "initial_phase_deg", "fitted_amplitude_m", "fitted_phase_deg",
            ])
            columns = (data.frequency, data.amplitude, data.amplitude_sd, data.phase_deg,
                       data.phase_sd, result.initial_amplitude, result.initial_phase_deg,
                       result.fitted_amplitude, result.fitted_phase_deg)
            for row in zip(*columns, strict=True):
                w.writerow([repr(float(x)) for x in row])

    def fitted_curve(path: Path) -> None:
        with path.open("w", newline="") as f:
            w = csv.writer(f)
            w.writerow(["frequency_hz", f"fitted_{motion}_amplitude_m", "fitted_phase_deg"])
            for row in zip(result.curve_frequency, result.curve_amplitude,
                           result.curve_phase_deg, strict=True):
                w.writerow([repr(float(x)) for x in row])

    fig, axes = plt.subplots(2, 1, figsize=(8, 7), sharex=True)
    order = np.argsort(data.frequency)
    f = data.frequency[order]
    for ax, measured, sd, start, fitted, curve, scale, unit in (
        (axes[0], data.amplitude, data.amplitude_sd, result.initial_amplitude,
         result.fitted_amplitude, result.curve_amplitude, 1e3, "amplitude (mm)"),
        (axes[1], data.phase_deg, data.phase_sd, result.initial_phase_deg,
         result.fitted_phase_deg, result.curve_phase_deg, 1.0, "phase (deg)"),
    ):
        errors = np.nan_to_num(sd[order]) * scale
        ax.errorbar(f, measured[order] * scale, yerr=errors, fmt="ks", ms=4, capsize=2,
                    label=LABELS["measured"])
        ax.plot(f, start[order] * scale, ":", color="0.5", label="model, starting values")
        if len(curve):
            ax.plot(result.curve_frequency, curve * scale, "-", color="C0", lw=1.2,
                    label="model, fitted")
            ax.plot(f, fitted[order] * scale, "o", color="C0", ms=3)
        else:
            ax.plot(f, fitted[order] * scale, "o-", color="C0", ms=3, label="model, fitted")
        ax.set_ylabel(f"{motion} {unit}")
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=8)
    axes[1].set_xlabel("excitation frequency (Hz)")
    fitted_text = ", ".join(
        f"{n} = {v:.4g} +- {s:.2g}"
        for n, v, s in zip(result.names, result.values, result.uncertainties, strict=True)
    )
    fig.suptitle(f"calibration of the {result.model} model: {fitted_text}", fontsize=9)
    fig.tight_layout()
    written = [
        _replace_atomically(output / "calibration.csv", parameters),
        _replace_atomically(output / "calibration_curves.csv", curves),
        *([_replace_atomically(output / "calibration_fitted_curve.csv", fitted_curve)]
          if len(result.curve_frequency) else []),
        _replace_atomically(
            output / "calibration.png", lambda p: fig.savefig(p, dpi=120, format="png")
        ),
        _replace_atomically(
            output / "calibration.txt", lambda p: p.write_text(result.summary() + "\n")
        ),
    ]
    plt.close(fig)
    return written
