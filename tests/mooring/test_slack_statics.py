"""The static equilibrium of a line whose spare length carries no tension.

`tests/data/moordyn/surface_float.txt`: a surface float (0.63 m of line 0.82 m across, stiff in
bending) on a 16 m tether from an anchor 16 m deep. The float pulls the tether straight up to
the surface, and the tether's spare length stands on the anchor, held straight by its bending
stiffness: its segments there are shorter than their length and, as MoorDyn's segments, carry
no compression. The statics with segments that can push found only compressed equilibria there
and stopped with a ConvergenceError after its 1,000 iterations; it now ends with the segments
as a run has them (``vinculo.mooring.statics``).

References, derived here: along a vertical line under tension, fully under water, each segment's
tension exceeds the one below it by the segment's weight in water, (m - rho pi d^2 / 4) g l (the
vertical equilibrium of the node between them, whose drag and friction vanish at rest); and a
static equilibrium of a run's own equations is where the run stays at rest.
"""

import math
from pathlib import Path

import numpy as np
import pytest

from vinculo.mooring.analysis import run
from vinculo.mooring.model import build_model

FILE = Path(__file__).parent.parent / "data" / "moordyn" / "surface_float.txt"
RHO, G = 1025.0, 9.80665  # MoorDyn's default water density and gravity (the file sets neither)


def test_the_spare_tether_is_slack_and_the_rest_hangs_by_its_weight():
    model = build_model(FILE)
    statics = model.statics
    assert statics.method == "slack continuation"
    tether, float_ = model.lines
    positions = statics.positions
    tension = tether.tensions(statics)[0]
    length = tether.unstretched_length / len(tether.segments)
    chords = np.linalg.norm(np.diff(positions[tether.nodes], axis=0), axis=1)
    slack = tension == 0.0
    # The spare length: the lowest segments, shorter than their length, without tension.
    assert 1 <= slack.sum() <= 3 and np.all(slack[: slack.sum()])
    assert np.all(chords[slack] < length)
    # The rest is taut and straight up from the anchor, fully under water.
    assert np.all(tension[~slack] > 0.0)
    np.testing.assert_allclose(positions[tether.nodes][:, :2], 0.0, atol=1e-9)
    assert positions[tether.nodes][:, 2].max() < -0.1
    # Each taut segment carries the one below it and a segment's weight in water (away from
    # the two next to the spare length, where the bending of unevenly spaced nodes acts).
    # Measured: within 3e-6 relative, but 1.5e-5 (8e-4 N) at the top, where the bending stiffness
    # (EI / l^3 = 242 N/m) feels the segments' stretch growing with the tension (3e-6 m from one
    # to the next) with no segment above to balance it.
    kind = tether.line_type
    wet_weight = (kind.mass_per_length - RHO * math.pi * kind.diameter ** 2 / 4) * G * length
    taut = np.flatnonzero(~slack)[2:]
    np.testing.assert_allclose(np.diff(tension[taut]), wet_weight, rtol=5e-5)
    # The float pierces the surface z = 0.
    heights = positions[float_.nodes][:, 2]
    assert heights.min() < 0.0 < heights.max()


def test_a_run_stays_at_rest_in_the_slack_equilibrium():
    result = run(FILE, None, 2.0, dt=0.01, plots=False)
    positions = np.asarray(result.solution.positions)
    # The run's own equations (inertia, damping, the trapezoidal rule, segments going slack)
    # balance there: nothing moves beyond round-off.
    assert np.abs(positions - positions[0]).max() < 1e-9
    tensions = np.asarray(result.segment_tensions)
    np.testing.assert_allclose(tensions[-1], tensions[0], atol=1e-6)


def test_the_shape_of_a_vertical_line_is_drawn_on_a_readable_axis():
    from matplotlib.figure import Figure

    from vinculo.mooring.plots import LEAST_WIDTH, _horizontal, _widen

    model = build_model(FILE)
    nodes = model.statics.positions[model.lines[0].nodes]
    reach = _horizontal(nodes, nodes[0])
    # The tether stands straight up: its nodes' horizontal distances are round-off.
    assert np.ptp(reach) < 1e-9
    ax = Figure().subplots()
    ax.plot(reach, nodes[:, 2])
    _widen(ax, reach, nodes[:, 2])
    low, high = ax.get_xlim()
    # The axis spans a fifth of the line's height about it, not its round-off.
    assert high - low == pytest.approx(LEAST_WIDTH * np.ptp(nodes[:, 2]), rel=1e-12)
    assert low < reach.min() and reach.max() < high


def test_the_command_lists_the_slack_segments(tmp_path, capsys):
    from vinculo.cli import main

    # The tether's spare length: its two lowest segments (the first test), and nothing else.
    assert main(["mooring", "statics", str(FILE), "--output", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "spare length lying slack): line 1: 2\n" in out


def test_the_stiffness_at_the_float_is_that_of_the_slack_equilibrium():
    from vinculo.mooring.statics import point_force, point_stiffness, solve_statics

    # Reference: central differences of the force on the float's lower point over equilibria
    # re-solved with the point held at moved positions (each found with the slack segments).
    model = build_model(FILE)
    statics = model.statics
    point = model.points[1]
    k = point_stiffness(model.system, statics, point.index)
    h = 1e-3
    fd = np.zeros((3, 3))
    for j in range(3):
        forces = []
        for sign in (1.0, -1.0):
            moved = model.system.copy()
            q = np.asarray(statics.positions).copy()
            q[point.index, j] += sign * h
            moved.set_initial_state(q)
            for axis in range(3):
                moved.add_fixed_coordinate(point, axis, float(q[point.index, axis]))
            forces.append(point_force(moved, solve_statics(moved), point.index))
        fd[:, j] = -(forces[0] - forces[1]) / (2.0 * h)
    # Measured: 7e-10 of the largest entry. With the compliant rows the spare length's
    # segments, which carry nothing, stiffened the vertical entry to 1.6e6 N/m (3,295 N/m).
    np.testing.assert_allclose(k, fd, atol=1e-6 * np.abs(fd).max())
