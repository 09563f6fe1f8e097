"""BODIES in MoorDyn files: Fixed and Coupled bodies place the points attached to them
(``Body<n>``) as MoorDyn does, the statics, stiffness and runs of a coupled body are those of
its points moved rigidly with it, and what is not supported (free bodies) is refused by
name."""

import dataclasses
from pathlib import Path

import numpy as np
import pytest

import vinculo.mooring as mooring
from vinculo import cli
from vinculo.errors import InvalidInputError, MooringFileError
from vinculo.mooring.moordyn_file import format_moordyn, parse_moordyn

DATA = Path(__file__).resolve().parent.parent / "data" / "moordyn"

ROTATED = """--------------------- MoorDyn Input File ------------------------------------
a line from an anchor to a point of a rotated fixed body
----------------------- LINE TYPES ------------------------------------------
TypeName   Diam    Mass/m     EA         BA/-zeta    EI         Cd     Ca     CdAx    CaAx
(name)     (m)     (kg/m)     (N)        (N-s/-)     (N-m^2)    (-)    (-)    (-)     (-)
main       0.1     20.0       1.0E8      -1.0        0          1.2    1.0    0.2     0.0
---------------------------- BODIES -----------------------------------------------------
ID   Attachment  X0    Y0   Z0     r0    p0    y0    Mass  CG*  I*        Volume  CdA*  Ca
(#)  (-)         (m)   (m)  (m)    (deg) (deg) (deg) (kg)  (m)  (kg-m^2)  (m^3)   (m^2) (-)
1    Fixed       10.0  5.0  -20.0  30.0  20.0  40.0  0     0    0         0       0     0
---------------------- POINTS --------------------------------
ID    Type      X       Y       Z       Mass   Volume  CdA    Ca
(#)   (-)       (m)     (m)     (m)     (kg)   (m^3)   (m^2)  (-)
1     Fixed     -40     0       -60     0      0       0      0
2     Body1     3.0     1.0     -2.0    0      0       0      0
---------------------- LINES ----------------------------------------
ID   LineType   AttachA  AttachB  UnstrLen  NumSegs  LineOutputs
(#)   (name)     (#)      (#)       (m)       (-)     (-)
1     main       1        2         70.0      10      -
---------------------- OPTIONS -----------------------------------------
0             writeLog      Write a log file
1E-4          dtM           time step to use in mooring integration (s)
100           WtrDpth       water depth (m)
0.0           TmaxIC        no initial-condition run
------------------------- need this line --------------------------------------
"""


def _oc3_on_a_body(yaw: float = 0.0) -> str:
    """The OC3-Hywind mooring with its fairleads on a Coupled body at the origin turned by
    ``yaw`` degrees (the points' coordinates, in the body's frame, are the file's)."""
    text = (DATA / "oc3_hywind.txt").read_text()
    bodies = ("---------------------- BODIES ---------------------------------------------\n"
              "ID Attachment X0 Y0 Z0 r0 p0 y0 Mass CG I Volume CdA Ca\n"
              "(#) (-) (m) (m) (m) (deg) (deg) (deg) (kg) (m) (kg-m^2) (m^3) (m^2) (-)\n"
              f"1 Coupled 0.0 0.0 0.0 0.0 0.0 {yaw} 0 0 0 0 0 0\n")
    text = text.replace("---------------------- POINTS", bodies + "---------------------- POINTS")
    return text.replace("   Vessel      ", "   Body1       ")


def test_a_body_places_its_points_where_moordyn_does():
    # Reference: MoorDyn 2.7.2's position of the point on a fixed body turned by (30, 20, 40)
    # degrees, read through its API after it reads the same file (to round-off).
    moordyn = pytest.importorskip("moordyn")
    model = parse_moordyn(ROTATED)
    point = model.points[1]
    assert point.body == 1 and point.attachment == "fixed"
    assert point.relative == (3.0, 1.0, -2.0)
    import tempfile

    with tempfile.TemporaryDirectory() as folder:
        file = Path(folder) / "rotated.txt"
        file.write_text(ROTATED)
        system = moordyn.Create(str(file))
        moordyn.Init(system, [], [])
        expected = moordyn.GetPointPos(moordyn.GetPoint(system, 2))
        moordyn.Close(system)
    np.testing.assert_allclose(point.position, expected, atol=1e-12)
    # Written back, the file reads to the same model (the point on its body, in its frame).
    again = parse_moordyn(format_moordyn(model))
    assert again.bodies == model.bodies and again.points == model.points


