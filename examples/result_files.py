"""A chain hanging at rest, saved to NetCDF and to a ParaView series, and read back.

At rest, the top link of a chain of n beads of mass m carries the whole weight n m g, and each
link below carries the weight of the beads under it. The script reads the tensions back from the
NetCDF file and compares them with these weights.

    python examples/result_files.py OUTPUT_FOLDER [--beads 4]
"""

import argparse
from itertools import pairwise
from pathlib import Path

import numpy as np

import vinculo
from vinculo.io import export_vtk, load_netcdf, read_pvd, save_netcdf

G = 9.81


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("output", type=Path, help="folder for the files (created if missing)")
    parser.add_argument("--beads", type=int, default=4, help="number of beads (default 4)")
    args = parser.parse_args()

    mass, link = 0.1, 0.25
    system = vinculo.System(gravity=(0.0, 0.0, -G))
    pivot = system.add_particle(1.0, (0.0, 0.0, 0.0), fixed=True)
    beads = [system.add_particle(mass, (0.0, 0.0, -link * (k + 1))) for k in range(args.beads)]
    links = [system.add_distance(a, b, length=link) for a, b in pairwise([pivot, *beads])]
    solution = vinculo.simulate(system, t_end=0.5, dt=1e-2)

    args.output.mkdir(parents=True, exist_ok=True)
    path = save_netcdf(solution, args.output / "chain.nc", attributes={"beads": args.beads,
                                                                       "bead_mass": mass})
    index = export_vtk(solution, args.output / "chain_vtk", overwrite=True)
    data = load_netcdf(path)
    tension = data["tension"].values[-1, [c.index for c in links]]
    weights = mass * G * np.arange(args.beads, 0, -1)
    print(f"netcdf: {path} ({path.stat().st_size} bytes)")
    print(f"paraview: {index} ({len(read_pvd(index))} times)")
    print(f"top tension from the file: {tension[0]:.12f} N (weight of the chain: "
          f"{weights[0]:.12f} N)")
    print(f"largest tension error: {np.max(np.abs(tension - weights)):.2e} N")


if __name__ == "__main__":
    main()
