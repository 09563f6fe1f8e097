"""``vinculo mooring statics`` and ``vinculo.mooring.statics`` against the closed-form elastic
catenary with a frictionless seabed (docs/theory/catenary.md): end tensions to 1e-3 relative and
the laid length to a segment length, for a line resting on the seabed and a taut one; and the
exact columns of statics.csv."""

import csv
import math
from pathlib import Path

import numpy as np
import pytest

from vinculo import cli
from vinculo.mooring import parse_moordyn, read_moordyn, solve_catenary, weight_in_water
from vinculo.mooring.analysis import STATICS_COLUMNS

DATA = Path(__file__).resolve().parent.parent / "data" / "moordyn"


def _catenary(model):
    line = model.lines[0]
    kind = model.line_types[line.line_type]
    a, b = (np.array(p.position) for p in model.points[:2])
    o = model.options
    w = weight_in_water(kind.mass_per_length, kind.diameter, o.density, o.gravity)
    return solve_catenary(math.hypot(*(b - a)[:2]), b[2] - a[2], line.unstretched_length, w,
                          kind.ea, seabed_contact=math.isclose(a[2], -o.depth))


def _file(tmp_path, name, segments=None):
    """A data file, with its number of segments changed if asked."""
    text = (DATA / f"{name}.txt").read_text()
    if segments is not None:
        model = read_moordyn(DATA / f"{name}.txt")
        old = model.lines[0].segments
        row = next(ln for ln in text.splitlines() if ln.startswith("1   ") and f" {old} " in ln)
        text = text.replace(row, row.replace(f" {old} ", f" {segments} "))
        assert parse_moordyn(text).lines[0].segments == segments
    path = tmp_path / f"{name}.txt"
    path.write_text(text)
    return path


@pytest.mark.parametrize(("name", "segments"), [("chain_on_seabed", 160), ("taut_line", 20),
                                                ("hanging_line", 40)])
def test_statics_csv_is_the_elastic_catenary(tmp_path, capsys, name, segments):
    path = _file(tmp_path, name, segments)
    model = read_moordyn(path)
    assert cli.main(["mooring", "statics", str(path), "--output", str(tmp_path / "out")]) == 0
    out = capsys.readouterr().out
    assert "laid" in out and "tension" in out
    with (tmp_path / "out" / "statics.csv").open() as handle:
        rows = list(csv.reader(handle))
    assert tuple(rows[0]) == STATICS_COLUMNS
    assert [r[:3] for r in rows[1:]] == [["1", "A", "1"], ["1", "B", "2"]]
    a, b = ({k: float(v) for k, v in zip(rows[0], r, strict=True) if k not in ("end",)}
            for r in rows[1:])
    for end, point in ((a, model.points[0]), (b, model.points[1])):
        np.testing.assert_allclose([end["x"], end["y"], end["z"]], point.position, atol=1e-9)
        assert end["tension"] == pytest.approx(math.hypot(end["fx"], end["fy"], end["fz"]))
    cat = _catenary(model)
    heading = np.sign(model.points[1].position[0] - model.points[0].position[0])
    # The line pulls the fairlead (end B) towards the anchor and down, the anchor (end A)
    # towards the fairlead: H along the line's heading, V_B and V_A vertical.
    assert b["tension"] == pytest.approx(cat.fairlead_tension, rel=1e-3)
    assert a["tension"] == pytest.approx(cat.anchor_tension, rel=1e-3)
    assert -b["fx"] * heading == pytest.approx(cat.horizontal_tension, rel=1e-3)
    assert -b["fz"] == pytest.approx(cat.fairlead_vertical_tension, rel=1e-3)
    assert a["fx"] * heading == pytest.approx(cat.horizontal_tension, rel=1e-3)
    segment = model.lines[0].unstretched_length / model.lines[0].segments
    assert a["laid_length"] == b["laid_length"]
    assert abs(a["laid_length"] - cat.laid_length_stretched) <= segment


def test_python_api_matches_the_command(tmp_path):
    import vinculo.mooring as mooring

    result = mooring.statics(DATA / "taut_line.txt")
    assert [(e.line, e.end, e.point) for e in result.ends] == [(1, "A", 1), (1, "B", 2)]
    path = result.to_csv(tmp_path / "statics.csv")
    with path.open() as handle:
        rows = list(csv.DictReader(handle))
    assert float(rows[1]["tension"]) == pytest.approx(result.ends[1].tension, rel=1e-15)
