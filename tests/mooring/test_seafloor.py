"""MoorDyn's 3D seafloor (SeafloorFile): reading the grid, the statics and runs of a chain on a
sloping seabed against the closed form, and MoorDyn itself on the same file."""

from __future__ import annotations

import csv
import dataclasses
import math
import shutil
from pathlib import Path

import numpy as np
import pytest

from vinculo import cli
from vinculo.errors import InvalidInputError, MooringFileError
from vinculo.mooring import parse_moordyn, read_moordyn, solve_catenary, weight_in_water
from vinculo.mooring.analysis import run, statics
from vinculo.mooring.catenary import solve_catenary_on_slope
from vinculo.mooring.moordyn_file import format_moordyn, write_moordyn
from vinculo.mooring.motion import Motion
from vinculo.mooring.seafloor import Seafloor, read_seafloor

DATA = Path(__file__).resolve().parent.parent / "data" / "moordyn"
FLOOR = DATA / "seafloors" / "slope.txt"
SLOPE = 0.05  # seafloors/slope.txt: z_b = -60 + 0.05 x


def _copy(tmp_path: Path, segments: int | None = None) -> Path:
    """chain_on_slope.txt and its seafloor file in ``tmp_path`` (segments changed if asked)."""
    (tmp_path / "seafloors").mkdir()
    shutil.copy(FLOOR, tmp_path / "seafloors")
    text = (DATA / "chain_on_slope.txt").read_text()
    if segments is not None:
        text = text.replace("320.0     40 ", f"320.0     {segments} ")
    path = tmp_path / "chain_on_slope.txt"
    path.write_text(text)
    return path


def _closed_form(model, fairlead=None):
    kind = model.line_types["chain"]
    a = np.array(model.points[0].position)
    b = np.array(model.points[1].position if fairlead is None else fairlead)
    o = model.options
    w = weight_in_water(kind.mass_per_length, kind.diameter, o.density, o.gravity)
    return solve_catenary_on_slope(b[0] - a[0], b[2] - a[2], model.lines[0].unstretched_length,
                                   w, kind.ea, slope=SLOPE)


def test_the_grid_file_is_read_with_its_plane_and_its_mean_depth():
    floor = read_seafloor(FLOOR)
    assert floor.z.shape == (4, 2)
    # Bilinear interpolation of a plane is the plane; beyond the grid, the edge's height.
    x = np.array([-300.0, -123.4, 0.0, 99.0, 500.0])
    expected = np.where(x <= 100.0, -60.0 + SLOPE * x, -55.0)
    np.testing.assert_allclose(floor.height(x, np.full(5, 7.0)), expected, rtol=0, atol=1e-12)
    assert floor.slope(-123.4, 7.0) == pytest.approx((SLOPE, 0.0), abs=1e-15)
    assert floor.mean_depth == pytest.approx(66.25, rel=1e-15)


def test_a_file_without_water_depth_takes_the_grids_mean_depth(tmp_path):
    path = _copy(tmp_path)
    text = path.read_text().replace("75.0          WtrDpth       water depth (m)\n", "")
    model = parse_moordyn(text, path)
    assert model.options.depth == pytest.approx(66.25, rel=1e-15)
    assert model.options.seafloor == read_seafloor(tmp_path / "seafloors" / "slope.txt")


@pytest.mark.parametrize(("text", "line", "field", "words"), [
    ("2 1\n0 1\n0\n", None, "nx ny", "3 lines"),
    ("2 x\n0 1\n0\n0 0 -1\n1 0 -1\n", 1, "nx ny", "not a finite number"),
    ("2 1\n0 1 2\n0\n0 0 -1\n1 0 -1\n", 2, "x ticks", "3 values"),
    ("2 2\n0 1\n5 5\n0 5 -1\n1 5 -1\n", 3, "y tick", "not above"),
    ("2 1\n0 1\n0\n0 0 -1\n0.5 0 -1\n", 5, "x", "not one of the x ticks"),
    ("2 1\n0 1\n0\n0 0 -1\n0 0 -2\n", 5, "x y", "second time"),
    ("2 2\n0 1\n0 1\n0 0 -1\n1 0 -1\n1 1 -1\n", None, "x y", "(0, 1)"),
    ("1 1\n0\n0\n0 0 deep\n", 4, "x y z", "'deep'"),
])
def test_a_malformed_seafloor_file_names_the_file_line_and_field(tmp_path, text, line, field,
                                                                  words):
    path = tmp_path / "floor.txt"
    path.write_text(text)
    with pytest.raises(MooringFileError) as info:
        read_seafloor(path)
    error = info.value
    assert (error.file, error.line, error.field) == (str(path), line, field)
    assert words in str(error) and str(path) in str(error)


