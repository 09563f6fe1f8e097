"""MoorDyn's output channels (OUTPUTS): their values against the closed-form catenary and the
prescribed motion, the CSV a run writes, and the names refused."""

from __future__ import annotations

import csv
import math
from pathlib import Path

import numpy as np
import pytest

from vinculo import cli
from vinculo.errors import MooringFileError
from vinculo.mooring import read_moordyn, solve_catenary, weight_in_water
from vinculo.mooring.analysis import run
from vinculo.mooring.bench import motion_for

DATA = Path(__file__).resolve().parent.parent / "data" / "moordyn"
CHANNELS = ["FAIRTEN1", "AnchTen1", "L1N20T", "L1N40PZ", "CON2PX", "Con2vX", "LINE1TENA",
            "Point2PZ", "CON1FX", "CON1FZ", "CON2FZ"]


def _file(tmp_path: Path) -> Path:
    """hanging_line.txt with 40 segments and the channels above."""
    text = (DATA / "hanging_line.txt").read_text().replace("100.0     20 ", "100.0     40 ")
    text = text.replace("------------------------- need this line",
                        "---------------------- OUTPUTS ---------\n" + "\n".join(CHANNELS)
                        + "\nEND\n------------------------- need this line")
    path = tmp_path / "hanging.txt"
    path.write_text(text)
    return path


def test_channels_are_the_catenary_at_rest_and_follow_the_motion(tmp_path):
    model = read_moordyn(_file(tmp_path))
    assert model.outputs == tuple(CHANNELS)
    motion = motion_for(model)
    result = run(model, motion, 5.0, dt=0.05, plots=False)
    values = result.channels()
    assert list(values) == CHANNELS
    # At t = 0 (the statics): the elastic catenary between the two points (40 segments: the
    # lumped-mass error below the 1e-3 asserted), the mid node's tension that at s = L/2.
    kind = model.line_types["chain"]
    w = weight_in_water(kind.mass_per_length, kind.diameter, model.options.density,
                        model.options.gravity)
    cat = solve_catenary(80.0, 0.0, 100.0, w, kind.ea, seabed_contact=False)
    assert values["FAIRTEN1"][0] == pytest.approx(cat.fairlead_tension, rel=1e-3)
    assert values["AnchTen1"][0] == pytest.approx(cat.anchor_tension, rel=1e-3)
    assert values["L1N20T"][0] == pytest.approx(float(cat.tension(50.0)), rel=1e-3)
    assert math.isclose(values["L1N20T"][0], cat.fairlead_tension, rel_tol=1e-3) is False
    np.testing.assert_array_equal(values["LINE1TENA"], values["AnchTen1"])
    # The coupled point follows the motion exactly; the line's last node is that point.
    times = np.asarray(result.times)
    x = np.array([motion.positions(t)[0][0] for t in times])
    vx = np.array([motion.velocities(t)[0][0] for t in times])
    np.testing.assert_allclose(values["CON2PX"], x, rtol=0, atol=1e-9)
    # Its velocity is the time rule's (trapezoidal: the velocity of the positions, second
    # order), within h^2/6 |x'''| of the motion's (A omega^3 = 2 m (2 pi / 10 s)^3; measured
    # 7.8e-5 m/s at h = 0.05 s).
    bound = 0.05**2 / 6.0 * 2.0 * (2.0 * math.pi / 10.0) ** 3
    np.testing.assert_allclose(values["Con2vX"], vx, rtol=0, atol=bound)
    np.testing.assert_array_equal(values["L1N40PZ"], values["Point2PZ"])
    # The anchor's load at rest: the catenary's pull, H towards the fairlead and V_A, up, with
    # the points' weight (none here); the two points together carry the chain's weight in
    # water (100 m of it, hanging symmetric at t = 0).
    assert values["CON1FX"][0] == pytest.approx(cat.horizontal_tension, rel=1e-3)
    assert values["CON1FZ"][0] == pytest.approx(values["CON2FZ"][0], rel=1e-9)
    assert values["CON1FZ"][0] + values["CON2FZ"][0] == pytest.approx(-w * 100.0, rel=1e-9)


def test_a_run_writes_the_channels_beside_its_results(tmp_path, capsys):
    path = _file(tmp_path)
    motion = tmp_path / "still.csv"
    motion.write_text("time,x,y,z\n0,40,0,-20\n10,40,0,-20\n")
    assert cli.main(["mooring", "run", str(path), "--motion", str(motion), "--t-end", "1",
                     "--dt", "0.1", "--no-plots", "--no-progress", "--output",
                     str(tmp_path / "out")]) == 0
    capsys.readouterr()
    with (tmp_path / "out" / "channels.csv").open() as handle:
        rows = list(csv.reader(handle))
    assert rows[0] == ["time", *CHANNELS] and len(rows) == 12
    # At rest: the fairlead tension stays the statics' (the same particle and state).
    fair = [float(r[1]) for r in rows[1:]]
    assert max(fair) - min(fair) < 1e-6 * fair[0]


@pytest.mark.parametrize("name", ["BODY1PX", "L1N5AX", "FAIRTEN", "ROD1SUB", "CON1AX"])
def test_a_channel_vinculo_cannot_give_is_refused_by_line(tmp_path, name):
    text = (DATA / "hanging_line.txt").read_text().replace(
        "------------------------- need this line",
        f"---------------------- OUTPUTS ---------\nFAIRTEN1\n{name}\nEND\n"
        "------------------------- need this line")
    path = tmp_path / "bad.txt"
    path.write_text(text)
    with pytest.raises(MooringFileError) as info:
        read_moordyn(path)
    number = next(k + 1 for k, ln in enumerate(text.splitlines()) if ln == name)
    assert (info.value.line, info.value.field) == (number, "OUTPUTS")
    assert name in str(info.value)


