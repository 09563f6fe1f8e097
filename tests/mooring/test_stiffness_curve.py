"""MoorDyn's nonlinear EA (a strain-tension file in a line type's EA column): reading it, a clump
weight stretching a rope along the curve in closed form, and MoorDyn itself on a taut rope."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from vinculo.errors import InvalidInputError, MooringFileError
from vinculo.mooring import read_moordyn
from vinculo.mooring.analysis import run, statics
from vinculo.mooring.model import build_model
from vinculo.mooring.moordyn_file import write_moordyn
from vinculo.mooring.stiffness_curve import StiffnessCurve, read_stiffness_curve

DATA = Path(__file__).resolve().parent.parent / "data" / "moordyn" / "nonlinear"
G = 9.80665

CLUMP = """--------------------- MoorDyn Input File ------------------------------------
A clump weight of {mass} kg on a 50 m rope of the same density as the water
---------------------- LINE TYPES ----------------------------------------------
TypeName  Diam   Mass/m   EA         BA/-zeta  EI  Cd   Ca   CdAx  CaAx
(name)    (m)    (kg/m)   (N)        (N-s/-)   (N-m^2) (-) (-) (-)   (-)
rope      0.05   {rho}  curve.txt  {ba}     0   0.0  1.0  0.0   0.0
---------------------- POINTS --------------------------------------------------
ID  Attachment  X       Y    Z       Mass    Volume  CdA  Ca
(#) (-)         (m)     (m)  (m)     (kg)    (m^3)   (m^2) (-)
1   Fixed       0.0     0.0  -10.0   0       0       0    0
2   Free        0.0     0.0  -60.0   {mass}  0       0    0
---------------------- LINES ---------------------------------------------------
ID  LineType  AttachA  AttachB  UnstrLen  NumSegs  LineOutputs
(#) (name)    (#)      (#)      (m)       (-)      (-)
1   rope      1        2        50.0      10       -
---------------------- OPTIONS -------------------------------------------------
200.0         WtrDpth    water depth (m)
------------------------- need this line ---------------------------------------
"""
CURVE = "---- rope ----\nStrain Tension\n(-) (N)\n0.0 0.0\n0.01 1.0e4\n0.05 1.0e5\n"


def _clump(tmp_path: Path, mass: float, ba: str = "100.0") -> Path:
    (tmp_path / "curve.txt").write_text(CURVE)
    path = tmp_path / "clump.txt"
    rho = repr(1025.0 * math.pi * 0.05**2 / 4.0)  # neutrally buoyant: the rope weighs nothing
    path.write_text(CLUMP.replace("{mass}", f"{mass:g}").replace("{rho}", rho)
                    .replace("{ba}", ba))
    return path


@pytest.mark.parametrize("mass", [500.0, 2000.0, 12000.0])
def test_a_clump_weight_stretches_the_rope_along_its_curve(tmp_path, mass):
    # The rope carries the weight W = m g all along: it is stretched to L (1 + e(W)), e the
    # curve read the other way (piecewise linear: 1e6 N per unit strain to 1 %, then 2.25e6,
    # continued beyond 5 %: 500 kg on the first piece, 2 t on the second, 12 t beyond).
    built = build_model(_clump(tmp_path, mass))
    tip = np.asarray(built.statics.positions)[built.points[1].index]
    weight = mass * G
    pieces = [(0.0, 0.0, 1e6), (0.01, 1e4, 2.25e6)]
    e0, t0, stiffness = pieces[1] if weight > 1e4 else pieces[0]
    strain = e0 + (weight - t0) / stiffness
    assert tip[2] == pytest.approx(-10.0 - 50.0 * (1.0 + strain), abs=1e-9)
    # The tension the run's output gives from the positions is the curve's at the stretch.
    result = run(_clump(tmp_path, mass), None, 1.0, dt=0.1, plots=False)
    tensions = result.segment_tensions
    np.testing.assert_allclose(tensions[-1], weight, rtol=1e-6)


def test_the_curve_is_read_and_read_back(tmp_path):
    curve = read_stiffness_curve(DATA / "rope_ea.txt")
    np.testing.assert_array_equal(curve.strains, [0.0, 0.005, 0.02])
    assert curve.stiffest == pytest.approx(1.6e7, rel=1e-12)
    # Both ways, and along the end pieces beyond the points.
    for strain, tension in [(0.0025, 1e4), (0.01, 1e5), (0.03, 4.2e5), (-0.001, -4e3)]:
        assert curve.tension(strain) == pytest.approx(tension, rel=1e-12)
        assert curve.strain(tension) == pytest.approx(strain, rel=1e-12)
    model = read_moordyn(DATA / "taut_rope.txt")
    written = write_moordyn(model, tmp_path / "w.txt")
    again = read_moordyn(written)
    assert again.line_types["rope"].ea_curve == curve
    # MoorDyn 2.7 reads an empty last line of a curve file as a point: none is written.
    assert not (tmp_path / "w_rope_ea.txt").read_text().endswith("\n")


@pytest.mark.parametrize(("text", "line", "field"), [
    ("h\nh\nh\n0 0\n0.01\n", 5, "strain tension"),
    ("h\nh\nh\n0 0\n0.01 ten\n", 5, "tension"),
    ("h\nh\nh\n0 0\n0.01 5\n0.02 4\n", 6, "tension"),
    ("h\nh\nh\n0 0\n", None, "strain tension"),
    ("h\nh\nh\n0.001 0\n0.01 5\n", 4, "strain tension"),
])
def test_a_malformed_curve_names_the_file_line_and_field(tmp_path, text, line, field):
    path = tmp_path / "curve.txt"
    path.write_text(text)
    with pytest.raises(MooringFileError) as info:
        read_stiffness_curve(path)
    assert (info.value.file, info.value.line, info.value.field) == (str(path), line, field)
    with pytest.raises(InvalidInputError, match="increase"):
        StiffnessCurve(np.array([0.0, 0.1]), np.array([1.0, 1.0]))


def test_a_missing_curve_and_a_damping_ratio_with_a_curve_are_refused(tmp_path):
    path = _clump(tmp_path, 500.0)
    (tmp_path / "curve.txt").unlink()
    with pytest.raises(MooringFileError, match="no such strain-tension file") as info:
        read_moordyn(path)
    assert info.value.field == "EA"
    path = _clump(tmp_path, 500.0, ba="-0.8")
    with pytest.raises(MooringFileError, match="damping ratio") as info:
        read_moordyn(path)
    assert info.value.field == "BA/-zeta"


def test_moordyn_settles_on_the_nonlinear_rope_where_vinculos_statics_is():
    # MoorDyn 2.7.2 on the same file (taut_rope.txt, its curve rewritten beside the copy it
    # runs): its dynamics from its own initial condition settle about vinculo's equilibrium;
    # the mean of its fairlead force over 10 s is within 2e-5 of it (measured 2e-6 and 3e-6).
    from vinculo.mooring.peer import moordyn_available, settled_end_forces

    if not moordyn_available():
        pytest.skip("MoorDyn's Python package is not installed")
    path = DATA / "taut_rope.txt"
    mean = settled_end_forces(path, 20.0, 10.0)[0, 1]
    ours = np.array(next(e for e in statics(read_moordyn(path)).ends if e.end == "B").force)
    np.testing.assert_allclose(mean, ours, rtol=0, atol=2e-5 * np.abs(ours).max())
