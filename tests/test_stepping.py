"""vinculo.Simulation: stepping, snapshots and driven laws repeat the steps of one simulate() call.

The reference of every bit-for-bit check is an independent run of ``vinculo.simulate`` on a
freshly built model: the stepping object promises (``crates/vinculo/src/run.rs``, module
documentation) that stopping at times on the fixed-step grid, or restoring a snapshot and stepping
on, changes no step, so the stored arrays must be equal to the last bit, not merely close.
"""

import numpy as np
import pytest

import vinculo

FIELDS = ("times", "positions", "velocities", "multipliers", "constraint_residual")


def double_pendulum(anchor_x=0.0) -> vinculo.System:
    """Two unit masses on rods of 1 m and 0.7 m, released from rest, the first rod horizontal.

    Arguments:
        anchor_x: the anchor's x coordinate (a number or a law).
    """
    system = vinculo.System(gravity=(0.0, 0.0, -9.81))
    a = system.add_particle(mass=1.0, position=(1.0, 0.0, 0.0))
    b = system.add_particle(mass=0.5, position=(1.0, 0.0, -0.7))
    system.add_distance_to_point(a, (anchor_x, 0.0, 0.0), length=1.0)
    system.add_distance(a, b, length=0.7)
    return system


def assert_same_arrays(actual: vinculo.Solution, expected: vinculo.Solution, what: str) -> None:
    """Every stored array equal bit for bit (np.array_equal: no tolerance)."""
    for name in FIELDS:
        a, b = getattr(actual, name), getattr(expected, name)
        assert a.shape == b.shape, f"{what}: {name} shapes {a.shape} != {b.shape}"
        assert np.array_equal(a, b), (
            f"{what}: {name} differs by up to {np.max(np.abs(a - b))} from one simulate() call"
        )


CASES = [
    {"scheme": "trapezoidal", "formulation": "index-3"},
    {"scheme": "trapezoidal", "formulation": "ggl"},
    {"scheme": "generalized-alpha", "formulation": "index-3"},
    {"scheme": "generalized-alpha", "formulation": "ggl"},
]


@pytest.mark.parametrize("options", CASES, ids=lambda o: "-".join(str(v) for v in o.values()))
def test_step_snapshot_restore_repeats_one_simulate_call(options):
    # Reference: one vinculo.simulate() to t2 on a separately built model.
    t1, t2, dt = 0.25, 0.6, 0.01
    reference = vinculo.simulate(double_pendulum(), t_end=t2, dt=dt, **options)
    sim = vinculo.Simulation(double_pendulum(), t_end=t2, dt=dt, **options)
    sim.step_to(t1)
    assert sim.time == pytest.approx(t1, abs=1e-12)  # on the grid: k dt to round-off
    snapshot = sim.snapshot()
    assert snapshot.time == sim.time
    sim.step_to(t2)
    assert_same_arrays(sim.solution(), reference, "stepped to t1 then t2")
    # The current state is the last stored row of the reference, bit for bit.
    assert np.array_equal(sim.positions, reference.positions[-1])
    assert np.array_equal(sim.velocities, reference.velocities[-1])
    assert np.array_equal(sim.multipliers, reference.multipliers[-1])
    sim.restore(snapshot)
    assert sim.time == snapshot.time
    assert len(sim.solution().times) == np.count_nonzero(reference.times <= snapshot.time)
    sim.step_to(t2)
    assert_same_arrays(sim.solution(), reference, "restored at t1, stepped to t2 again")


def test_modified_newton_repeats_to_the_newton_tolerance_after_a_restore():
    # Stopping keeps the reused factorisation (bit for bit); a restore discards it, so the first
    # step after it factorises afresh and modified Newton stops at another iterate: the restored
    # run then agrees with one simulate() call to the Newton tolerance (1e-10 m, per step, over
    # 35 steps, with margin), not bit for bit (run.rs, Simulation::restore).
    options = {"scheme": "generalized-alpha", "jacobian_reuse": True}
    reference = vinculo.simulate(double_pendulum(), t_end=0.6, dt=0.01, **options)
    sim = vinculo.Simulation(double_pendulum(), t_end=0.6, dt=0.01, **options)
    sim.step_to(0.25)
    snapshot = sim.snapshot()
    sim.step_to(0.6)
    assert_same_arrays(sim.solution(), reference, "modified Newton stepped to t1 then t2")
    sim.restore(snapshot)
    sim.step_to(0.6)
    restored = sim.solution()
    assert np.array_equal(restored.times, reference.times)
    np.testing.assert_allclose(restored.positions, reference.positions, rtol=0, atol=1e-8)


