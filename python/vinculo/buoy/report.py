"""Files and plots of the buoy study: CSV tables of every plotted number, the parameters with
their sources, the figures of the study (time histories, amplitude and phase against frequency)
and a printed summary."""

from __future__ import annotations

import csv
import dataclasses
import math
import os
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from vinculo.buoy.calibration import Calibration
from vinculo.buoy.case import ASSUMPTIONS, PAPER_VALUES, UNITS, BuoyCase
from vinculo.buoy.data import Measurements
from vinculo.buoy.harmonic import PHASE_CONVENTION
from vinculo.buoy.parameter_study import ParameterStudy
from vinculo.buoy.reference import OneDofModel, TwoDofModel
from vinculo.buoy.study import LABELS, MODELS, StudyResult

__all__ = [
    "parameter_source",
    "plot_parameter_study",
    "stokes_damping_ratio",
    "summary",
    "write_calibration",
    "write_report",
]

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


def summary(study: StudyResult, sources: dict[str, str] | None = None) -> str:
    """A printable summary: linear natural frequencies and, per model, the resonance (refined,
    with the digits its uncertainty leaves), the steady-state check, the closed-tank assumption
    and the failures.

    Arguments:
        study: the result of :func:`vinculo.buoy.study.run_study`.
        sources: where parameters came from (see :func:`parameter_source`).

    Returns:
        The text, one line per item.
    """
    case = study.case
    amplitude_source = parameter_source("amplitude", case.amplitude, sources or {}).split(":")[0]
    lines = [
        f"buoy study: D = {case.diameter} m, rho_s = {case.sphere_density} kg/m^3, string "
        f"{case.string_length} m ({case.attachment}), Cd = {case.drag_coefficient}, "
        f"Ca = {case.added_mass_coefficient}, X0 = {case.amplitude * 1e3:g} mm "
        f"({amplitude_source.lower()})",
        f"linear natural frequency: 1-DOF {OneDofModel(case).natural_frequency():.4f} Hz; "
        f"2-DOF {', '.join(f'{f:.4f}' for f in TwoDofModel(case).natural_frequencies())} Hz",
    ]
    if case.viscous_force == "stokes-layer":
        lines.append(_stokes_line(case))
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
        ok = sum(r.response is not None for r in runs)
        refined = study.resonances.get(model)
        if refined is not None:
            found = refined.describe()
            peak = refined.peak
        else:
            f, peak = study.resonance(model)
            found = f"{f:.4f} Hz, peak relative amplitude {peak * 1e3:.3f} mm (sweep's estimate)"
        lines.append(
            f"{LABELS[model]:48s} resonance {found}; {peak / case.amplitude:.3f} X0; "
            f"{ok}/{len(runs)} runs ok"
        )
    if study.resonances and not records:
        lines.append(
            "resonance: frequency of the peak of the relative amplitude, refined by rounds of "
            "three fresh runs around the vertex of a parabola (each round a tenth of the "
            "spacing of the one before) until it moves by less than "
            f"{study.settings.resonance_tolerance:g} Hz; the frequency's +- is the last round's "
            "move, the peak's the larger of its last change and the runs' amplitude change "
            "between their last two fit windows"
        )
    lines.extend(study.notes)
    settings = study.settings
    unconverged = study.unconverged()
    checked = [r for r in study.results if r.response is not None]
    if checked and not records:
        extended = [r for r in checked if r.response.periods > settings.run_periods(0) + 1e-6]
        lines.append(
            f"steady state: {len(checked) - len(unconverged)}/{len(checked)} runs converged "
            f"(amplitude within {settings.amplitude_tolerance:g} relative and phase within "
            f"{settings.phase_tolerance:g} deg between the last two windows of "
            f"{settings.fit_periods} periods); {len(extended)} run(s) extended beyond "
            f"{settings.run_periods(0):g} periods"
        )
    for r in unconverged:
        source = f" ({r.record})" if r.record else ""
        lines.append(
            f"NOT CONVERGED {r.model} at {r.frequency:g} Hz{source} after "
            f"{r.response.periods:.0f} periods: amplitude changed by {r.response.settling:.2g} "
            f"(relative), phase by {r.response.phase_change_deg:.2g} deg between the last two "
            f"windows"
        )
    lines.append(
        f"closed tank assumed: the water moves with the tank as a rigid body (no free surface); "
        f"an open {case.tank_size[0]:g} m tank filled to {case.tank_size[2]:g} m would slosh "
        f"first at {case.sloshing_frequency():.3f} Hz"
        + (
            ", inside the sweep"
            if not records and settings.f_min <= case.sloshing_frequency() <= settings.f_max
            else ""
        )
    )
    for r in study.failures():
        source = f" ({r.record})" if r.record else ""
        lines.append(f"FAILED {r.model} at {r.frequency:g} Hz{source}: {r.error}")
    lines.append(f"{len(study.results)} runs in {study.elapsed:.1f} s on {study.workers} workers")
    return "\n".join(lines)