def test_a_missing_seafloor_file_is_named_where_the_input_file_names_it(tmp_path):
    text = (DATA / "chain_on_slope.txt").read_text()
    path = tmp_path / "mooring.txt"
    path.write_text(text)
    with pytest.raises(MooringFileError) as info:
        read_moordyn(path)
    number = next(k + 1 for k, ln in enumerate(text.splitlines()) if "SeafloorFile" in ln)
    assert (info.value.line, info.value.field) == (number, "SeafloorFile")
    assert "no such seafloor file" in str(info.value)
    # "0" switches the 3D seafloor off: the flat seabed at the water depth.
    model = parse_moordyn(text.replace("seafloors/slope.txt  SeafloorFile",
                                       "0  SeafloorFile"), path)
    assert model.options.seafloor is None


def test_a_model_with_a_seafloor_is_written_back_and_read_the_same(tmp_path):
    model = read_moordyn(DATA / "chain_on_slope.txt")
    again = parse_moordyn(format_moordyn(model), tmp_path / "again.txt")
    assert dataclasses.replace(again, path=None) == dataclasses.replace(model, path=None)
    # A grid built in code is written beside the file, which names it.
    floor = Seafloor.from_function([-400.0, 100.0], [0.0], lambda x, y: -60.0 + SLOPE * x)
    built = dataclasses.replace(model, path=None, options=dataclasses.replace(
        model.options, seafloor=floor))
    with pytest.raises(InvalidInputError, match="seafloor_path"):
        format_moordyn(built)
    path = write_moordyn(built, tmp_path / "written.txt")
    assert read_moordyn(path).options.seafloor == floor
    assert (tmp_path / "written_seafloor.txt").is_file()


def test_the_slope_catenary_on_a_level_seabed_is_the_flat_one():
    # slope 0: the closed form of the flat seabed (solve_catenary), the same numbers.
    w = weight_in_water(126.0, 0.137)
    flat = solve_catenary(300.0, 40.0, 315.0, w, 5.0e8)
    level = solve_catenary_on_slope(300.0, 40.0, 315.0, w, 5.0e8, slope=0.0)
    assert level.horizontal_tension == pytest.approx(flat.horizontal_tension, rel=1e-12)
    assert level.laid_length == pytest.approx(flat.laid_length, rel=1e-12)
    assert level.fairlead_tension == pytest.approx(flat.fairlead_tension, rel=1e-12)


def test_statics_on_the_slope_is_the_sloping_catenary(tmp_path, capsys):
    # 160 segments: the lumped-mass discretisation error is then below the 1e-3 asserted
    # (measured 3e-4 on H). The closed form is docs/theory/catenary.md, "A sloping seabed".
    path = _copy(tmp_path, segments=160)
    model = read_moordyn(path)
    assert cli.main(["mooring", "statics", str(path), "--output", str(tmp_path / "out")]) == 0
    capsys.readouterr()
    with (tmp_path / "out" / "statics.csv").open() as handle:
        rows = list(csv.DictReader(handle))
    a, b = ({k: float(v) for k, v in r.items() if k != "end"} for r in rows)
    cat = _closed_form(model)
    assert -b["fx"] == pytest.approx(cat.horizontal_tension, rel=1e-3)
    assert a["fx"] == pytest.approx(cat.horizontal_tension, rel=1e-3)
    assert -b["fz"] == pytest.approx(cat.fairlead_vertical_tension, rel=1e-3)
    assert b["tension"] == pytest.approx(cat.fairlead_tension, rel=1e-3)
    assert a["tension"] == pytest.approx(cat.anchor_tension, rel=1e-3)
    segment = 320.0 / 160
    assert abs(a["laid_length"] - cat.laid_length) <= segment
    # A flat seabed at the anchor's depth would hold the line very differently (its H is
    # 77 % higher).
    flat = solve_catenary(300.0, 65.0, 320.0, cat.weight, 5.0e8)
    assert flat.horizontal_tension / cat.horizontal_tension - 1.0 > 0.5


def test_a_level_grid_holds_the_line_as_the_flat_seabed_does(tmp_path):
    # The chain on a flat seabed (chain_on_seabed.txt, 50 m deep) and the same chain on a
    # grid of equal heights -50: the same equilibrium (rounding apart).
    flat = read_moordyn(DATA / "chain_on_seabed.txt")
    floor = Seafloor.from_function([-400.0, 0.0, 100.0], [-10.0, 10.0],
                                   lambda x, y: np.full_like(x, -50.0))
    grid = dataclasses.replace(flat, options=dataclasses.replace(flat.options, seafloor=floor))
    on_flat, on_grid = statics(flat), statics(grid)
    for e, g in zip(on_flat.ends, on_grid.ends, strict=True):
        assert g.force == pytest.approx(e.force, rel=1e-9, abs=1e-6)
        assert g.laid_length == e.laid_length