def test_adaptive_stepping_stops_after_the_step_that_reaches_the_stop():
    # Reference: one error-controlled simulate() call; error-controlled steps are not bent to an
    # intermediate stop (run.rs), so stopping changes nothing and the run ends at or past t1.
    options = {"adaptive": True, "rtol": 1e-5, "atol": 1e-6, "scheme": "generalized-alpha"}
    reference = vinculo.simulate(double_pendulum(), t_end=0.6, dt=1e-3, **options)
    sim = vinculo.Simulation(double_pendulum(), t_end=0.6, dt=1e-3, **options)
    sim.step_to(0.3)
    assert sim.time >= 0.3
    assert sim.time in set(reference.times)  # an accepted step of the reference
    snapshot = sim.snapshot()
    sim.step_to(0.6)
    sim.restore(snapshot)
    sim.step_to(0.6)
    assert_same_arrays(sim.solution(), reference, "adaptive, restored and stepped on")


def test_driven_anchor_equals_the_same_motion_given_as_a_piecewise_linear_law():
    # Reference: the anchor motion x(t) = A sin(w t), sampled at the coupling times, given in
    # advance as vinculo.piecewise_linear; the driven law set knot by knot evaluates as that
    # table (left-continuous rate), so the two runs must take identical steps.
    amplitude, omega, dt, t_end = 0.05, 3.0, 0.01, 0.5
    times = np.arange(0.0, t_end + 1e-12, 0.05)
    x = amplitude * np.sin(omega * times)
    table = vinculo.piecewise_linear(times, x)
    reference = vinculo.simulate(double_pendulum(table), t_end=t_end, dt=dt)

    law = vinculo.driven(float(x[0]), float(times[0]))
    sim = vinculo.Simulation(double_pendulum(law), t_end=t_end, dt=dt)
    for t_k, x_k in zip(times[1:], x[1:], strict=True):
        law.set(float(t_k), float(x_k))
        sim.step_to(float(t_k))
    assert_same_arrays(sim.solution(), reference, "driven anchor")
    # The anchor did move: the first rod's length about the moving anchor holds, about the
    # origin it does not (a change of about A sin(w t) = 0.05 m).
    anchor_end = x[-1]
    a = sim.positions[0]
    assert np.hypot(a[0] - anchor_end, a[2]) == pytest.approx(1.0, abs=1e-8)
    assert abs(np.hypot(a[0], a[2]) - 1.0) > 1e-3


def test_restore_of_a_snapshot_of_another_system_is_refused():
    sim = vinculo.Simulation(double_pendulum(), t_end=0.1, dt=0.01)
    other = vinculo.System(gravity=(0.0, 0.0, -9.81))
    bob = other.add_particle(mass=1.0, position=(1.0, 0.0, 0.0))
    other.add_distance_to_point(bob, (0.0, 0.0, 0.0), length=1.0)
    foreign = vinculo.Simulation(other, t_end=0.1, dt=0.01).snapshot()
    with pytest.raises(vinculo.InvalidInputError, match="another system") as raised:
        sim.restore(foreign)
    assert raised.value.name == "snapshot"
    assert "1 particles" in str(raised.value)
    with pytest.raises(vinculo.InvalidInputError, match="Snapshot"):
        sim.restore("not a snapshot")


def test_step_to_before_the_current_time_is_refused_and_changes_nothing():
    sim = vinculo.Simulation(double_pendulum(), t_end=0.2, dt=0.01)
    sim.step_to(0.1)
    before = sim.positions
    with pytest.raises(vinculo.InvalidInputError, match="before the current time") as raised:
        sim.step_to(0.05)
    assert raised.value.name == "t"
    assert float(raised.value.value) == 0.05
    assert np.array_equal(sim.positions, before)


def test_driven_law_refuses_a_time_that_is_not_after_the_last():
    law = vinculo.driven(0.0)
    law.set(0.1, 1.0)
    # Reference: linear interpolation by hand between (0, 0) and (0.1, 1).
    assert law.derivatives(0.05) == pytest.approx((0.5, 10.0, 0.0), rel=1e-12)
    with pytest.raises(vinculo.InvalidInputError, match="after the last knot") as raised:
        law.set(0.1, 2.0)
    assert float(raised.value.value) == 0.1
    with pytest.raises(vinculo.InvalidInputError, match="driven"):
        vinculo.constant(1.0).set(1.0, 2.0)


