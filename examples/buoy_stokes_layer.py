"""The buoy's resonance with and without the Stokes-layer viscous force (docs/buoy/stokes-layer.md).

Runs the 2-DOF string + sphere model of the buoy study over a sweep around its resonance twice,
with the study's fluid model (Morison drag and added mass) and with the Stokes layer added
(``BuoyCase(viscous_force="stokes-layer")``, no recalibration of Cd or Ca), refines both peaks,
prints the damping ratios and the drop of the peak, and draws the curves.

    python examples/buoy_stokes_layer.py [--plot docs/buoy/stokes-layer.png] [--count 15]
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import numpy as np

from vinculo.buoy.case import BuoyCase, SweepSettings
from vinculo.buoy.reference import OneDofModel
from vinculo.buoy.report import stokes_damping_ratio
from vinculo.buoy.study import run_study

FIGURE = Path(__file__).resolve().parent.parent / "docs" / "buoy" / "stokes-layer.png"


def morison_damping_ratio(case: BuoyCase, amplitude: float) -> float:
    """Damping ratio of Morison drag at a relative amplitude, by equivalent linearisation.

    Over a cycle of amplitude A at w, ``k |u| u`` dissipates as a linear damper
    ``c_eq = 8/(3 pi) k w A`` (k = 1/2 rho Cd A_frontal); on the rigid pendulum (L, I) that is
    ``zeta = c_eq L^2 / (2 (m L^2 + I) w)`` at its natural frequency w.

    Arguments:
        case: the buoy case.
        amplitude: the relative amplitude of the centre, in m.

    Returns:
        The damping ratio.
    """
    pendulum = OneDofModel(case)
    w = 2 * math.pi * pendulum.natural_frequency()
    k = 0.5 * case.fluid_density * case.drag_coefficient * case.frontal_area
    inertia = (case.sphere_mass + case.added_mass) * pendulum.length**2 + pendulum.inertia
    return 8 / (3 * math.pi) * k * w * amplitude * pendulum.length**2 / (2 * inertia * w)


def main() -> None:
    """Run both sweeps, print the numbers, draw the figure."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--plot", type=Path, default=FIGURE, help="the PNG to write")
    parser.add_argument("--count", type=int, default=15, help="frequencies in 0.75-1.1 Hz")
    args = parser.parse_args()
    settings = SweepSettings(f_min=0.75, f_max=1.1, count=args.count)
    cases = {"Morison only (the study)": BuoyCase(),
             "Morison + Stokes layer": BuoyCase(viscous_force="stokes-layer")}
    studies = {
        name: run_study(case, settings, models=("two-dof",), history_frequencies=(),
                        progress=False)
        for name, case in cases.items()
    }
    base = BuoyCase()
    peaks = {name: study.resonances["two-dof"] for name, study in studies.items()}
    plain, viscous = peaks.values()
    frequency = plain.frequency
    damping, mass = base.stokes_layer(frequency)
    delta = math.sqrt(2 * base.kinematic_viscosity / (2 * math.pi * frequency))
    print(f"Stokes layer at {frequency:.3f} Hz: delta = {delta * 1e3:.3f} mm, R/delta = "
          f"{base.radius / delta:.1f}, c = {damping:.4f} N s/m, m_v = {mass * 1e3:.2f} g")
    print(f"damping ratio, Stokes layer: {stokes_damping_ratio(base):.4f}")
    print(f"damping ratio, Morison drag at the peak: "
          f"{morison_damping_ratio(base, plain.peak):.4f}")
    for name, peak in peaks.items():
        print(f"{name}: resonance {peak.describe()}")
    print(f"peak drop: {100 * (1 - viscous.peak / plain.peak):.1f} %")

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (amp, phase) = plt.subplots(2, 1, figsize=(7.5, 6.5), sharex=True,
                                     layout="constrained")
    styles = [dict(color="C1", ls="--", marker="s"), dict(color="C4", ls="-", marker="o")]
    for (name, study), style in zip(studies.items(), styles, strict=True):
        f, a = study.curve("two-dof", "relative_amplitude")
        _, p = study.curve("two-dof", "relative_phase_deg")
        amp.plot(f, a * 1e3, ms=3.5, mfc="none", label=name, **style)
        phase.plot(f, p, ms=3.5, mfc="none", **style)
        peak = peaks[name]
        amp.plot(peak.frequency, peak.peak * 1e3, "*", ms=12, color=style["color"], mec="k",
                 mew=0.5)
        amp.annotate(f"{peak.peak * 1e3:.2f} mm at {peak.frequency:.4f} Hz",
                     (peak.frequency, peak.peak * 1e3), xytext=(12, -4),
                     textcoords="offset points", fontsize=8)
    amp.set_ylabel("relative amplitude (mm)")
    phase.set_ylabel("relative phase (deg)")
    phase.set_xlabel("excitation frequency (Hz)")
    amp.set_title("2-DOF buoy model, X0 = 5 mm: the Stokes layer added without recalibration",
                  fontsize=10)
    for ax in (amp, phase):
        ax.grid(alpha=0.3)
    amp.legend(fontsize=8, loc="upper left")
    phase.set_yticks(np.arange(0, 181, 45))
    args.plot.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(args.plot, dpi=110)
    print(f"figure: {args.plot}")


if __name__ == "__main__":
    main()
