"""ParaView time series of a run: one VTK file per stored time and a ``.pvd`` index.

Each time is an unstructured grid (``.vtu``, written by meshio) whose points are the particles,
with a vertex cell per particle (so ParaView shows the particles even without a glyph filter) and a
line cell per distance constraint between two particles. Point data: ``velocity`` (m/s) and
``mass`` (kg); cell data: ``tension`` (N, the line's ``2 lambda L``; NaN on vertices) and
``constraint`` (the line's constraint index; -1 on vertices).

Constraints that are not distances between two particles are not drawn: a distance to a moving
point would need that point's path, which the system does not expose; planes and fixed
coordinates have no line to draw. Their multipliers are in the NetCDF file
(:func:`vinculo.io.save_netcdf`).

The ``.pvd`` index lists every file with its time; open it in ParaView to play the run.
"""

from __future__ import annotations

import os
import xml.etree.ElementTree as ElementTree
from pathlib import Path
from typing import Any

import numpy as np

from vinculo.errors import InvalidInputError
from vinculo.io.output import checked_folder, folder_written_in_place
from vinculo.io.topology import distance_pairs
from vinculo.solution import Solution

__all__ = ["export_vtk", "read_pvd"]


def _meshio() -> Any:
    """Import meshio, or say which extra provides it."""
    try:
        import meshio
    except ImportError as exc:  # pragma: no cover - the test environment has it
        raise ImportError(
            f"VTK files need meshio ({exc}); install it with `pip install 'vinculo[io]'`"
        ) from exc
    return meshio


def export_vtk(
    solution: Solution,
    folder: str | os.PathLike[str],
    *,
    name: str = "state",
    every: int = 1,
    overwrite: bool = False,
) -> Path:
    """Write a run as a ParaView time series.

    The files are built in a temporary folder beside ``folder``, which takes ``folder``'s place
    once every file is written, so an interrupted export leaves no partial series behind.

    Arguments:
        solution: the run.
        folder: the folder to create (or an empty one) for the files.
        name: stem of the file names: ``<name>_<k>.vtu`` for the k-th stored time written and
            ``<name>.pvd`` for the index.
        every: write every ``every``-th stored time (1: all; the last stored time is always
            written).
        overwrite: replace ``folder`` if it exists and is not empty.

    Returns:
        The path of the ``.pvd`` index.

    Raises:
        InvalidInputError: ``folder`` is a file, its parent does not exist, or it is not empty
            (without ``overwrite``); ``name`` is not a plain file stem; ``every`` is not a
            positive whole number; the solution holds no stored time.
    """
    if not isinstance(solution, Solution):
        raise InvalidInputError(
            f"expected a vinculo.Solution, got {type(solution).__name__}",
            name="solution",
            value=type(solution).__name__,
        )
    if not isinstance(name, str) or not name or Path(name).name != name or name.startswith("."):
        raise InvalidInputError(
            f"name {name!r} must be a plain file stem (no folder, not starting with a dot)",
            name="name",
            value=name,
        )
    if isinstance(every, bool) or not isinstance(every, (int, np.integer)) or every < 1:
        raise InvalidInputError(
            f"every must be a whole number >= 1, got {every!r}", name="every", value=every
        )
    count = len(solution.times)
    if count == 0:
        raise InvalidInputError(
            "the solution holds no stored time: nothing to export", name="solution", value=0
        )
    target = checked_folder(folder, "VTK files", overwrite)
    meshio = _meshio()
    system = solution.system
    constraints, pairs = distance_pairs(system)
    num_particles = solution.positions.shape[1]
    masses = np.asarray(system.masses(), dtype=np.float64)
    vertices = np.arange(num_particles, dtype=np.int64)[:, np.newaxis]
    cells = [("vertex", vertices)]
    if len(pairs):
        cells.append(("line", pairs))
    lengths = np.asarray(system.constraint_lengths, dtype=np.float64)[constraints]
    indices = sorted({*range(0, count, int(every)), count - 1})
    width = max(6, len(str(count - 1)))
    entries: list[tuple[float, str]] = []
    with folder_written_in_place(target) as building:
        for k in indices:
            tension = 2.0 * solution.multipliers[k, constraints] * lengths
            cell_data = {
                "tension": [np.full(num_particles, np.nan)] + ([tension] if len(pairs) else []),
                "constraint": [np.full(num_particles, -1, dtype=np.int64)]
                + ([constraints] if len(pairs) else []),
            }
            mesh = meshio.Mesh(
                np.array(solution.positions[k]),
                cells,
                point_data={"velocity": np.array(solution.velocities[k]), "mass": masses},
                cell_data=cell_data,
            )
            file_name = f"{name}_{k:0{width}d}.vtu"
            meshio.write(building / file_name, mesh, file_format="vtu")
            entries.append((float(solution.times[k]), file_name))
        _write_pvd(building / f"{name}.pvd", entries)
    return target / f"{name}.pvd"


def _write_pvd(path: Path, entries: list[tuple[float, str]]) -> None:
    """Write a ParaView collection listing each file with its time."""
    root = ElementTree.Element(
        "VTKFile", type="Collection", version="0.1", byte_order="LittleEndian"
    )
    collection = ElementTree.SubElement(root, "Collection")
    for time, file_name in entries:
        ElementTree.SubElement(
            collection, "DataSet", timestep=repr(time), group="", part="0", file=file_name
        )
    ElementTree.indent(root)
    ElementTree.ElementTree(root).write(path, encoding="utf-8", xml_declaration=True)


def read_pvd(path: str | os.PathLike[str]) -> list[tuple[float, Path]]:
    """The times and files listed in a ``.pvd`` index.

    Arguments:
        path: the ``.pvd`` file.

    Returns:
        ``(time, file)`` pairs in the index's order, the files as paths beside the index.

    Raises:
        InvalidInputError: the file does not exist or is not a ParaView collection.
    """
    source = Path(path)
    if not source.is_file():
        raise InvalidInputError(f"no .pvd file at {str(source)!r}", name="path", value=str(source))
    try:
        root = ElementTree.parse(source).getroot()
    except ElementTree.ParseError as exc:
        raise InvalidInputError(
            f"{str(source)!r} is not an XML file: {exc}", name="path", value=str(source)
        ) from exc
    if root.tag != "VTKFile" or root.get("type") != "Collection":
        raise InvalidInputError(
            f"{str(source)!r} is not a ParaView collection (.pvd)", name="path", value=str(source)
        )
    return [
        (float(item.get("timestep", "nan")), source.parent / str(item.get("file")))
        for item in root.iter("DataSet")
    ]
