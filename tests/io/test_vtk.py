"""ParaView time series: the VTK files hold the particles, links and tensions of each time."""

from __future__ import annotations

import meshio
import numpy as np
import pytest

import vinculo
from vinculo.io import export_vtk, read_pvd


def small_run() -> tuple[vinculo.Solution, list[vinculo.ConstraintId]]:
    """Three bobs in a chain hung from a point; the last one kept in the x-z plane."""
    system = vinculo.System(gravity=(0.0, 0.0, -9.81))
    a = system.add_particle(1.0, (1.0, 0.0, 0.0))
    b = system.add_particle(2.0, (2.0, 0.0, 0.0))
    c = system.add_particle(0.5, (2.0, 0.0, -0.5), velocity=(0.1, 0.0, 0.0))
    constraints = [
        system.add_distance_to_point(a, (0.0, 0.0, 0.0), length=1.0),
        system.add_distance(a, b),
        system.add_distance(b, c),
        system.add_fixed_coordinate(c, "y"),
    ]
    return vinculo.simulate(system, t_end=0.2, dt=1e-2), constraints


def test_each_file_holds_the_positions_links_and_tensions_of_its_time(tmp_path):
    solution, constraints = small_run()
    index = export_vtk(solution, tmp_path / "series")
    assert index == tmp_path / "series" / "state.pvd"
    entries = read_pvd(index)
    assert [t for t, _ in entries] == list(solution.times)
    k = 7
    time, path = entries[k]
    assert time == solution.times[k]
    mesh = meshio.read(path)
    assert np.array_equal(mesh.points, solution.positions[k])
    lines = mesh.cells_dict["line"]
    # Only the particle-particle distances are lines: a-b (0-1) and b-c (1-2).
    assert lines.tolist() == [[0, 1], [1, 2]]
    assert mesh.cells_dict["vertex"].ravel().tolist() == [0, 1, 2]
    assert np.array_equal(mesh.point_data["velocity"], solution.velocities[k])
    assert np.array_equal(mesh.point_data["mass"], solution.system.masses())
    tension = mesh.cell_data_dict["tension"]["line"]
    expected = [solution.distance_tension(c)[k] for c in constraints[1:3]]
    np.testing.assert_allclose(tension, expected, rtol=1e-15)
    assert mesh.cell_data_dict["constraint"]["line"].tolist() == [1, 2]


def test_every_kth_time_and_the_last_one(tmp_path):
    solution, _ = small_run()
    entries = read_pvd(export_vtk(solution, tmp_path / "series", name="chain", every=3))
    count = len(solution.times)
    expected = sorted({*range(0, count, 3), count - 1})
    assert [t for t, _ in entries] == [solution.times[k] for k in expected]
    assert sorted(p.name for p in (tmp_path / "series").iterdir()) == sorted(
        ["chain.pvd", *(p.name for _, p in entries)]
    )


def test_a_non_empty_folder_is_kept_unless_overwrite(tmp_path):
    solution, _ = small_run()
    folder = tmp_path / "series"
    folder.mkdir()
    (folder / "notes.txt").write_text("mine")
    with pytest.raises(vinculo.InvalidInputError, match="not empty") as info:
        export_vtk(solution, folder)
    assert info.value.name == "folder"
    assert [p.name for p in folder.iterdir()] == ["notes.txt"]
    export_vtk(solution, folder, overwrite=True, every=10)
    assert not (folder / "notes.txt").exists()
    assert (folder / "state.pvd").is_file()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["series"]


@pytest.mark.parametrize(
    "arguments, name",
    [({"every": 0}, "every"), ({"name": "a/b"}, "name"), ({"name": ".hidden"}, "name")],
)
def test_bad_settings_are_refused(tmp_path, arguments, name):
    solution, _ = small_run()
    with pytest.raises(vinculo.InvalidInputError) as info:
        export_vtk(solution, tmp_path / "series", **arguments)
    assert info.value.name == name
    assert list(tmp_path.iterdir()) == []


def test_bad_folders_are_refused(tmp_path):
    solution, _ = small_run()
    (tmp_path / "file").write_text("x")
    with pytest.raises(vinculo.InvalidInputError, match="not a folder"):
        export_vtk(solution, tmp_path / "file")
    with pytest.raises(vinculo.InvalidInputError, match="does not exist"):
        export_vtk(solution, tmp_path / "missing" / "series")


def test_an_interrupted_export_leaves_nothing(tmp_path, monkeypatch):
    solution, _ = small_run()
    written = []
    original = meshio.write

    def failing(path, mesh, **kwargs):
        if len(written) == 3:
            raise OSError("disk full")
        written.append(path)
        original(path, mesh, **kwargs)

    monkeypatch.setattr(meshio, "write", failing)
    with pytest.raises(OSError, match="disk full"):
        export_vtk(solution, tmp_path / "series")
    assert list(tmp_path.iterdir()) == []


def test_files_get_the_usual_permissions(tmp_path):
    import os

    solution, _ = small_run()
    umask = os.umask(0o022)
    try:
        index = export_vtk(solution, tmp_path / "series", every=100)
    finally:
        os.umask(umask)
    assert (tmp_path / "series").stat().st_mode & 0o777 == 0o755
    assert index.stat().st_mode & 0o777 == 0o644
