"""A chain hanging at rest, saved to NetCDF and to a ParaView series, and read back.

At rest, the top link of a chain of n beads of mass m carries the whole weight n m g, and each
link below carries the weight of the beads under it. The script reads the tensions back from the
NetCDF file and compares them with these weights.

    python examples/result_files.py OUTPUT_FOLDER [--beads 4] [--plot result_files.png]
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
    parser.add_argument("--plot", metavar="FILE",
                        help="write a PNG figure of what the two files hold to FILE")
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
    if args.plot:
        plot(data, index, weights, links, args.plot)


def plot(data, index: Path, weights: np.ndarray, links, path: str) -> None:
    """Draw the tensions read from the NetCDF file and the last state read from the .vtu file."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import meshio

    fig, axes = plt.subplots(1, 2, figsize=(10, 3.8), layout="constrained")
    k = np.arange(1, len(weights) + 1)
    axes[0].plot(k, weights, "k-", label="weight below the link")
    axes[0].plot(k, data["tension"].values[-1, [c.index for c in links]], "o",
                 label="tension from chain.nc")
    axes[0].set(xlabel="link", ylabel="tension (N)", title="NetCDF: tension, last time")
    axes[0].legend(fontsize=8)
    time, last = read_pvd(index)[-1]
    mesh = meshio.read(last)
    points = mesh.points
    for block in mesh.cells:
        if block.type != "line":  # the particles are vertex cells, the distances lines
            continue
        for a, b in block.data:
            axes[1].plot(points[[a, b], 0], points[[a, b], 2], "-", color="0.5")
    axes[1].scatter(points[:, 0], points[:, 2], c=mesh.point_data["mass"], zorder=3)
    axes[1].set(xlabel="x (m)", ylabel="z (m)", title=f"ParaView file: {last.name}, t = {time:g} s",
                xlim=(-0.5, 0.5))
    fig.savefig(path, dpi=110)
    print(f"plot: {path}")


if __name__ == "__main__":
    main()