def test_a_failed_step_raises_and_keeps_what_was_computed():
    # A pendulum with a 1-iteration Newton budget cannot converge: the error carries the states
    # stored before (here only the initial one), as vinculo.simulate does.
    sim = vinculo.Simulation(double_pendulum(), t_end=0.2, dt=0.01, max_iterations=1,
                             max_halvings=0)
    with pytest.raises(vinculo.ConvergenceError) as raised:
        sim.step_to(0.2)
    assert raised.value.solution.times[0] == 0.0
    assert np.array_equal(sim.solution().times, raised.value.solution.times)


@pytest.mark.parametrize("adaptive", [False, True], ids=["fixed", "adaptive"])
@pytest.mark.parametrize("options", CASES, ids=lambda o: "-".join(str(v) for v in o.values()))
def test_snapshot_file_continues_as_one_simulate_call(tmp_path, options, adaptive):
    # Reference: one vinculo.simulate() to t2; a new simulation loads the state saved at t1 and
    # stores, from t1 on, the same rows and accepted step sizes bit for bit (the file holds the
    # floats' exact bits; with error control also the controller's state, and t1 is the end of
    # the step that reaches 0.25).
    t1, t2, dt = 0.25, 0.6, 0.01
    if adaptive:
        options = {**options, "adaptive": True, "rtol": 1e-5, "atol": 1e-6}
    reference = vinculo.simulate(double_pendulum(), t_end=t2, dt=dt, **options)
    sim = vinculo.Simulation(double_pendulum(), t_end=t2, dt=dt, **options)
    sim.step_to(t1)
    before = sim.solution().accepted_step_sizes
    path = tmp_path / "state.snap"
    sim.save_snapshot(path)
    other = vinculo.Simulation(double_pendulum(), t_end=t2, dt=dt, **options)
    other.load_snapshot(path)
    assert other.time == sim.time
    assert np.array_equal(other.positions, sim.positions)
    other.step_to(t2)
    continued = other.solution()
    later = reference.times >= sim.time
    assert later.sum() > 3
    assert np.array_equal(continued.times, reference.times[later])
    for name in FIELDS[1:]:
        assert np.array_equal(getattr(continued, name), getattr(reference, name)[later]), name
    steps = np.concatenate([before, continued.accepted_step_sizes])
    assert np.array_equal(steps, reference.accepted_step_sizes)


def test_corrupt_and_foreign_snapshot_files_are_refused(tmp_path):
    sim = vinculo.Simulation(double_pendulum(), t_end=0.1, dt=0.01)
    sim.step_to(0.05)
    path = tmp_path / "state.snap"
    sim.save_snapshot(path)
    data = bytearray(path.read_bytes())
    data[40] ^= 0x01  # one bit of the stored time flipped (bytes 36-43)
    corrupt = tmp_path / "corrupt.snap"
    corrupt.write_bytes(bytes(data))
    with pytest.raises(vinculo.InvalidInputError, match="checksum") as raised:
        sim.load_snapshot(corrupt)
    assert "corrupt.snap" in str(raised.value.value)
    truncated = tmp_path / "truncated.snap"
    truncated.write_bytes(path.read_bytes()[:30])
    with pytest.raises(vinculo.InvalidInputError, match=r"corrupt|truncated"):
        sim.load_snapshot(truncated)
    text = tmp_path / "text.snap"
    text.write_text("not a snapshot at all")
    with pytest.raises(vinculo.InvalidInputError, match="VNCLSNAP"):
        sim.load_snapshot(text)
    with pytest.raises(vinculo.InvalidInputError, match="cannot be read"):
        sim.load_snapshot(tmp_path / "missing.snap")
    other = vinculo.System(gravity=(0.0, 0.0, -9.81))
    bob = other.add_particle(mass=1.0, position=(1.0, 0.0, 0.0))
    other.add_distance_to_point(bob, (0.0, 0.0, 0.0), length=1.0)
    with pytest.raises(vinculo.InvalidInputError, match="another system"):
        vinculo.Simulation(other, t_end=0.1, dt=0.01).load_snapshot(path)
    adaptive = vinculo.Simulation(double_pendulum(), t_end=0.1, dt=0.01, adaptive=True)
    adaptive.step_to(0.05)
    adaptive_path = tmp_path / "adaptive.snap"
    adaptive.save_snapshot(adaptive_path)
    truncated.write_bytes(adaptive_path.read_bytes()[:-30])
    with pytest.raises(vinculo.InvalidInputError, match=r"corrupt|truncated"):
        adaptive.load_snapshot(truncated)
    with pytest.raises(vinculo.InvalidInputError, match="step control"):
        sim.load_snapshot(adaptive_path)