def _stokes_line(case: BuoyCase) -> str:
    """The Stokes-layer terms at the 2-DOF swing frequency, with their damping ratio."""
    frequency = float(min(f for f in TwoDofModel(case).natural_frequencies() if f > 0.0))
    damping, mass = case.stokes_layer(frequency)
    ratio = stokes_damping_ratio(case)
    return (
        f"Stokes-layer force on: at {frequency:.3f} Hz damping {damping:.4g} N s/m and added "
        f"mass {mass * 1e3:.3g} g (damping ratio {ratio:.4f}); evaluated at each run's "
        f"frequency"
    )


def stokes_damping_ratio(case: BuoyCase) -> float:
    """Damping ratio of the rigid pendulum's swing from the Stokes layer alone.

    The linearised 1-DOF pendulum (:class:`vinculo.buoy.reference.OneDofModel`, the rod's
    ``L``, ``I``) with the Stokes layer at its natural frequency w_n reads
    ``((m + m_v) L^2 + I) th'' + c L^2 th' + mu g L th = 0``, so
    ``zeta = c L^2 / (2 ((m + m_v) L^2 + I) w_n)``, with w_n including m_v (one fixed-point
    pass: m_v changes w_n by about 1.5 %, and w_n changes m_v by half that).

    Arguments:
        case: the buoy case (its viscosity; ``viscous_force`` need not be on).

    Returns:
        The damping ratio.
    """
    pendulum = OneDofModel(case)
    length, inertia = pendulum.length, pendulum.inertia
    mu_g_l = (case.displaced_mass - case.sphere_mass) * case.gravity * length
    mass = case.sphere_mass + case.added_mass
    frequency = pendulum.natural_frequency()
    for _ in range(3):
        damping, viscous_mass = case.stokes_layer(frequency)
        inertia_total = (mass + viscous_mass) * length**2 + inertia
        frequency = math.sqrt(mu_g_l / inertia_total) / (2.0 * math.pi)
    return damping * length**2 / (2.0 * inertia_total * 2.0 * math.pi * frequency)


def parameter_source(name: str, value: Any, sources: dict[str, str]) -> str:
    """Where a case parameter's value comes from, for ``parameters.csv`` and the summary.

    ``sources[name]`` when the caller knows it (``"case file FILE"``, ``"option --name"``);
    otherwise ``"paper"`` when the value is the paper's (:data:`PAPER_VALUES`),
    ``"ASSUMPTION: why"`` when it is the default of a field the paper does not give
    (:data:`ASSUMPTIONS`), else ``"given"``. A value that is not the paper's says what the
    paper's is.

    Arguments:
        name: a field of :class:`BuoyCase`.
        value: its value.
        sources: known sources by field name.

    Returns:
        The text.
    """
    paper = PAPER_VALUES.get(name)
    is_paper = name in PAPER_VALUES and _same(value, paper)
    default = _DEFAULTS.get(name)
    if name in sources:
        origin = sources[name]
        if is_paper:
            return f"{origin} (the paper's value)"
        if name in PAPER_VALUES:
            return f"{origin} (the paper's value is {_show(paper)})"
        return origin
    if is_paper:
        return "paper"
    if name in ASSUMPTIONS and _same(value, default):
        return f"ASSUMPTION: {ASSUMPTIONS[name]}"
    if name in PAPER_VALUES:
        return f"given (the paper's value is {_show(paper)})"
    return "given"


_DEFAULTS = {f.name: f.default for f in dataclasses.fields(BuoyCase)}


def _same(a: Any, b: Any) -> bool:
    """Whether two parameter values are equal (tuples and lists alike)."""
    if isinstance(a, (tuple, list)) or isinstance(b, (tuple, list)):
        return list(a) == list(b)
    return bool(a == b)