PENDULUM = """--------------------- MoorDyn Input File ------------------------------------
A 100 kg bob on a 10 m neutrally buoyant rope, released at rest 5 degrees from the vertical
---------------------- LINE TYPES ----------------------------------------------
TypeName  Diam   Mass/m   EA     BA/-zeta  EI  Cd   Ca   CdAx  CaAx
(name)    (m)    (kg/m)   (N)    (N-s/-)   (N-m^2) (-) (-) (-)   (-)
rope      0.01   {rho}  1.0e9  0.0      0   0.0  0.0  0.0   0.0
---------------------- POINTS --------------------------------------------------
ID  Attachment  X       Y    Z       Mass  Volume  CdA  Ca
(#) (-)         (m)     (m)  (m)     (kg)  (m^3)   (m^2) (-)
1   Fixed       0.0     0.0  -5.0    0     0       0    0
2   Free        {x}  0.0  {z}   100   0       0    0
---------------------- LINES ---------------------------------------------------
ID  LineType  AttachA  AttachB  UnstrLen  NumSegs  LineOutputs
(#) (name)    (#)      (#)      (m)       (-)      (-)
1   rope      1        2        10.0      1        -
---------------------- OPTIONS -------------------------------------------------
200.0         WtrDpth    water depth (m)
---------------------- OUTPUTS -------------------------------------------------
CON2PX
------------------------- need this line ---------------------------------------
"""


def test_a_run_from_the_files_positions_swings_the_pendulum_it_describes(tmp_path):
    # start="file": the bob released where the file puts it, at rest (MoorDyn without its
    # initial condition). A pendulum of 10 m, 5 degrees: its period is
    # 2 pi sqrt(L m_i / (m g)) (1 + theta^2 / 16 + 11 theta^4 / 3072), m_i = 100.4 kg with the
    # rope's half segment lumped on the bob (neutrally buoyant: inertia, no weight); the run's
    # period between two upward crossings of x = 0 meets it within 1e-4 (the trapezoidal
    # rule's phase error at 5 ms is 2e-6, the amplitude term 4.8e-4). From the statics it would
    # hang still.
    theta = math.radians(5.0)
    rho = 1025.0 * math.pi * 0.01**2 / 4.0
    text = PENDULUM.replace("{rho}", repr(rho)).replace(
        "{x}", repr(10.0 * math.sin(theta))).replace("{z}", repr(-5.0 - 10.0 * math.cos(theta)))
    path = tmp_path / "pendulum.txt"
    path.write_text(text)
    result = run(path, None, 14.0, dt=0.005, plots=False, start="file")
    t, x = np.asarray(result.times), result.channels()["CON2PX"]
    assert x[0] == pytest.approx(10.0 * math.sin(theta), rel=1e-12)
    up = [t[k] - x[k] * (t[k + 1] - t[k]) / (x[k + 1] - x[k])
          for k in range(len(t) - 1) if x[k] < 0.0 <= x[k + 1]]
    inertia = 100.0 + rho * 10.0 / 2.0
    g = 9.80665
    period = (2.0 * math.pi * math.sqrt(10.0 * inertia / (100.0 * g))
              * (1.0 + theta**2 / 16.0 + 11.0 * theta**4 / 3072.0))
    assert len(up) >= 2
    assert up[1] - up[0] == pytest.approx(period, rel=1e-4)
    still = run(path, None, 1.0, dt=0.005, plots=False).channels()["CON2PX"]
    assert np.abs(still).max() < 1e-9
    # A free point's net force is its mass times its acceleration, not a load: refused.
    from vinculo.errors import InvalidInputError
    from vinculo.mooring.channels import channel_values, parse_channel

    with pytest.raises(InvalidInputError, match="is free"):
        channel_values(result, parse_channel("CON2FX"))


def test_a_shape_without_a_catenary_holds_no_tension():
    # A neutrally buoyant line (no catenary: no weight) of 32 m between points 29.7 m apart:
    # its initial shape is a parabola of arc length 32 m with the nodes at equal arc lengths,
    # so that every segment's chord is at most its length (slack, no tension), and close to it
    # (within 5 %: the last segments bend round the parabola's lower end, up to 3.5 % short;
    # the first fifteen within 1e-4).
    import vinculo
    from vinculo.mooring.line import LineType, Water, add_line

    system = vinculo.System(gravity=(0.0, 0.0, -9.80665))
    a = system.add_particle(1.0, (0.0, -1.0, 0.0), fixed=True)
    b = system.add_particle(10.0, (10.0, -1.0, -28.0))
    rope = LineType("rope", 0.1, 1025.0 * math.pi * 0.1**2 / 4.0, 1e9)
    line = add_line(system, a.index, b.index, rope, 32.0, 20, Water(depth=500.0))
    q = np.asarray(system.initial_positions())[line.nodes]
    chords = np.linalg.norm(np.diff(q, axis=0), axis=1)
    assert np.all(chords <= 32.0 / 20 * (1.0 + 1e-12))
    assert np.all(chords >= 32.0 / 20 * (1.0 - 0.05))
    assert np.all(chords[:15] >= 32.0 / 20 * (1.0 - 1e-4))
