"""The flexible jumper of Lowe and Langley (OMAE 2006): its statics, and 10 m of surge, sway and
heave of its top end against the paper's top tension.

Runs ``examples/flexible_jumper/jumper.txt`` (170 m, EI = 120.8 kN m^2, 68 segments; the
folder's README gives the paper's configuration): the static equilibrium, whose end forces the
paper gives, then the top end moved 10 m with a period of 27 s along x, y and z in turn (one
period of smooth start, then 80 s at 0.05 s steps). It prints the end forces against the paper's
and, for each motion, the largest and the rms difference of the top tension from the paper's
curve (digitised, at whole seconds). In heave the top end rises 5 m out of the water, whose
surface (z = 0) leaves the jumper's top part without buoyancy. ``--plot FILE`` draws the three
tensions over the paper's points.

Run:  .venv/bin/python examples/flexible_jumper.py [--plot flexible_jumper.png]
"""

import argparse
from pathlib import Path

import numpy as np

from vinculo.mooring import Motion, read_moordyn, statics
from vinculo.mooring.analysis import run

FOLDER = Path(__file__).resolve().parent / "flexible_jumper"
AMPLITUDE, PERIOD, DURATION = 10.0, 27.0, 80.0
MOTIONS = ("surge", "sway", "heave")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--plot", metavar="FILE", help="draw the tensions into FILE")
    args = parser.parse_args()
    model = read_moordyn(FOLDER / "jumper.txt")
    lower, top = (np.asarray(e.force) / 1e3 for e in statics(model).ends)
    print(f"static top force: ({-top[0]:.3f}, {-top[2]:.3f}) kN; the paper's (11.40, 45.71)")
    print(f"static lower force: ({lower[0]:.3f}, {-lower[2]:.3f}) kN; the paper's (11.40, 24.04)")
    paper = np.genfromtxt(FOLDER / "top_tension_kN.csv", delimiter=",", names=True)
    start = [p.position for p in model.coupled_points()]
    curves = {}
    for axis, name in enumerate(MOTIONS):
        amplitude = [0.0, 0.0, 0.0]
        amplitude[axis] = AMPLITUDE
        motion = Motion.harmonic(start, amplitude, period=PERIOD, ramp_time=PERIOD)
        result = run(model, motion, DURATION + PERIOD, dt=0.05, plots=False)
        tension = np.linalg.norm(result.end_forces[:, 0, 1, :], axis=1) / 1e3
        given = ~np.isnan(paper[name])
        t = paper["t"][given]
        difference = np.interp(t + PERIOD, result.times, tension) - paper[name][given]
        after = tension[result.times >= PERIOD]
        print(f"{name}: top tension {after.min():.2f} to {after.max():.2f} kN; from the "
              f"paper's: largest {np.abs(difference).max():.2f}"
              f" kN, rms {np.sqrt(np.mean(difference**2)):.2f} kN "
              f"(CPU {result.cpu_time:.2f} s)")
        curves[name] = (result.times - PERIOD, tension, t, paper[name][given])
    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, axes = plt.subplots(3, 1, figsize=(8, 8), sharex=True)
        for ax, name in zip(axes, MOTIONS, strict=True):
            times, tension, t, reference = curves[name]
            after = times >= 0.0
            ax.plot(times[after], tension[after], label="vinculo")
            ax.plot(t, reference, "o", markersize=3, label="Lowe and Langley (2006)")
            ax.set_ylabel(f"{name}: top tension (kN)")
        axes[0].legend(loc="upper right")
        axes[-1].set_xlabel("time after the smooth start (s)")
        fig.suptitle("The flexible jumper: 10 m of top motion, period 27 s")
        fig.tight_layout()
        fig.savefig(args.plot, dpi=110)


if __name__ == "__main__":
    main()