def _show(value: Any) -> str:
    """A parameter value as the files print it."""
    if isinstance(value, (tuple, list)):
        return " x ".join(f"{v:g}" for v in value)
    return f"{value:g}" if isinstance(value, float) else str(value)


def _amplitude_note(study: StudyResult) -> str:
    """What the table amplitude used does to the string's swing, from the runs themselves."""
    case = study.case
    peak = max(
        (r.response.relative_amplitude for r in study.results if r.response is not None),
        default=math.nan,
    )
    if not math.isfinite(peak):
        return f"X0 = {case.amplitude * 1e3:g} mm (the paper does not report X0)"
    swing = math.degrees(math.asin(min(1.0, peak / case.pendulum_length)))
    return (
        f"X0 = {case.amplitude * 1e3:g} mm (the paper does not report X0): the largest relative "
        f"amplitude of the runs, {peak * 1e3:.1f} mm, swings the {case.pendulum_length:g} m "
        f"anchor-to-centre line by about {swing:.0f} deg"
    )


def _write_parameters(study: StudyResult, path: Path, sources: dict[str, str]) -> None:
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
            source = parameter_source(name, value, sources)
            if name == "amplitude":
                if source.startswith("ASSUMPTION"):
                    source = f"ASSUMPTION: {_amplitude_note(study)}"
                else:
                    source = f"{source}; {_amplitude_note(study)}"
            w.writerow([name, _show(value) if name == "tank_size" else value,
                        _unit(name), source])
        for name, (value, unit) in derived.items():
            w.writerow([name, value, unit, "derived"])
        w.writerow([
            "open_tank_sloshing_frequency", case.sloshing_frequency(), "Hz",
            "derived: first sloshing mode an open tank of this size, full, would have, "
            "f = sqrt(g k tanh(k h)) / (2 pi), k = pi / length, h = height; not modelled "
            "(closed tank assumed)",
        ])
        if case.viscous_force == "stokes-layer":
            w.writerow(["stokes_damping_ratio", stokes_damping_ratio(case), "",
                        "derived: Stokes layer alone, rigid pendulum at its natural frequency"])
        for name, value in settings.to_dict().items():
            source = sources.get(f"sweep.{name}", "sweep setting")
            w.writerow([f"sweep.{name}", value, _unit(name), source])


def _unit(name: str) -> str:
    """The unit of a case or sweep field for parameters.csv (case.UNITS; empty for a choice)."""
    unit = UNITS.get(name, "")
    return "" if unit.startswith("one of") else unit


def _write_sweep(study: StudyResult, data: Measurements | None, path: Path) -> None:
    with path.open("w", newline="") as f:
        w = csv.writer(f)
        w.writerow(
            ["model", "frequency_hz", *_FIELDS, "window_start_s", "window_end_s", "error",
             "tank_record", *_CHECK_FIELDS, "run"]
        )
        blank_check = [""] * len(_CHECK_FIELDS)
        for r in study.results:
            record = r.record or ""
            if r.response is None:
                w.writerow([r.model, r.frequency, *([""] * (len(_FIELDS) + 2)), r.error, record,
                            *blank_check, r.kind])
                continue
            values = [getattr(r.response, k) for k in _FIELDS]
            check = [getattr(r.response, k) for k in _CHECK_FIELDS]
            w.writerow([r.model, r.frequency, *values, *r.response.window, "", record, *check,
                        r.kind])
        if data is not None:
            for fr, amp, ph in zip(data.frequency, data.amplitude, data.phase_deg, strict=True):
                row = dict.fromkeys(_FIELDS, "")
                row[f"{data.motion}_amplitude"] = amp
                row[f"{data.motion}_phase_deg"] = ph
                w.writerow(["measured", fr, *row.values(), "", "", "", "", *blank_check,
                            "measured"])


