"""NetCDF archives of a run: the file holds exactly the Solution's arrays, with units."""

from __future__ import annotations

import numpy as np
import pytest

import vinculo
from vinculo.buoy import BuoyCase
from vinculo.io import load_netcdf, save_netcdf
from vinculo.io.netcdf import tensions

PER_TIME = [
    "constraint_residual",
    "newton_iterations",
    "step_sizes",
    "residual_norms",
    "increment_norms",
]


def small_run() -> tuple[vinculo.Solution, list[vinculo.ConstraintId]]:
    """A double pendulum hung from a point, with a third bob kept in the x-z plane."""
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
    return vinculo.simulate(system, t_end=0.3, dt=1e-2), constraints


def test_round_trip_gives_the_solutions_arrays_exactly(tmp_path):
    solution, _ = small_run()
    path = save_netcdf(solution, tmp_path / "run.nc")
    data = load_netcdf(path)
    assert np.array_equal(data["time"].values, solution.times)
    assert np.array_equal(data["positions"].values, solution.positions)
    assert np.array_equal(data["velocities"].values, solution.velocities)
    assert np.array_equal(data["multipliers"].values, solution.multipliers)
    for name in PER_TIME:
        assert np.array_equal(data[name].values, getattr(solution, name)), name
    assert data["newton_iterations"].dtype == np.int64
    assert np.array_equal(data["masses"].values, solution.system.masses())
    assert list(data["constraint_names"].values) == solution.system.constraint_names()
    assert list(data["constraint_kinds"].values) == [
        "point distance", "distance", "distance", "fixed coordinate"
    ]
    assert list(data["component"].values) == ["x", "y", "z"]
    assert data.sizes == {"time": len(solution.times), "particle": 3, "component": 3,
                          "constraint": 4}


def test_tensions_in_the_file_equal_distance_tension(tmp_path):
    solution, constraints = small_run()
    data = load_netcdf(save_netcdf(solution, tmp_path / "run.nc"))
    tension = data["tension"].values
    for c in constraints[:3]:
        assert np.array_equal(tension[:, c.index], solution.distance_tension(c))
    # The fixed coordinate is not a distance: no tension, its multiplier is a force in N.
    assert np.isnan(tension[:, constraints[3].index]).all()
    assert list(data["multiplier_units"].values) == ["N m-1", "N m-1", "N m-1", "N"]
    assert np.array_equal(tensions(solution), tension, equal_nan=True)
    # The hanging bobs pull on their links.
    assert (tension[1:, :3] > 0).all()


def test_units_version_solver_status_and_parameters_are_stored(tmp_path):
    solution, _ = small_run()
    case = BuoyCase()
    path = solution.save_netcdf(
        tmp_path / "run.nc", attributes={"case": case.to_dict(), "frequency": 0.9, "label": None,
                                         "tagged": True}
    )
    data = load_netcdf(path)
    for name, variable in data.variables.items():
        assert "units" in variable.attrs and "long_name" in variable.attrs, name
    assert data["positions"].attrs["units"] == "m"
    assert data["velocities"].attrs["units"] == "m s-1"
    assert data["tension"].attrs["units"] == "N"
    assert data["time"].attrs["units"] == "s"
    assert data.attrs["vinculo_version"] == vinculo.__version__
    assert data.attrs["linear_solver"] == solution.linear_solver != ""
    assert data.attrs["status"] == "completed"
    assert data.attrs["frequency"] == 0.9
    assert data.attrs["tagged"] == "true"
    assert "label" not in data.attrs
    assert data.attrs["case.amplitude"] == case.amplitude
    assert data.attrs["case.attachment"] == case.attachment
    assert np.array_equal(data.attrs["case.tank_size"], case.tank_size)
    assert np.array_equal(data.attrs["gravity"], [0.0, 0.0, -9.81])


def test_a_failed_run_is_saved_with_its_status(tmp_path):
    # A bob on a 1 m string, launched at 6 m/s (below the 7 m/s = sqrt(5 g L) that would carry
    # it over the top), rises above the pivot and the string goes slack: the run stops early.
    system = vinculo.System(gravity=(0.0, 0.0, -9.81))
    bob = system.add_particle(1.0, (0.0, 0.0, -1.0), velocity=(6.0, 0.0, 0.0))
    string = system.add_distance_to_point(bob, (0.0, 0.0, 0.0), length=1.0)
    system.set_tension_only(string)
    with pytest.raises(vinculo.NegativeTensionError) as info:
        vinculo.simulate(system, t_end=2.0, dt=1e-3)
    partial = info.value.solution
    data = load_netcdf(save_netcdf(partial, tmp_path / "failed.nc"))
    assert data.attrs["status"] == "failed"
    assert data.attrs["error_message"]
    assert np.array_equal(data["positions"].values, partial.positions)


@pytest.mark.parametrize(
    "name, expected",
    [("run.txt", "unknown suffix"), ("missing/run.nc", "does not exist"), ("folder.nc", "folder")],
)
def test_bad_paths_are_refused_before_writing(tmp_path, name, expected):
    solution, _ = small_run()
    (tmp_path / "folder.nc").mkdir()
    with pytest.raises(vinculo.InvalidInputError, match=expected) as info:
        save_netcdf(solution, tmp_path / name)
    assert info.value.name == "path"
    assert str(tmp_path / name) in str(info.value)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["folder.nc"]


def test_bad_attributes_are_refused_and_nothing_is_written(tmp_path):
    solution, _ = small_run()
    with pytest.raises(vinculo.InvalidInputError, match="'status' is set by vinculo"):
        save_netcdf(solution, tmp_path / "run.nc", attributes={"status": "fine"})
    with pytest.raises(vinculo.InvalidInputError, match="'model'") as info:
        save_netcdf(solution, tmp_path / "run.nc", attributes={"model": object()})
    assert info.value.name == "model"
    assert list(tmp_path.iterdir()) == []


def test_an_interrupted_write_leaves_no_file(tmp_path, monkeypatch):
    import xarray

    solution, _ = small_run()
    target = tmp_path / "run.nc"
    target.write_bytes(b"previous")

    def broken(self, path, **kwargs):
        with open(path, "wb") as f:
            f.write(b"half")
        raise OSError("disk full")

    monkeypatch.setattr(xarray.Dataset, "to_netcdf", broken)
    with pytest.raises(OSError, match="disk full"):
        save_netcdf(solution, target)
    assert [p.name for p in tmp_path.iterdir()] == ["run.nc"]
    assert target.read_bytes() == b"previous"


def test_loading_a_missing_or_foreign_file_is_an_invalid_input(tmp_path):
    with pytest.raises(vinculo.InvalidInputError, match="no NetCDF file"):
        load_netcdf(tmp_path / "absent.nc")
    (tmp_path / "text.nc").write_text("not netcdf")
    with pytest.raises(vinculo.InvalidInputError, match="cannot read"):
        load_netcdf(tmp_path / "text.nc")


def test_the_file_gets_the_usual_permissions(tmp_path):
    import os

    solution, _ = small_run()
    umask = os.umask(0o022)
    try:
        path = save_netcdf(solution, tmp_path / "run.nc")
    finally:
        os.umask(umask)
    assert path.stat().st_mode & 0o777 == 0o644
