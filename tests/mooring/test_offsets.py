"""The offset curve of a mooring (``vinculo.mooring.offset_curve``, ``vinculo mooring
offsets``): against the elastic catenary in closed form, against the analytic stiffness at zero
offset, and what a sweep keeps when an offset fails."""

import csv
import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest

import vinculo.mooring as mooring
from vinculo import cli
from vinculo.errors import ConvergenceError, InvalidInputError

DATA = Path(__file__).resolve().parent.parent / "data" / "moordyn"
OC3 = DATA / "oc3_hywind.txt"
OC3_POINTS = {p.id: p.position for p in mooring.read_moordyn(OC3).points}
CHAIN = DATA / "chain_on_seabed.txt"


def test_a_single_line_follows_the_elastic_catenary_over_its_offsets():
    # Reference: the elastic catenary with a frictionless seabed in closed form
    # (docs/theory/catenary.md) at each moved fairlead, the anchor 300 + s m away and 40 m
    # below. The fairlead tension is held to 1e-3 of itself, and the horizontal and anchor
    # tensions, a tenth of it where the line lies slackest (-15 m), to 1e-3 of it; the laid
    # length within a segment. Those are discretisation errors of the touchdown: measured at
    # -15 m, the anchor tension 1.2e-2, 1.7e-3, 6.1e-4 and 1.8e-4 of the fairlead tension off
    # at 80, 160, 320 and 640 segments; 320 here.
    model = mooring.read_moordyn(CHAIN)
    model = dataclasses.replace(model, lines=(dataclasses.replace(model.lines[0],
                                                                  segments=320),))
    offsets = [-15.0, -5.0, 0.0, 5.0, 10.0]
    curve = mooring.offset_curve(model, offsets, heading=0.0)
    assert not curve.failed
    kind = model.line_types["chain"]
    o = model.options
    w = mooring.weight_in_water(kind.mass_per_length, kind.diameter, o.density, o.gravity)
    for i, s in enumerate(offsets):
        cat = mooring.solve_catenary(300.0 + s, 40.0, 315.0, w, kind.ea, seabed_contact=True)
        # The line pulls the fairlead back towards the anchor (-x): restoring +H.
        assert abs(curve.restoring[i] - cat.horizontal_tension) <= 1e-3 * cat.fairlead_tension
        assert curve.end_tensions[i, 0, 1] == pytest.approx(cat.fairlead_tension, rel=1e-3)
        assert abs(curve.end_tensions[i, 0, 0] - cat.anchor_tension) <= (
            1e-3 * cat.fairlead_tension)
        assert abs(curve.laid_lengths[i, 0] - cat.laid_length_stretched) <= 315.0 / 320
    # A tauter line pulls harder: the curve rises with the offset.
    assert np.all(np.diff(curve.restoring) > 0.0)


@pytest.mark.parametrize(("heading", "row"), [(0.0, 0), (90.0, 1), (30.0, None)])
def test_the_curves_slope_at_zero_is_the_analytic_stiffness(heading, row):
    # Central differences of the restoring force over +-1 cm of offset against d^T K_uu d of
    # the vessel stiffness from the analytic Jacobian (two independent computations: re-solved
    # equilibria, and the Schur complement of one): to 1e-5 relative (O(h^2) truncation).
    curve = mooring.offset_curve(OC3, [-0.01, 0.0, 0.01], heading=heading)
    slope = (curve.restoring[2] - curve.restoring[0]) / 0.02
    k = mooring.statics(OC3).vessel_stiffness()[:3, :3]
    d = curve.direction
    assert d == pytest.approx([math.cos(math.radians(heading)), math.sin(math.radians(heading)),
                               0.0])
    expected = d @ k @ d
    if row is not None:
        assert expected == pytest.approx(k[row, row], rel=1e-12)
    assert slope == pytest.approx(expected, rel=1e-5)
    # At zero offset the mooring is balanced horizontally by its symmetry (to round-off of
    # the 1 MN tensions).
    assert abs(curve.restoring[1]) < 1e-5 * curve.end_tensions[1].max()