#: Columns of sweep.csv from the steady-state check (see SteadyResponse).
_CHECK_FIELDS = ["phase_change_deg", "converged", "periods"]


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
    study: StudyResult,
    output: Path,
    data: Measurements | None = None,
    sources: dict[str, str] | None = None,
) -> list[Path]:
    """Write the study's tables and figures into ``output``.

    Files: ``parameters.csv`` (every parameter with its unit and source; assumptions marked),
    ``sweep.csv`` (amplitude and phase of every model at every frequency, fit windows, the
    steady-state check, why each run was made, errors, and the measurements if given),
    ``histories.csv`` (the kept time histories), ``history_<f>Hz.png`` (figs. 11-13;
    ``history_<record>.png`` for a measured tank record), ``amplitude.png`` (fig. 14),
    ``phase.png`` (fig. 15), ``summary.txt``.

    Arguments:
        study: the result of :func:`vinculo.buoy.study.run_study`.
        output: the folder (created if missing).
        data: the user's measurements, plotted beside the models.
        sources: where case parameters came from, by field name (``"case file FILE"``,
            ``"option --amplitude"``; sweep settings as ``"sweep.NAME"``); others are judged
            against the paper's values (:func:`parameter_source`).

    Returns:
        The paths written.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    sources = sources or {}
    output.mkdir(parents=True, exist_ok=True)
    written = []
    for name, writer in (
        ("parameters.csv", lambda p: _write_parameters(study, p, sources)),
        ("sweep.csv", lambda p: _write_sweep(study, data, p)),
        ("histories.csv", lambda p: _write_histories(study, p)),
    ):
        writer(output / name)
        written.append(output / name)

    by_excitation: dict[tuple[float, str], list] = {}
    for r in study.results:
        if r.history is not None:
            by_excitation.setdefault((round(r.frequency, 9), r.record or ""), []).append(r)
    for (f, record), runs in sorted(by_excitation.items()):
        fig = _history_figure(plt, study, f, record, runs)
        path = (
            output / f"history_{Path(record).stem}.png" if record
            else output / f"history_{f:.2f}Hz.png"
        )
        fig.savefig(path, dpi=120)
        plt.close(fig)
        written.append(path)
    for kind in ("amplitude", "phase"):
        fig = _response_figure(plt, study, kind, data)
        path = output / f"{kind}.png"
        fig.savefig(path, dpi=120)
        plt.close(fig)
        written.append(path)
    text = summary(study, sources)
    (output / "summary.txt").write_text(text + "\n")
    written.append(output / "summary.txt")
    return written


def _label(model: str, run: Any = None) -> str:
    """A model's legend label (marked when its run failed)."""
    failed = run is not None and run.error is not None
    return LABELS[model] + (" (FAILED)" if failed else "")


