"""The OC3-Hywind spar's mooring: its stiffness about the spar's reference point and its offset
curve in surge.

Reads ``tests/data/moordyn/oc3_hywind.txt`` (three 902.2 m chains 120 degrees apart at 320 m
depth, 20 segments each), prints the 6x6 linearised stiffness of the mooring on the spar about
its reference point at the still water level against the matrix published for it (Jonkman,
NREL/TP-500-47535, 2010, eq. 5-3), then moves the three fairleads together from -20 to 20 m in
surge, solving the static equilibrium at each offset, and prints the restoring force and the
fairlead tensions. ``--plot FILE`` draws the offset curve.

Run:  .venv/bin/python examples/oc3_offsets.py [--plot oc3_offsets.png]
"""

import argparse
from pathlib import Path

import numpy as np

import vinculo.mooring as mooring

FILE = Path(__file__).resolve().parent.parent / "tests" / "data" / "moordyn" / "oc3_hywind.txt"

#: The published entries (N/m, N/rad, N m/m, N m/rad), by (row, column) of x, y, z, rx, ry, rz.
PUBLISHED = {(0, 0): 41_180.0, (2, 2): 11_940.0, (3, 3): 311_100_000.0,
             (5, 5): 11_560_000.0, (0, 4): -2_821_000.0}
NAMES = ("x", "y", "z", "rx", "ry", "rz")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--plot", metavar="FILE", help="draw the offset curve into FILE")
    args = parser.parse_args()
    statics = mooring.statics(FILE)
    k = statics.vessel_stiffness()
    print("stiffness about the reference point, vinculo against the published matrix:")
    for (i, j), value in PUBLISHED.items():
        print(f"  K[{NAMES[i]}, {NAMES[j]}] = {k[i, j]:14.6g}  published {value:14.6g}  "
              f"({k[i, j] / value - 1.0:+.2%})")
    curve = mooring.offset_curve(FILE, np.linspace(-20.0, 20.0, 9), heading=0.0)
    print(curve.table())
    if args.plot:
        mooring.plot_offset_curve(curve, args.plot)


if __name__ == "__main__":
    main()
