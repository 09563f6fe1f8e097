"""The MoorDyn peer runner (vinculo.mooring.peer): MoorDyn's own equilibrium of the example
files against the closed-form elastic catenary (two independent computations of the same line),
and a slow fairlead motion that MoorDyn follows quasi-statically."""

import math
from pathlib import Path

import numpy as np
import pytest

from vinculo.errors import InvalidInputError
from vinculo.mooring import Motion, read_moordyn, solve_catenary, weight_in_water

moordyn = pytest.importorskip("moordyn")
from vinculo.mooring.peer import largest_stable_step, run_moordyn  # noqa: E402

DATA = Path(__file__).resolve().parent.parent / "data" / "moordyn"


def _catenary(model, fairlead=None):
    """The closed-form catenary of a one-line file from its point 1 to its point 2."""
    line = model.lines[0]
    kind = model.line_types[line.line_type]
    a = np.array(model.points[0].position)
    b = np.array(model.points[1].position if fairlead is None else fairlead)
    o = model.options
    w = weight_in_water(kind.mass_per_length, kind.diameter, o.density, o.gravity)
    on_seabed = math.isclose(a[2], -o.depth)
    return solve_catenary(math.hypot(*(b - a)[:2]), b[2] - a[2], line.unstretched_length, w,
                          kind.ea, seabed_contact=on_seabed)


@pytest.mark.parametrize(("name", "tmax"), [("taut_line", "10.0"), ("hanging_line", None)])
def test_moordyns_equilibrium_is_the_elastic_catenary(tmp_path, name, tmax):
    # MoorDyn's initial-condition solve of a 20-segment line against the closed form: within
    # the lumped-mass discretisation error (3e-4 for the hanging chain, 2e-6 for the taut rope,
    # measured; 1e-3 asserted). The taut rope settles within 10 s of MoorDyn's solve (TmaxIC).
    text = (DATA / f"{name}.txt").read_text()
    if tmax is not None:
        text = text.replace("100.0         TmaxIC", f"{tmax}  TmaxIC")
    path = tmp_path / f"{name}.txt"
    path.write_text(text)
    model = read_moordyn(path)
    run = run_moordyn(path, None, 0.1)
    cat = _catenary(model)
    force_a, force_b = run.end_forces[0, 0]
    # The force of the line on the fairlead pulls it towards the anchor and down.
    assert force_b[0] == pytest.approx(-cat.horizontal_tension, rel=1e-3)
    assert force_b[2] == pytest.approx(-cat.fairlead_vertical_tension, rel=1e-3)
    assert np.linalg.norm(force_b) == pytest.approx(cat.fairlead_tension, rel=1e-3)
    assert np.linalg.norm(force_a) == pytest.approx(cat.anchor_tension, rel=1e-3)


def test_a_slow_fairlead_motion_is_followed_quasi_statically(tmp_path):
    # The taut rope's fairlead moved 1 m towards the anchor and back over 200 s: slow enough
    # that drag and inertia are negligible, so the fairlead force follows the catenary at the
    # displaced position (closed form, within the 1e-3 of the lumped masses).
    path = tmp_path / "taut_line.txt"
    path.write_text((DATA / "taut_line.txt").read_text().replace("100.0         TmaxIC",
                                                                 "10.0  TmaxIC"))
    model = read_moordyn(path)
    start = np.array([model.points[1].position])
    motion = Motion.harmonic(start, (-1.0, 0.0, 0.0), period=200.0)
    run = run_moordyn(path, motion, 50.0, dt_output=5.0, time_step=4e-4)
    assert run.error is None and run.times[-1] == pytest.approx(50.0)
    for i in (5, 10):  # t = 25 s and 50 s
        fairlead = motion.positions(run.times[i])[0]
        cat = _catenary(model, fairlead)
        assert run.end_tensions[i, 0, 1] == pytest.approx(cat.fairlead_tension, rel=1e-3)
    # The moving fairlead changes the tension by far more than that tolerance.
    assert abs(run.end_tensions[10, 0, 1] / run.end_tensions[0, 0, 1] - 1.0) > 0.1


def test_a_motion_with_the_wrong_number_of_points_is_rejected():
    motion = Motion.still([[0.0, 0.0, -5.0], [1.0, 0.0, -5.0]])
    with pytest.raises(InvalidInputError, match="2 points but the file has 1 coupled"):
        run_moordyn(DATA / "taut_line.txt", motion, 1.0)