def _history_figure(plt: Any, study: StudyResult, f: float, record: str, runs: list) -> Any:
    """Figs. 11-13: the steady state (last periods, fit window shaded), the models' differences
    there, and the whole run in a smaller panel; the legend above the panels."""
    fig, (steady, difference, whole) = plt.subplots(
        3, 1, figsize=(10, 8.5), layout="constrained", height_ratios=(3.0, 1.5, 1.5)
    )
    first = runs[0].history
    window = next((r.response.window for r in runs if r.response is not None), None)
    # runs extended by the steady-state check end later: show up to the latest, shade each window
    windows = sorted({r.response.window for r in runs if r.response is not None})
    period = 1.0 / f
    t_last = max(float(r.history["time"][-1]) for r in runs)
    if window is not None:
        start = max(window[0] - period, 0.0)
    else:  # a failed run: its last periods
        start = max(t_last - (study.settings.fit_periods + 1) * period, 0.0)
    for ax in (steady, difference):
        ax.set_xlim(start, t_last)
    time = first["time"]
    shown = time >= start - 1e-9
    # the tank on its own axis (right), scaled to the buoy's, so that the phase can be read
    tank_axis = steady.twinx()
    tank_axis.plot(time[shown], first["tank"][shown] * 1e3, color="0.6", lw=2.5, alpha=0.8,
                   label="tank (right axis)", zorder=1)
    tank_axis.set_ylabel("tank displacement (mm)", color="0.4")
    steady.set_zorder(tank_axis.get_zorder() + 1)
    steady.patch.set_visible(False)
    for index, r in enumerate(runs):
        h = r.history
        keep = h["time"] >= start - 1e-9
        step = max(1, int(keep.sum()) // 45)  # about 45 markers, staggered between models
        steady.plot(h["time"][keep], h["buoy"][keep] * 1e3, lw=1.2, label=_label(r.model, r),
                    **_line(r.model, markevery=(index * step // 3, step)))
        whole.plot(h["time"], h["buoy"] * 1e3, lw=0.8, **_line(r.model, marker=False))
    whole.plot(time, first["tank"] * 1e3, color="0.55", lw=1.0)
    # differences from the particle model (or the first model run), on the common samples
    base = next((r for r in runs if r.model == "particle"), runs[0])
    drawn = False
    for r in runs:
        if r is base:
            continue
        common = min(len(r.history["time"]), len(base.history["time"]))
        t = base.history["time"][:common]
        if not np.allclose(r.history["time"][:common], t, rtol=0.0, atol=1e-9):
            continue
        keep = t >= start - 1e-9
        delta = (r.history["buoy"][:common] - base.history["buoy"][:common])[keep]
        difference.plot(t[keep], delta * 1e3, lw=1.0, **_line(r.model, marker=False))
        drawn = True
    buoy_limit = max(abs(v) for v in steady.get_ylim())
    tank_limit = float(np.max(np.abs(first["tank"][shown]))) * 1e3 or 1.0
    steady.set_ylim(-buoy_limit, buoy_limit)
    tank_axis.set_ylim(-1.1 * tank_limit, 1.1 * tank_limit)
    difference.axhline(0.0, color="0.3", lw=0.6)
    difference.set_ylabel(f"minus {base.model}\n(mm)")
    if not drawn:
        difference.text(0.5, 0.5, "one model only: no differences", ha="center",
                        va="center", transform=difference.transAxes, color="0.4")
    if window is not None:
        for ax in (steady, difference, whole):
            for span in windows:
                ax.axvspan(*span, color="gold", alpha=0.15, lw=0)
        steady.axvline(window[0], color="0.35", lw=0.8, ls="--")
        label = dict(fontsize=8, va="top", color="0.25",
                     bbox=dict(boxstyle="square,pad=0.15", fc="white", ec="none", alpha=0.8))
        steady.text(window[0], 0.985, f" fit window: the last {study.settings.fit_periods} "
                    f"periods, {window[0]:.2f}-{window[1]:.2f} s",
                    transform=steady.get_xaxis_transform(), **label)
        whole.text(window[0], 0.96, " fit window", transform=whole.get_xaxis_transform(),
                   ha="right", **label)
    steady.set_ylabel("horizontal displacement (mm)")
    whole.set_ylabel("displacement\n(mm)")
    whole.set_xlabel("time (s)")
    steady.set_title("steady state: the fit window and the period before it", fontsize=9,
                     loc="left")
    difference.set_title(f"difference from the {LABELS[base.model].split(' (')[0]} (same time "
                         f"samples)", fontsize=9, loc="left")
    whole.set_title("the whole run, from rest", fontsize=9, loc="left")
    for ax in (steady, difference, whole):
        ax.grid(alpha=0.3)
    x0_mm = study.case.amplitude * 1e3
    if record:
        title = f"buoy and tank displacement, tank record {record} ({f:.4g} Hz)"
    else:
        title = f"buoy and tank displacement at {f:g} Hz (X0 = {x0_mm:g} mm)"
    fig.suptitle(title, fontsize=11)
    handles, labels = steady.get_legend_handles_labels()
    tank_handles, tank_labels = tank_axis.get_legend_handles_labels()
    fig.legend(tank_handles + handles, tank_labels + labels, loc="outside lower center",
               ncols=2, fontsize=8, frameon=False)
    return fig


def _line(model: str, marker: bool = True, **extra: Any) -> dict[str, Any]:
    """Colour, line style and (optionally) open markers that tell a model apart."""
    style = dict(_STYLE[model])
    if marker:
        style.update(marker=_RECORD_MARKERS[model], ms=4, mfc="none", **extra)
    else:
        style["marker"] = ""
    return style


def _peak_inset(ax: Any, study: StudyResult) -> None:
    """A zoom on the refined peaks of the relative amplitude, where the models' curves and
    their refinement runs would otherwise overlap, in the upper right of ``ax``."""
    peaks = [r for r in study.resonances.values() if math.isfinite(r.frequency)]
    if not peaks:
        return
    centre = float(np.mean([r.frequency for r in peaks]))
    runs = [f for r in peaks for f in r.runs] or [r.frequency for r in peaks]
    half = max(max(abs(f - centre) for f in runs), 1e-4) * 1.15
    inset = ax.inset_axes((0.6, 0.42, 0.38, 0.52))
    top = []
    for model in MODELS:
        f, y = study.curve(model, "relative_amplitude")
        near = np.abs(f - centre) <= half
        if near.any():
            inset.plot(f[near], y[near] * 1e3, lw=1.0, **_line(model))
            top.append(y[near])
    for r in peaks:
        inset.plot(r.frequency, r.peak * 1e3, marker="*", ms=11, color=_STYLE[r.model]["color"],
                   mec="k", mew=0.5, ls="")
    values = np.concatenate(top) * 1e3 if top else np.array([0.0])
    spread = max(float(values.max() - values.min()), 1e-3)
    inset.set_xlim(centre - half, centre + half)
    inset.set_ylim(values.max() - 1.1 * spread, values.max() + 0.25 * spread)
    inset.tick_params(labelsize=7)
    inset.set_title("near the peak: refinement runs and refined peaks (stars)", fontsize=7)
    inset.grid(alpha=0.3)


def _response_figure(plt: Any, study: StudyResult, kind: str, data: Measurements | None) -> Any:
    """Figs. 14-15: absolute and relative amplitude (or phase) against frequency, every run a
    marker, the refined resonances marked, and the models' differences in a third panel."""
    measured_tank = any(r.record is not None for r in study.results)
    fig, axes = plt.subplots(
        3, 1, figsize=(8.5, 9), sharex=True, layout="constrained", height_ratios=(2.2, 2.2, 1.4)
    )
    scale = 1e3 if kind == "amplitude" else 1.0
    unit = "mm" if kind == "amplitude" else "deg"
    for ax, motion in zip(axes[:2], ("absolute", "relative"), strict=True):
        quantity = f"{motion}_amplitude" if kind == "amplitude" else f"{motion}_phase_deg"
        for model in MODELS:
            f, y = study.curve(model, quantity)
            if len(f):
                ax.plot(f, y * scale, label=LABELS[model], lw=1.3, **_line(model))
        if data is not None and data.motion == motion:
            y = data.amplitude * 1e3 if kind == "amplitude" else data.phase_deg
            ax.plot(data.frequency, y, "ks", ms=5, label=LABELS["measured"])
        what = "buoy displacement" if motion == "absolute" else "buoy relative to tank"
        ax.set_ylabel(f"{kind} ({unit})")
        ax.set_title(what, fontsize=9, loc="left")
        ax.grid(alpha=0.3)
    if kind == "amplitude":
        for model, res in study.resonances.items():
            if math.isfinite(res.frequency):
                axes[1].plot(res.frequency, res.peak * 1e3, marker="*", ms=13,
                             color=_STYLE[model]["color"], mec="k", mew=0.6, ls="",
                             label=f"peak, {model}: {res.frequency:.4f} Hz, "
                             f"{res.peak * 1e3:.2f} mm")
    if kind == "amplitude" and study.resonances:
        _peak_inset(axes[1], study)
    # differences from the particle model (else the first model run) at common frequencies
    present = [m for m in MODELS if study.of(m)]
    base = present[0] if present else "particle"
    quantity = "relative_amplitude" if kind == "amplitude" else "relative_phase_deg"
    fb, yb = study.curve(base, quantity)
    drawn = False
    for model in present[1:]:
        f, y = study.curve(model, quantity)
        common, ib, im = np.intersect1d(np.round(fb, 9), np.round(f, 9), return_indices=True)
        if len(common) and len(fb):
            axes[2].plot(common, (y[im] - yb[ib]) * scale, lw=1.2, **_line(model))
            drawn = True
    axes[2].axhline(0.0, color="0.3", lw=0.6)
    axes[2].grid(alpha=0.3)
    axes[2].set_ylabel(f"minus {base}\n({unit})")
    axes[2].set_title(f"relative {kind}: difference from the {LABELS[base].split(' (')[0]} "
                      "(at the frequencies both ran)", fontsize=9, loc="left")
    if not drawn:
        axes[2].text(0.5, 0.5, "one model only: no differences", ha="center",
                     va="center", transform=axes[2].transAxes, color="0.4")
    axes[-1].set_xlabel("excitation frequency (Hz)")
    if kind == "amplitude":
        x0_mm = study.case.amplitude * 1e3
        tank = "measured tank records" if measured_tank else f"X0 = {x0_mm:g} mm"
        title = f"amplitude of the buoy's horizontal displacement ({tank})"
    else:
        title = f"phase: {PHASE_CONVENTION}"
    fig.suptitle(title, fontsize=10)
    handles, labels = [], []
    for ax in axes[:2]:
        for h, lab in zip(*ax.get_legend_handles_labels(), strict=True):
            if lab not in labels:
                handles.append(h)
                labels.append(lab)
    fig.legend(handles, labels, loc="outside lower center", ncols=2, fontsize=8, frameon=False)
    return fig


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