def test_a_coupled_body_is_its_points():
    # The statics of the OC3 mooring with its fairleads on a Coupled body turned by 25 degrees
    # equal those of the file with Coupled points where the body puts them (the same model,
    # bit for bit), and the body's stiffness about its reference point is the vessel stiffness
    # of those points about it.
    on_body = parse_moordyn(_oc3_on_a_body(25.0))
    points = tuple(dataclasses.replace(p, body=None, relative=None) for p in on_body.points)
    plain = dataclasses.replace(on_body, points=points, bodies=())
    a, b = mooring.statics(on_body), mooring.statics(plain)
    assert [e.tension for e in a.ends] == [e.tension for e in b.ends]
    assert a.coupled_bodies() == [1] and b.coupled_bodies() == []
    np.testing.assert_array_equal(a.body_stiffness(1), b.vessel_stiffness((0.0, 0.0, 0.0)))


def test_the_oc3_spar_as_a_coupled_body_has_its_published_stiffness(tmp_path, capsys):
    # The OC3-Hywind fairleads on a Coupled body at the spar's reference point: the body's 6x6
    # is the published matrix (Jonkman, NREL/TP-500-47535, 2010, eq. 5-3; 0.5 %, as
    # test_vessel_stiffness.py), printed and written by the statics command.
    path = tmp_path / "oc3_body.txt"
    path.write_text(_oc3_on_a_body())
    output = tmp_path / "out"
    assert cli.main(["mooring", "statics", str(path), "--output", str(output)]) == 0
    out = capsys.readouterr().out
    assert "stiffness of the mooring on body 1, about its reference point (0, 0, 0) m" in out
    # The body's points are its own: no second matrix of them as a vessel of coupled points.
    assert "on a vessel carrying points" not in out and not (output / "stiffness.csv").exists()
    assert (output / "point_stiffness.csv").exists()
    k = np.genfromtxt(output / "stiffness_body1.csv", delimiter=",", skip_header=1)[:, 1:]
    for (i, j), value in {(0, 0): 41_180.0, (2, 2): 11_940.0, (3, 3): 311_100_000.0,
                          (5, 5): 11_560_000.0, (0, 4): -2_821_000.0}.items():
        assert k[i, j] == pytest.approx(value, rel=5e-3), (i, j)


def test_what_bodies_do_not_support_yet_is_refused_by_name(tmp_path):
    free = ROTATED.replace("1    Fixed       10.0", "1    Free        10.0")
    with pytest.raises(MooringFileError, match="line 10: Attachment: 'Free': free bodies"):
        parse_moordyn(free)
    missing = ROTATED.replace("2     Body1", "2     Body2")
    with pytest.raises(MooringFileError, match="line 15: Attachment: 'Body2': there is no body"):
        parse_moordyn(missing)
    coupled = parse_moordyn(_oc3_on_a_body())
    statics = mooring.statics(coupled)
    with pytest.raises(InvalidInputError, match="body 2 is not one of the file's bodies"):
        statics.body_stiffness(2)


def test_moordyn_runs_a_coupled_body_as_its_points(tmp_path):
    # The peer runner drives a coupled body in MoorDyn's six degrees of freedom (the motion
    # file's pose, its angles in radians): MoorDyn's run of the OC3 fairleads on a body moved in
    # surge and yaw agrees with its run of the same fairleads as Coupled points moved by the
    # positions the pose gives them, to 1e-5 of the peak tension (measured 4.9e-6; MoorDyn
    # moves a body's points rigidly over each call, the points along their chords). Read as
    # plain points, the motion lacks the body's poses, which the runner says.
    pytest.importorskip("moordyn")
    from vinculo.mooring.peer import run_moordyn

    text = _oc3_on_a_body(25.0).replace("320.0         WtrDpth",
                                        "320.0         WtrDpth\n0.0           TmaxIC")
    model = parse_moordyn(text)
    times = np.arange(0.0, 6.0001, 0.05)
    rows = _body_motion(tmp_path / "body.csv", times)
    expected = _placed(model, rows)
    points = tuple(dataclasses.replace(p, body=None, relative=None) for p in model.points)
    plain = dataclasses.replace(model, points=points, bodies=())
    as_body = run_moordyn(model, mooring.read_motion(model, tmp_path / "body.csv"), 6.0)
    as_points = run_moordyn(plain, mooring.Motion.from_table(times, expected), 6.0)
    assert as_body.error is None and as_points.error is None
    peak = np.abs(as_points.segment_tensions).max()
    assert np.abs(as_body.segment_tensions - as_points.segment_tensions).max() < 1e-5 * peak
    with pytest.raises(InvalidInputError, match="1 coupled bodies and the motion table gives"):
        run_moordyn(model, mooring.Motion.from_table(times, expected), 6.0)