@pytest.mark.parametrize("amplitude", [-3.0, 3.0])
def test_a_slow_surge_follows_the_sloping_catenary(amplitude):
    # The fairlead moved by 3 m over a quarter of a 240 s period (at rest there): nodes land
    # on the slope and leave it as the touchdown point moves (contact events on the grid),
    # and the fairlead's force ends at the closed form of its new position, within the
    # discretisation error (5e-4 at 40 segments, statics) and the slow motion's lag (the
    # measured differences are 1e-3 to 4e-3; 6e-3 asserted).
    model = read_moordyn(DATA / "chain_on_slope.txt")
    fairlead = np.array(model.points[1].position)
    motion = Motion.harmonic([fairlead], (amplitude, 0.0, 0.0), period=240.0)
    result = run(model, motion, 60.0, dt=0.05, plots=False)
    assert result.solution.steps_rejected > 0  # a node landed or lifted within a step
    force = result.end_forces[-1, 0, 1]
    cat = _closed_form(model, fairlead + np.array([amplitude, 0.0, 0.0]))
    assert -force[0] == pytest.approx(cat.horizontal_tension, rel=6e-3)
    assert -force[2] == pytest.approx(cat.fairlead_vertical_tension, rel=6e-3)


def test_moordyn_settles_on_the_slope_where_vinculos_statics_is(tmp_path):
    # MoorDyn 2.x on the same file: its initial-condition solve stops on this slope with the
    # chain still slack at the anchor (a force of 0 N along x there), but its dynamics from
    # there settle within 60 s about vinculo's equilibrium; the mean of its fairlead force
    # over the next 60 s is within 1e-4 of it (measured 1.0e-5 along x, 7.5e-6 along z).
    from vinculo.mooring.peer import moordyn_available, settled_end_forces

    if not moordyn_available():
        pytest.skip("MoorDyn's Python package is not installed")
    path = _copy(tmp_path)
    model = read_moordyn(path)
    mean = settled_end_forces(path, 120.0, 60.0)[0, 1]
    ours = next(e for e in statics(model).ends if e.end == "B").force
    assert mean[0] == pytest.approx(ours[0], rel=1e-4)
    assert mean[2] == pytest.approx(ours[2], rel=1e-4)
    assert math.isclose(ours[1], 0.0, abs_tol=1e-6)


BATHYMETRY = """----- MoorDyn Bathymetry Input File ----
nGridX 4
nGridY 2
       -400.0 -200.0 0.0 100.0
-50.0   80.0 70.0 60.0 55.0
 50.0   80.0 70.0 60.0 55.0
"""


def test_moordyn_f_bathymetry_as_water_depth_is_the_same_seabed(tmp_path):
    # MoorDyn-F's layout of the grid of seafloors/slope.txt (depths positive down), given as
    # WtrDpth: the same heights, and the same equilibrium.
    (tmp_path / "bathymetry.dat").write_text(BATHYMETRY)
    floor = read_seafloor(tmp_path / "bathymetry.dat")
    assert floor == read_seafloor(FLOOR)
    assert floor.layout == "F"
    text = (DATA / "chain_on_slope.txt").read_text()
    text = text.replace("75.0          WtrDpth", "bathymetry.dat  WtrDpth").replace(
        "seafloors/slope.txt  SeafloorFile", "0  SeafloorFile")
    path = tmp_path / "f.txt"
    path.write_text(text)
    model = read_moordyn(path)
    assert model.options.seafloor == floor
    assert model.options.depth == pytest.approx(66.25, rel=1e-15)
    ours = statics(model).ends
    reference = statics(read_moordyn(DATA / "chain_on_slope.txt")).ends
    for a, b in zip(ours, reference, strict=True):
        assert a.force == pytest.approx(b.force, rel=1e-12, abs=1e-9)
    # Written back for MoorDyn-C: the grid in its layout beside the file.
    (tmp_path / "out").mkdir()
    again = read_moordyn(write_moordyn(model, tmp_path / "out" / "c.txt"))
    assert again.options.seafloor == floor and again.options.seafloor.layout == "C"
    # Two seafloors (WtrDpth and SeafloorFile) are one too many.
    shutil.copytree(DATA / "seafloors", tmp_path / "seafloors")
    both = text.replace("0  SeafloorFile", "seafloors/slope.txt  SeafloorFile")
    with pytest.raises(MooringFileError, match="a second seafloor"):
        parse_moordyn(both, path)


@pytest.mark.parametrize(("text", "line", "field"), [
    ("title\nnGridX 2\nnGrid 1\n0 1\n0 5 5\n", 3, "nGridY"),
    ("title\nnGridX 2\nnGridY 1\n0 1 2\n0 5 5\n", 4, "x ticks"),
    ("title\nnGridX 2\nnGridY 1\n0 1\n0 5\n", 5, "y depths"),
    ("title\nnGridX 2\nnGridY 2\n0 1\n0 5 5\n", None, "nGridY"),
    ("title\nnGridX 2\nnGridY 1\n1 0\n0 5 5\n", 4, "x ticks"),
    ("title\nnGridX 2.5\nnGridY 1\n0 1\n0 5 5\n", 2, "nGridX"),
])
def test_a_malformed_bathymetry_file_names_the_line_and_field(tmp_path, text, line, field):
    path = tmp_path / "bathymetry.dat"
    path.write_text(text)
    with pytest.raises(MooringFileError) as info:
        read_seafloor(path)
    assert (info.value.file, info.value.line, info.value.field) == (str(path), line, field)
