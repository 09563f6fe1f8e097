"""MoorDyn's steady current (Currents 1, current_profile.txt): reading it, the drag it puts on a
taut rope against the closed form, and MoorDyn itself on a chain in a current."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest

from vinculo.errors import InvalidInputError, MooringFileError
from vinculo.mooring import read_moordyn
from vinculo.mooring.analysis import statics
from vinculo.mooring.current_profile import CurrentProfile, read_current_profile
from vinculo.mooring.moordyn_file import write_moordyn

DATA = Path(__file__).resolve().parent.parent / "data" / "moordyn" / "current"
HEADER = "--- MoorDyn steady currents File ---\nthe current\nz (m), ux (m/s), uy (m/s), uz (m/s)\n"

TAUT = """--------------------- MoorDyn Input File ------------------------------------
A neutrally buoyant rope stretched across a current (rho pi d^2 / 4 = 2.01258 kg/m)
---------------------- LINE TYPES ----------------------------------------------
TypeName  Diam   Mass/m   EA     BA/-zeta  EI  Cd   Ca   CdAx  CaAx
(name)    (m)    (kg/m)   (N)    (N-s/-)   (N-m^2) (-) (-) (-)   (-)
rope      0.05   {mass}  1.0e8  -1.0      0   1.2  1.0  0.0   0.0
---------------------- POINTS --------------------------------------------------
ID  Attachment  X       Y    Z      Mass  Volume  CdA  Ca
(#) (-)         (m)     (m)  (m)    (kg)  (m^3)   (m^2) (-)
1   Fixed       -50.0   0.0  -20.0  0     0       0    0
2   Fixed        50.0   0.0  -20.0  0     0       0    0
---------------------- LINES ---------------------------------------------------
ID  LineType  AttachA  AttachB  UnstrLen  NumSegs  LineOutputs
(#) (name)    (#)      (#)      (m)       (-)      (-)
1   rope      1        2        99.0      20       -
---------------------- OPTIONS -------------------------------------------------
200.0         WtrDpth    water depth (m)
1             Currents   steady current from current_profile.txt
------------------------- need this line ---------------------------------------
""".replace("{mass}", repr(1025.0 * math.pi * 0.05**2 / 4.0))


def test_the_profile_is_read_and_interpolated_as_moordyns():
    profile = read_current_profile(DATA / "current_profile.txt")
    np.testing.assert_array_equal(profile.heights, [-40.0, -20.0, 0.0])
    # Linear between the heights, the nearest one's value beyond them.
    u = profile.velocity(np.array([-60.0, -30.0, -5.0, 3.0]))
    np.testing.assert_allclose(u[:, 1], [0.2, 0.4, 0.9, 1.0], rtol=0, atol=1e-15)
    assert np.all(u[:, [0, 2]] == 0.0)


@pytest.mark.parametrize(("rows", "line", "field"), [
    ("-10 1 0\n", 4, "z ux uy uz"),
    ("-10 1 0 zero\n", 4, "uz"),
    ("-10 1 0 0\n-20 1 0 0\n", 5, "z"),
    ("\n", None, "z ux uy uz"),
])
def test_a_malformed_profile_names_the_file_line_and_field(tmp_path, rows, line, field):
    path = tmp_path / "current_profile.txt"
    path.write_text(HEADER + rows)
    with pytest.raises(MooringFileError) as info:
        read_current_profile(path)
    assert (info.value.file, info.value.line, info.value.field) == (str(path), line, field)
    with pytest.raises(InvalidInputError, match="increase"):
        CurrentProfile(np.array([0.0, -1.0]), np.zeros((2, 3)))


def test_a_taut_rope_across_a_uniform_current_carries_its_drag(tmp_path):
    # A uniform current U across a straight rope pushes each unit of its (unstretched) length
    # by 1/2 rho Cd d U^2 (MoorDyn's normal drag); the two ends hold the whole of it. Stretched
    # to 1e6 N, the rope bows by 1.5e-3 rad, which takes 2e-6 off the normal velocity's
    # square: the end forces' sum meets q L within 1e-5 (measured 1.1e-6).
    (tmp_path / "current_profile.txt").write_text(HEADER + "-100 0 1.0 0\n0 0 1.0 0\n")
    (tmp_path / "rope.txt").write_text(TAUT)
    ends = statics(tmp_path / "rope.txt").ends
    drag = 0.5 * 1025.0 * 1.2 * 0.05 * 1.0**2 * 99.0
    assert sum(e.force[1] for e in ends) == pytest.approx(drag, rel=1e-5)
    # Along the current, and symmetric.
    assert ends[0].force[1] == pytest.approx(ends[1].force[1], rel=1e-12)


def test_currents_other_than_steady_and_a_missing_profile_are_refused(tmp_path):
    (tmp_path / "rope.txt").write_text(TAUT)
    with pytest.raises(MooringFileError, match="there is no") as info:
        read_moordyn(tmp_path / "rope.txt")
    number = next(k + 1 for k, ln in enumerate(TAUT.splitlines()) if "Currents" in ln)
    assert (info.value.line, info.value.field) == (number, "Currents")
    (tmp_path / "rope.txt").write_text(TAUT.replace("1             Currents",
                                                    "2             Currents"))
    with pytest.raises(MooringFileError, match="only steady currents"):
        read_moordyn(tmp_path / "rope.txt")
    (tmp_path / "rope.txt").write_text(TAUT.replace("1             Currents",
                                                    "0             Currents"))
    assert read_moordyn(tmp_path / "rope.txt").options.current is None


BUOY = """--------------------- MoorDyn Input File ------------------------------------
A 500 kg buoy of 2 m^3 and CdA 1 m^2 on a 50 m tether, neutrally buoyant and without drag
---------------------- LINE TYPES ----------------------------------------------
TypeName  Diam   Mass/m   EA     BA/-zeta  EI  Cd   Ca   CdAx  CaAx
(name)    (m)    (kg/m)   (N)    (N-s/-)   (N-m^2) (-) (-) (-)   (-)
rope      0.05   {mass}  1.0e9  -1.0      0   0.0  1.0  0.0   0.0
---------------------- POINTS --------------------------------------------------
ID  Attachment  X       Y    Z       Mass  Volume  CdA  Ca
(#) (-)         (m)     (m)  (m)     (kg)  (m^3)   (m^2) (-)
1   Fixed       0.0     0.0  -100.0  0     0       0    0
2   Free        0.0     0.0  -50.0   500   2.0     1.0  1.0
---------------------- LINES ---------------------------------------------------
ID  LineType  AttachA  AttachB  UnstrLen  NumSegs  LineOutputs
(#) (name)    (#)      (#)      (m)       (-)      (-)
1   rope      1        2        50.0      10       -
---------------------- OPTIONS -------------------------------------------------
200.0         WtrDpth    water depth (m)
1             Currents   steady current from current_profile.txt
------------------------- need this line ---------------------------------------
""".replace("{mass}", repr(1025.0 * math.pi * 0.05**2 / 4.0))


def test_a_buoy_on_its_tether_leans_in_a_current_by_drag_over_buoyancy(tmp_path):
    # A free point (MoorDyn: volume V, CdA) in a uniform current U on a straight tether: its
    # drag D = 1/2 rho CdA U^2 and net buoyancy B = (rho V - m) g tilt the tether by
    # atan(D / B), stretched by sqrt(D^2 + B^2) / EA. Exact in the statics (the tether carries
    # no load of its own), to 1e-9 m.
    (tmp_path / "current_profile.txt").write_text(HEADER + "-200 0.5 0 0\n0 0.5 0 0\n")
    (tmp_path / "buoy.txt").write_text(BUOY)
    from vinculo.mooring.model import build_model

    built = build_model(tmp_path / "buoy.txt")
    buoy = np.asarray(built.statics.positions)[built.points[1].index]
    rho, g = 1025.0, 9.80665
    drag, lift = 0.5 * rho * 1.0 * 0.5**2, (rho * 2.0 - 500.0) * g
    length = 50.0 * (1.0 + math.hypot(drag, lift) / 1.0e9)
    tilt = math.atan2(drag, lift)
    np.testing.assert_allclose(buoy, [length * math.sin(tilt), 0.0,
                                      -100.0 + length * math.cos(tilt)], rtol=0, atol=1e-9)
    ends = statics(tmp_path / "buoy.txt").ends
    assert ends[1].force == pytest.approx((-drag, 0.0, -lift), rel=1e-9)


def test_a_model_in_a_current_is_written_back_with_its_profile(tmp_path):
    model = read_moordyn(DATA / "chain_in_current.txt")
    again = read_moordyn(write_moordyn(model, tmp_path / "chain.txt"))
    assert (tmp_path / "current_profile.txt").is_file()
    assert dataclasses.replace(again, path=None) == dataclasses.replace(model, path=None)


def test_moordyn_settles_in_the_current_where_vinculos_statics_is():
    # MoorDyn 2.7.2 on the same file: its initial condition leaves the current out (no force
    # across the line at t = 0), its dynamics then settle within 30 s; the mean of its fairlead
    # force over the next 30 s equals vinculo's equilibrium to 1e-6 of the largest component
    # (measured 3e-10: the same lumped-mass model and drag law).
    from vinculo.mooring.peer import moordyn_available, settled_end_forces

    if not moordyn_available():
        pytest.skip("MoorDyn's Python package is not installed")
    path = DATA / "chain_in_current.txt"
    mean = settled_end_forces(path, 60.0, 30.0)[0, 1]
    ours = np.array(next(e for e in statics(read_moordyn(path)).ends if e.end == "B").force)
    assert ours[1] > 300.0  # the current pushes the chain across its plane
    np.testing.assert_allclose(mean, ours, rtol=0, atol=1e-6 * np.abs(ours).max())
