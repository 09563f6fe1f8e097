"""The buoy study in small: a sweep of three models, a parameter study and a calibration.

A buoyant sphere tied by a string to the floor of a shaken water tank (the paper's case,
``vinculo.buoy.BuoyCase``). With coarse, fast settings (few frequencies, short settling) the
script

1. runs the particle model (a 7-particle rigid body on a string, with Morison forces) and the two
   scipy reference models (``two-dof``: string and sphere angles; ``one-dof``: the paper's
   corrected eq. 31) over a frequency sweep, and compares the particle model with the 2-DOF
   model, the fair reference for a sphere on a string;
2. runs a parameter study of the 2-DOF model over the drag coefficient, written to a CSV file that
   a second call resumes instead of recomputing;
3. calibrates the drag and added-mass coefficients of the 1-DOF model (the fastest) against
   synthetic "measurements" that the same model made with known coefficients (vinculo ships no
   measured data), and recovers them.

    python examples/buoy_study.py [--plot buoy_study.png] [--output DIR]
"""

import argparse
import tempfile
from pathlib import Path

import numpy as np

from vinculo.buoy import (
    BuoyCase,
    SweepSettings,
    calibrate,
    grid,
    read_measurements,
    run_parameter_study,
)
from vinculo.buoy.calibration import model_curve
from vinculo.buoy.study import run_study

TRUE_DRAG, TRUE_ADDED_MASS = 0.35, 0.60


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--plot", metavar="FILE", help="write a PNG figure to FILE")
    parser.add_argument("--output", type=Path, default=None,
                        help="folder for the study and data files (default: a temporary one)")
    args = parser.parse_args()
    output = args.output or Path(tempfile.mkdtemp(prefix="buoy-study-"))
    output.mkdir(parents=True, exist_ok=True)

    # 1. A coarse sweep of the three models around the resonance (about 0.9 Hz).
    case = BuoyCase()
    settings = SweepSettings(f_min=0.7, f_max=1.2, count=6, dt=5e-3, settle_periods=12.0,
                             fit_periods=3)
    study = run_study(case, settings, history_frequencies=(), workers=1, progress=False)
    for model in ("particle", "two-dof", "one-dof"):
        frequency, peak = study.resonance(model)
        print(f"{model:>8}: relative amplitude peaks at {frequency:.3f} Hz, {peak * 1e3:.2f} mm")
    f, particle = study.curve("particle", "relative_amplitude")
    _, two_dof = study.curve("two-dof", "relative_amplitude")
    gap = np.max(np.abs(particle - two_dof)) / np.max(two_dof)
    print(f"particle against two-dof: largest gap {gap:.1%} of the peak relative amplitude")

    # 2. A parameter study of the 2-DOF model over the drag coefficient (fast, scipy).
    points = grid({"drag_coefficient": [0.1, 0.22, 0.4], "frequency": list(f)})
    first = run_parameter_study(points, settings=settings, models=("two-dof",),
                                output=output / "study", workers=1, progress=False)
    again = run_parameter_study(points, settings=settings, models=("two-dof",),
                                output=output / "study", workers=1, progress=False)
    print(f"parameter study: {first.computed} runs computed, then {again.computed} computed "
          f"and {again.reused} reused from {again.path.name}")

    # 3. Synthetic measurements from known coefficients, then the calibration from the defaults.
    truth = BuoyCase(drag_coefficient=TRUE_DRAG, added_mass_coefficient=TRUE_ADDED_MASS)
    measured_f = np.linspace(0.8, 1.1, 4)
    amplitude, phase = model_curve(truth, settings, measured_f, model="one-dof")
    data_file = output / "measurements.csv"
    rows = [f"{a:.6f}, {b:.9e}, {c:.6f}" for a, b, c in zip(measured_f, amplitude, phase,
                                                           strict=True)]
    data_file.write_text("frequency (Hz), amplitude (m), phase (deg)\n" + "\n".join(rows) + "\n")
    fit = calibrate(read_measurements(data_file), case=case, settings=settings, model="one-dof",
                    workers=1, curve_points=0, progress=False)
    for name, value, sd, true in zip(fit.names, fit.values, fit.uncertainties,
                                     (TRUE_DRAG, TRUE_ADDED_MASS), strict=True):
        print(f"calibrated {name}: {value:.4f} +- {sd:.1e} (true {true})")

    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, axes = plt.subplots(1, 3, figsize=(13, 3.8), layout="constrained")
        for model, style in (("particle", "o-"), ("two-dof", "s--"), ("one-dof", "^:")):
            freq, rel = study.curve(model, "relative_amplitude")
            axes[0].plot(freq, rel * 1e3, style, ms=4, label=model)
        axes[0].set(xlabel="frequency (Hz)", ylabel="relative amplitude (mm)",
                    title="three models")
        axes[0].legend(fontsize=8)
        for cd in sorted(set(first.column("drag_coefficient"))):
            rows_cd = [r for r in again.rows if r.parameters["drag_coefficient"] == cd]
            rows_cd.sort(key=lambda r: r.parameters["frequency"])
            axes[1].plot([r.parameters["frequency"] for r in rows_cd],
                         [r.results["relative_amplitude"] * 1e3 for r in rows_cd], "o-", ms=3,
                         label=f"Cd = {cd}")
        axes[1].set(xlabel="frequency (Hz)", ylabel="relative amplitude (mm)",
                    title="parameter study (2-DOF)")
        axes[1].legend(fontsize=8)
        axes[2].plot(measured_f, amplitude * 1e3, "ko", label="synthetic data")
        axes[2].plot(measured_f, fit.initial_amplitude * 1e3, ":", label="start (defaults)")
        axes[2].plot(measured_f, fit.fitted_amplitude * 1e3, "-", label="calibrated")
        axes[2].set(xlabel="frequency (Hz)", ylabel="absolute amplitude (mm)",
                    title="calibration of Cd and Ca (1-DOF)")
        axes[2].legend(fontsize=8)
        fig.savefig(args.plot, dpi=110)
        print(f"plot: {args.plot}")


if __name__ == "__main__":
    main()