@pytest.mark.parametrize(("axis", "reference"), [((0.0, 0.0, 1.0), (0.0, 0.0, 0.0)),
                                                 ((1.0, 0.0, 0.0), (0.0, 0.0, -20.0)),
                                                 ((0.0, 1.0, 1.0), (1.0, 2.0, 0.0))])
def test_the_rotation_curves_slope_at_zero_is_the_analytic_stiffness(axis, reference):
    # Rotations of the fairleads by +-0.01 degree about an axis through a reference point:
    # central differences of the restoring moment per radian against d^T K_tt d of the vessel
    # stiffness about that point (to 1e-5, O(h^2)); at zero angle the moment is the fairlead
    # forces' r x F, which the mooring's symmetry balances about the spar's axis.
    curve = mooring.offset_curve(OC3, [-0.01, 0.0, 0.01], rotation_axis=axis,
                                 reference=reference)
    assert curve.rotation
    slope = (curve.restoring[2] - curve.restoring[0]) / math.radians(0.02)
    d = np.asarray(axis) / np.linalg.norm(axis)
    k = mooring.statics(OC3).vessel_stiffness(reference)[3:, 3:]
    assert slope == pytest.approx(d @ k @ d, rel=1e-5)
    statics = mooring.statics(OC3)
    forces = statics.point_forces()
    arms = np.array([OC3_POINTS[k] for k in (4, 5, 6)]) - np.asarray(reference)
    np.testing.assert_allclose(curve.moments[1], np.cross(arms, forces).sum(axis=0),
                               atol=1e-9 * np.abs(forces).max())


def test_a_failed_offset_is_reported_and_the_others_kept(monkeypatch):
    # The equilibrium at one offset fails (here made to fail): its row is NaN with the error's
    # message, and the other offsets are the same as in a sweep without it.
    import vinculo.mooring.analysis as analysis

    real = analysis.statics

    def failing(model, **options):
        if model.points[3].position[0] > 5.2 + 7.0:
            raise ConvergenceError("no equilibrium found (made to fail)")
        return real(model, **options)

    whole = mooring.offset_curve(OC3, [-5.0, 0.0, 5.0], heading=0.0)
    monkeypatch.setattr(analysis, "statics", failing)
    curve = mooring.offset_curve(OC3, [-5.0, 0.0, 5.0, 10.0], heading=0.0)
    assert list(curve.failed) == [10.0]
    assert "made to fail" in curve.failed[10.0]
    assert np.all(np.isnan(curve.forces[3])) and np.all(np.isnan(curve.end_tensions[3]))
    np.testing.assert_array_equal(curve.forces[:3], whole.forces)


def test_bad_offset_requests_are_refused():
    with pytest.raises(InvalidInputError, match="heading"):
        mooring.offset_curve(OC3, [1.0])
    with pytest.raises(InvalidInputError, match="one of the three"):
        mooring.offset_curve(OC3, [1.0], heading=0.0, direction=(1.0, 0.0, 0.0))
    with pytest.raises(InvalidInputError, match="not all zero"):
        mooring.offset_curve(OC3, [1.0], direction=(0.0, 0.0, 0.0))
    with pytest.raises(InvalidInputError, match="rotation_axis as three finite numbers"):
        mooring.offset_curve(OC3, [1.0], rotation_axis=(0.0, math.inf, 1.0))
    with pytest.raises(InvalidInputError, match="reference point"):
        mooring.offset_curve(OC3, [1.0], heading=0.0, reference=(0.0, 0.0))
    with pytest.raises(InvalidInputError, match="finite offsets"):
        mooring.offset_curve(OC3, [1.0, math.nan], heading=0.0)
    anchored = mooring.read_moordyn(CHAIN)
    fixed = tuple(dataclasses.replace(p, attachment="fixed") for p in anchored.points)
    with pytest.raises(InvalidInputError, match="no coupled"):
        mooring.offset_curve(dataclasses.replace(anchored, points=fixed), [1.0], heading=0.0)