def _placed(model, rows):
    """``(rows, points, 3)``: where body 1's pose in each row of a motion table puts its
    points."""
    body = model.bodies[0]
    return np.array([[dataclasses.replace(body, position=tuple(r[1:4]),
                                          rotation=tuple(r[4:7])).place(p.relative)
                      for p in model.points if p.body == 1] for r in rows])


def _body_motion(path, times):
    """A motion file of the body of _oc3_on_a_body: 2 m of surge and 3 degrees of yaw, both
    with a period of 4 s, from rest at its file pose (25 degrees of yaw), smoothly: its
    velocity and acceleration start from zero, as the equilibrium it starts from has them (a
    recorded motion that starts with an acceleration leaves the trapezoidal rule's velocities
    of the moved points oscillating about the motion's by its spline's jump in jerk)."""
    ramp = (0.5 * (1.0 - np.cos(2.0 * np.pi * times / 4.0))) ** 2
    surge = 2.0 * ramp
    yaw = 25.0 + 3.0 * ramp
    rows = np.column_stack([times, surge, 0.0 * times, 0.0 * times, 0.0 * times, 0.0 * times,
                            yaw])
    header = "time,x,y,z,roll,pitch,yaw\n"
    path.write_text(header + "\n".join(",".join(repr(float(v)) for v in row) for row in rows))
    return rows


def test_a_coupled_body_runs_as_its_points_moved_with_it(tmp_path):
    # A run of the OC3 fairleads on a coupled body, the body moved in surge and yaw by its six
    # columns of the motion file, equals (bit for bit) the run of the same fairleads as
    # Coupled points moved by the positions the body's pose gives them at each row of the file
    # (the same splines through the same samples); and at those rows the run's fairleads are
    # where the pose puts them: to the constraints' tolerance at a step's end, and to 1e-4 m
    # where a node's touchdown shortened the steps and the row falls inside one, whose state is
    # interpolated (measured 1.5e-5 m).
    model = parse_moordyn(_oc3_on_a_body(25.0))
    times = np.arange(0.0, 4.0001, 0.05)
    rows = _body_motion(tmp_path / "body.csv", times)
    expected = _placed(model, rows)
    on_body = mooring.run(model, tmp_path / "body.csv", 4.0, dt=0.05, plots=False)
    points = tuple(dataclasses.replace(p, body=None, relative=None) for p in model.points)
    plain = dataclasses.replace(model, points=points, bodies=())
    as_points = mooring.run(plain, mooring.Motion.from_table(times, expected), 4.0, dt=0.05,
                            plots=False)
    np.testing.assert_array_equal(on_body.end_forces, as_points.end_forces)
    fairleads = [on_body.model.points[k - 1].index for k in (4, 5, 6)]
    stored = on_body.solution.positions[:, fairleads, :]
    np.testing.assert_allclose(stored, expected[: len(on_body.times)], atol=1e-4)
    # The yaw turns the lines' pull: the fairlead tensions change.
    tensions = on_body.end_tensions[:, :, 1]
    assert np.ptp(tensions, axis=0).min() > 1e-3 * tensions.max()


def test_a_body_motion_file_with_the_wrong_columns_is_refused(tmp_path):
    model = parse_moordyn(_oc3_on_a_body())
    path = tmp_path / "points.csv"
    path.write_text("time,x1,y1,z1\n0,0,0,-70\n1,0,0,-70\n")
    with pytest.raises(InvalidInputError, match="1 coupled bodies and 0 coupled points of "
                                                "their own: give time, then x, y, z, roll"):
        mooring.read_motion(model, path)


def test_a_coupled_bodys_offset_curve_turns_it_about_its_reference():
    # The OC3 fairleads on a body turned by 25 degrees, turned further by +-0.01 degree about
    # the vertical through the body's reference point: the restoring moment's slope per radian
    # is the body's yaw stiffness (to 1e-5, central differences; measured 3e-9), with the
    # fairleads 25 degrees off their anchors' bearings, the lines pulling them sideways.
    model = parse_moordyn(_oc3_on_a_body(25.0))
    curve = mooring.offset_curve(model, [-0.01, 0.0, 0.01], rotation_axis=(0.0, 0.0, 1.0),
                                 reference=model.bodies[0].position)
    slope = (curve.restoring[2] - curve.restoring[0]) / np.radians(0.02)
    assert slope == pytest.approx(mooring.statics(model).body_stiffness(1)[5, 5], rel=1e-5)
