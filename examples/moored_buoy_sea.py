"""A surface buoy on three chains in a JONSWAP sea: motions, fairlead tensions, spectra.

Runs ``examples/moored_buoy/surface_buoy.toml`` (a 3 m cylindrical buoy, three studless chains
in 40 m of water, Hs 1.5 m, Tp 7 s, a 0.5 m/s power-law current) for 120 s from its static
equilibrium, the waves growing over the first 14 s, as ``vinculo moored-buoy`` does. It prints
the equilibrium, the significant wave height of the elevation at the buoy (against the 1.5 m
asked for: 120 s is a short record), the motions' and tensions' ranges, and the CPU time.
``--plot FILE`` draws the elevation, surge and heave, pitch, and the three fairlead tensions.

Run:  .venv/bin/python examples/moored_buoy_sea.py [--plot moored_buoy_sea.png]
"""

import argparse
from pathlib import Path

import numpy as np

from vinculo.ocean import moored_buoy as mb

CASE = Path(__file__).resolve().parent / "moored_buoy" / "surface_buoy.toml"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--plot", metavar="FILE", help="draw the run into FILE")
    args = parser.parse_args()
    case = mb.read_case(CASE)
    built = mb.build(case)
    centre = built.statics.positions[built.body["centre"].index]
    print(f"equilibrium: centre of gravity at ({centre[0]:.3f}, {centre[1]:.3f}, "
          f"{centre[2]:.3f}) m")
    result = mb.run(built, t_end=120.0)
    after = result.times >= case.sea.ramp
    print(f"significant height at the buoy: {4 * result.elevation[after].std():.3f} m")
    print(f"heave: significant {4 * result.motions[after, 2].std():.3f} m")
    print(f"pitch: {np.degrees(result.motions[after, 4]).min():.2f} to "
          f"{np.degrees(result.motions[after, 4]).max():.2f} deg")
    for k, line in enumerate(built.lines):
        t = result.tensions[after, k, 0]
        print(f"{line.name}: fairlead tension {t.min() / 1e3:.1f} to {t.max() / 1e3:.1f} kN")
    print(f"CPU time of the run: {result.cpu_time:.1f} s for {result.times[-1]:.0f} s")
    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        t = result.times
        fig, ax = plt.subplots(4, 1, figsize=(8, 8), sharex=True)
        ax[0].plot(t, result.elevation)
        ax[0].set_ylabel("elevation (m)")
        ax[1].plot(t, result.motions[:, 0], label="surge")
        ax[1].plot(t, result.motions[:, 2], label="heave")
        ax[1].set_ylabel("motion (m)")
        ax[1].legend(loc="upper right")
        ax[2].plot(t, np.degrees(result.motions[:, 4]))
        ax[2].set_ylabel("pitch (deg)")
        for k, line in enumerate(built.lines):
            ax[3].plot(t, result.tensions[:, k, 0] / 1e3, label=line.name)
        ax[3].set_ylabel("fairlead tension (kN)")
        ax[3].set_xlabel("time (s)")
        ax[3].legend(loc="upper right", fontsize="small")
        fig.suptitle(case.title)
        fig.tight_layout()
        fig.savefig(args.plot, dpi=100)


if __name__ == "__main__":
    main()