def test_the_offsets_command_writes_the_curve(tmp_path, capsys):
    output = tmp_path / "out"
    code = cli.main(["mooring", "offsets", str(OC3), "--max", "10", "--count", "3",
                     "--heading", "90", "--output", str(output)])
    assert code == 0
    out = capsys.readouterr().out
    assert "moved along heading 90 deg, 3 offsets from -10 to 10 m" in out
    with (output / "offsets.csv").open() as handle:
        rows = list(csv.reader(handle))
    curve = mooring.offset_curve(OC3, [-10.0, 0.0, 10.0], heading=90.0)
    assert rows[0] == curve.columns()
    assert rows[0][:8] == ["offset", "fx", "fy", "fz", "mx", "my", "mz", "restoring"]
    table = np.array(rows[1:], dtype=float)
    np.testing.assert_array_equal(table[:, 0], [-10.0, 0.0, 10.0])
    np.testing.assert_array_equal(table[:, 7], curve.restoring)
    assert (output / "offsets.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_the_offsets_command_turns_the_points(tmp_path, capsys):
    # --about z: the fairleads turned about the vertical through the origin, the restoring
    # moment per radian at small angles OC3's yaw stiffness (11.55 MN m/rad; the curve's
    # secant over 1 degree within 1e-3 of it).
    output = tmp_path / "out"
    assert cli.main(["mooring", "offsets", str(OC3), "--max", "1", "--count", "3", "--about",
                     "z", "--output", str(output), "--no-plots"]) == 0
    assert "turned about z through (0, 0, 0) m, 3 angles from -1 to 1 deg" in (
        capsys.readouterr().out)
    with (output / "offsets.csv").open() as handle:
        table = np.array(list(csv.reader(handle))[1:], dtype=float)
    yaw = mooring.statics(OC3).vessel_stiffness()[5, 5]
    assert table[2, 7] / math.radians(1.0) == pytest.approx(yaw, rel=1e-3)


@pytest.mark.parametrize("arguments", [["--max", "0"], ["--max", "5", "--count", "1"],
                                       ["--max", "5", "--heading", "inf"],
                                       ["--max", "5", "--heading", "10", "--about", "z"],
                                       ["--max", "5", "--about", "w"]])
def test_bad_offsets_arguments_exit_with_code_2(arguments, capsys):
    with pytest.raises(SystemExit) as info:
        cli.main(["mooring", "offsets", str(OC3), *arguments])
    assert info.value.code == 2
    assert "usage: vinculo mooring offsets" in capsys.readouterr().err


def test_the_command_reports_a_failed_offset_and_writes_the_others(tmp_path, capsys,
                                                                    monkeypatch):
    # An offset whose equilibrium fails (made to fail) is printed with its message, its row of
    # offsets.csv is NaN, the other rows are written, and the command exits with 1.
    import vinculo.mooring.analysis as analysis

    real = analysis.statics

    def failing(model, **options):
        if model.points[3].position[0] > 5.2 + 7.0:
            raise ConvergenceError("no equilibrium found (made to fail)")
        return real(model, **options)

    monkeypatch.setattr(analysis, "statics", failing)
    output = tmp_path / "out"
    code = cli.main(["mooring", "offsets", str(OC3), "--max", "10", "--count", "3",
                     "--output", str(output), "--no-plots"])
    assert code == 1
    assert "offset 10 m: no equilibrium: no equilibrium found (made to fail)" in (
        capsys.readouterr().out)
    with (output / "offsets.csv").open() as handle:
        table = np.array(list(csv.reader(handle))[1:], dtype=float)
    assert np.all(np.isfinite(table[:2, 1:])) and np.all(np.isnan(table[2, 1:]))