@pytest.mark.slow
def test_largest_stable_step_of_the_hanging_chain():
    # MoorDyn's explicit RK2 step is bounded by the axial wave crossing a segment,
    # dt ~ l / sqrt(EA / m) (5 m / sqrt(1e8 / 20) = 2.2 ms, times a factor of order one); the
    # bisection finds a step of that order, and a step 1.5 x above it fails.
    path = DATA / "hanging_line.txt"
    model = read_moordyn(path)
    motion = Motion.harmonic([model.points[1].position], (1.0, 0.0, 0.0), period=10.0,
                             ramp_time=5.0)
    reference = run_moordyn(path, motion, 10.0, time_step=1e-4)
    step, runs = largest_stable_step(path, motion, 10.0, reference, low=1e-4, high=1e-3)
    assert 1e-3 < step < 1e-2
    assert runs >= 3
    bad = run_moordyn(path, motion, 10.0, time_step=1.5 * step)
    assert bad.error is not None or np.max(np.abs(bad.end_tensions - reference.end_tensions)) \
        > 0.05 * np.max(reference.end_tensions)


def test_a_run_from_the_saved_initial_state_is_the_run_from_moordyns_own(tmp_path):
    # MoorDyn's initial-condition solve saved once (SaveState) and loaded by a later run
    # (LoadState) gives that run the state its own solve gives: the same end forces, at t = 0
    # (saved beside the state) and after the fairlead has moved, bit for bit at the same dtM.
    from vinculo.mooring.peer import moordyn_initial_state

    path = DATA / "hanging_line.txt"
    model = read_moordyn(path)
    motion = Motion.harmonic([model.points[1].position], (1.0, 0.0, 0.0), period=10.0,
                             ramp_time=5.0)
    state = moordyn_initial_state(path, motion, tmp_path / "hanging.state", time_step=1e-3)
    own = run_moordyn(path, motion, 2.0, time_step=1e-3)
    loaded = run_moordyn(path, motion, 2.0, time_step=1e-3, initial_state=state)
    assert loaded.error is None and own.error is None
    np.testing.assert_array_equal(loaded.end_forces, own.end_forces)
    np.testing.assert_array_equal(loaded.segment_tensions, own.segment_tensions)
    # The fairlead moved: the forces at the end differ from those at the start.
    assert abs(own.end_tensions[-1, 0, 1] / own.end_tensions[0, 0, 1] - 1.0) > 1e-3
    assert loaded.initial_cpu_time < own.initial_cpu_time


def test_a_missing_initial_state_is_named():
    with pytest.raises(InvalidInputError, match=r"no\.such\.state: no such file"):
        run_moordyn(DATA / "hanging_line.txt", None, 1.0, initial_state="no.such.state")


def test_moordyn_takes_whole_steps_of_the_output_interval():
    # MoorDyn's Step takes steps of dtM until less than dtM of the call is left, then one step
    # of the rest (MoorDyn2.cpp). A call a hair longer than dtM (a coupling interval rounded
    # to divide the output interval) then ends with a step of a millionth of dtM, after which
    # MoorDyn's fairlead tension on the benchmark's cable was 14 times as far from its
    # small-step reference (1.5e-3 against 1.1e-4 of the peak at 0.45 and 0.9 of the largest
    # stable step, 20 segments: errors that must shrink with the step, the scheme being
    # convergent). The runner takes the largest step at most the one asked that divides the
    # output interval, and calls MoorDyn with whole numbers of it.
    path = DATA / "hanging_line.txt"
    model = read_moordyn(path)
    motion = Motion.harmonic([model.points[1].position], (1.0, 0.0, 0.0), period=10.0,
                             ramp_time=5.0)
    asked = run_moordyn(path, motion, 2.0, time_step=0.1 / 47.4, coupling_step=0.1 / 47.4)
    whole = run_moordyn(path, motion, 2.0, time_step=0.1 / 48, coupling_step=0.1 / 48)
    assert asked.time_step == pytest.approx(0.1 / 48, rel=1e-12)
    assert asked.coupling_step == pytest.approx(asked.time_step, rel=1e-12)
    assert asked.steps == whole.steps == 20 * 48
    # The same steps from the same start: the same run, bit for bit.
    np.testing.assert_array_equal(asked.segment_tensions, whole.segment_tensions)
    # Called once an output interval (the benchmark's timed runs), it takes the same steps.
    timed = run_moordyn(path, motion, 2.0, time_step=0.1 / 47.4, coupling_step=0.1)
    assert timed.coupling_step == pytest.approx(0.1) and timed.steps == 20 * 48
    with pytest.raises(InvalidInputError, match="time_step"):
        run_moordyn(path, motion, 2.0, time_step=0.0)
