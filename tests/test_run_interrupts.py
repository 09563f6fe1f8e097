"""Interrupting a run keeps what it computed; re-entrant runs and runs too large for memory are
refused with typed errors.

Ctrl-C is sent for real: SIGINT to this process from a timer thread (the default handler raises
KeyboardInterrupt in the main thread, where the run is), or from inside a progress callback. The
references: a run that stops after a completed step holds converged states, so they satisfy the
rod's constraint |q| = L (closed form) to the Newton tolerance, and an uninterrupted run of the
same model to the last stored time takes the same steps (fixed steps on the same grid), so it
must agree to round-off. The output-size estimate is checked against numpy's own count of the
bytes of a run's arrays.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager

import numpy as np
import pytest

import vinculo

GRAVITY = 9.81
LENGTH = 1.0


def pendulum() -> vinculo.System:
    """A 1 kg bob on a 1 m rod, released horizontally."""
    system = vinculo.System(gravity=(0.0, 0.0, -GRAVITY))
    bob = system.add_particle(1.0, (LENGTH, 0.0, 0.0))
    system.add_distance_to_point(bob, (0.0, 0.0, 0.0), length=LENGTH)
    return system


@pytest.fixture
def sigint_raises():
    """Python's default SIGINT handler (KeyboardInterrupt in the main thread) for the test."""
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    yield
    signal.signal(signal.SIGINT, previous)


@contextmanager
def interrupt_after(seconds: float) -> Iterator[None]:
    """Send SIGINT to this process after `seconds` (what Ctrl-C in a terminal does), unless the
    block has ended by then."""
    timer = threading.Timer(seconds, os.kill, (os.getpid(), signal.SIGINT))
    timer.start()
    try:
        yield
    finally:
        timer.cancel()
        timer.join()


def assert_is_the_run_up_to_its_end(partial: vinculo.Solution, system, dt: float, **options):
    """The partial solution holds converged steps (|q| = L to the Newton tolerance, 1e-10 L
    with a margin) and is the uninterrupted run up to its last time (the same steps: round-off)."""
    t_last = partial.times[-1]
    assert t_last > 0.0
    radius = np.linalg.norm(partial.positions[:, 0, :], axis=1)
    assert np.max(np.abs(radius - LENGTH)) < 1e-9 * LENGTH
    reference = vinculo.simulate(system, t_last, dt, **options)
    np.testing.assert_array_equal(reference.times, partial.times)
    np.testing.assert_allclose(partial.positions, reference.positions, rtol=0, atol=1e-12)
    np.testing.assert_allclose(partial.velocities, reference.velocities, rtol=0, atol=1e-10)


def test_ctrl_c_in_the_steps_raises_keyboard_interrupt_with_the_partial_solution(sigint_raises):
    system = pendulum()
    sent = time.perf_counter() + 0.3
    with pytest.raises(KeyboardInterrupt) as info, interrupt_after(0.3):
        vinculo.simulate(system, t_end=1e4, dt=1e-3, save_every=7)
    latency = time.perf_counter() - sent
    error = info.value
    assert isinstance(error, vinculo.Interrupted)
    assert not isinstance(error, Exception)  # `except Exception` does not swallow Ctrl-C
    # The core looks for the signal every 0.1 s of wall time (margin for a loaded machine).
    assert latency < 1.0
    partial = error.solution
    assert partial.error["kind"] == "Interrupted"
    # The state where it stopped is kept, even between two stored steps of save_every (an
    # uninterrupted run to that time stores it too, as its last state).
    assert error.time == partial.times[-1]
    assert_is_the_run_up_to_its_end(partial, system, 1e-3, save_every=7)


def slow_damper(t, q, v):
    """A linear damper -c v written in Python, slowed down so that the signal lands in it."""
    time.sleep(2e-4)
    return -0.3 * v


def slow_rod(t, q):
    """The rod |q| = L as a Python constraint, Phi = L^2 - |q|^2, slowed down likewise."""
    time.sleep(2e-4)
    return LENGTH**2 - np.sum(q * q, axis=1)


def pendulum_with_a_damper() -> vinculo.System:
    system = pendulum()
    system.add_force_group([0], slow_damper, name="damper")
    return system


def pendulum_on_a_python_rod() -> vinculo.System:
    system = vinculo.System(gravity=(0.0, 0.0, -GRAVITY))
    system.add_particle(1.0, (LENGTH, 0.0, 0.0))
    system.add_constraint_group([0], slow_rod, name="rod")
    return system


@pytest.mark.parametrize(
    ("build", "group", "call"),
    [(pendulum_with_a_damper, "damper", "force"), (pendulum_on_a_python_rod, "rod", "phi")],
)
def test_ctrl_c_inside_a_user_function_stays_a_keyboard_interrupt(
    sigint_raises, build, group, call
):
    system = build()
    with pytest.raises(KeyboardInterrupt) as info, interrupt_after(0.3):
        vinculo.simulate(system, t_end=100.0, dt=1e-3)
    error = info.value
    assert isinstance(error, vinculo.Interrupted)
    assert (error.group, error.call) == (group, call)
    # The user's KeyboardInterrupt, with its traceback in the function, is the cause.
    assert type(error.__cause__) is KeyboardInterrupt
    assert_is_the_run_up_to_its_end(error.solution, system, 1e-3)


def test_ctrl_c_inside_the_progress_callback(sigint_raises):
    def progress(t, t_end):
        os.kill(os.getpid(), signal.SIGINT)
        time.sleep(5.0)  # the KeyboardInterrupt lands here

    system = pendulum()
    with pytest.raises(KeyboardInterrupt) as info:
        vinculo.simulate(system, t_end=1e4, dt=1e-3, progress=progress)
    assert isinstance(info.value, vinculo.Interrupted)
    assert_is_the_run_up_to_its_end(info.value.solution, system, 1e-3)


def test_an_exception_of_the_progress_callback_carries_the_partial_solution():
    class Enough(Exception):
        pass

    def progress(t, t_end):
        raise Enough(f"stop at {t}")

    system = pendulum()
    with pytest.raises(Enough) as info:
        vinculo.simulate(system, t_end=1e4, dt=1e-3, progress=progress)
    partial = info.value.solution
    assert any("solution" in note for note in info.value.__notes__)
    assert_is_the_run_up_to_its_end(partial, system, 1e-3)


def test_ctrl_c_during_step_to_keeps_the_states_and_the_simulation(sigint_raises):
    system = pendulum()
    simulation = vinculo.Simulation(system, t_end=1e4, dt=1e-3)
    simulation.step_to(0.1)
    snapshot = simulation.snapshot()
    with pytest.raises(KeyboardInterrupt) as info, interrupt_after(0.3):
        simulation.step_to(1e4)
    assert isinstance(info.value, vinculo.Interrupted)
    partial = info.value.solution
    assert partial.times[-1] == simulation.time
    np.testing.assert_array_equal(simulation.solution().times, partial.times)
    assert_is_the_run_up_to_its_end(partial, system, 1e-3)
    # A snapshot restored goes on as the uninterrupted run.
    simulation.restore(snapshot)
    simulation.step_to(0.2)
    reference = vinculo.simulate(system, 0.2, 1e-3)
    np.testing.assert_array_equal(simulation.solution().positions, reference.positions)


# ---- re-entrant use ---------------------------------------------------------------------------

REENTRANT = textwrap.dedent(
    """
    import numpy as np, vinculo
    system = vinculo.System(gravity=(0.0, 0.0, -9.81))
    bob = system.add_particle(1.0, (1.0, 0.0, 0.0))
    system.add_distance_to_point(bob, (0.0, 0.0, 0.0), length=1.0)
    def force(t, q, v):
        {call}
        return np.zeros_like(q)
    group = system.add_force_group([0], force, name="inner")
    try:
        vinculo.simulate(system, 0.01, 1e-3)
    except vinculo.ReentrantRunError as e:
        print("refused", e.call, e.solution.times[-1])
    """
)


@pytest.mark.parametrize(
    ("call", "name"),
    [
        ("vinculo.simulate(system, 0.01, 1e-3)", "simulate"),
        ("vinculo.simulate(system.copy(), 0.01, 1e-3)", "simulate"),
        ("vinculo.Simulation(system, 0.01, 1e-3)", "Simulation"),
        ("group.calls", "UserGroup.calls"),
        ("system.constraint_residual(np.ones((1, 3)))", "System.constraint_residual"),
    ],
)
def test_a_run_of_the_same_system_from_its_user_function_is_an_error_not_a_deadlock(call, name):
    # In a separate process: a deadlock there is a timeout here, not a hung test session.
    script = REENTRANT.replace("{call}", call)
    done = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, timeout=30
    )
    assert done.returncode == 0, done.stderr
    refused, called, t_last = done.stdout.split()
    assert (refused, called) == ("refused", name)
    assert float(t_last) == 0.0  # the outer run stopped in its first step's first call


def test_a_run_of_another_system_inside_a_user_function_is_allowed():
    # A force that runs a separate model (a System built anew) is fine: the inner run equals the
    # same run made outside, bit for bit.
    inner_results = []

    def force(t, q, v):
        if not inner_results:
            inner_results.append(vinculo.simulate(pendulum(), 0.05, 1e-3).positions)
        return np.zeros_like(q)

    system = pendulum()
    system.add_force_group([0], force)
    vinculo.simulate(system, 0.01, 1e-3)
    outside = vinculo.simulate(pendulum(), 0.05, 1e-3).positions
    np.testing.assert_array_equal(inner_results[0], outside)


# ---- output size ------------------------------------------------------------------------------


def output_bytes(solution: vinculo.Solution) -> int:
    """The bytes of a solution's arrays, as numpy counts them."""
    names = (
        "times positions velocities multipliers constraint_residual velocity_violation "
        "newton_iterations step_sizes residual_norms increment_norms accepted_step_sizes"
    ).split()
    return sum(getattr(solution, name).nbytes for name in names)


def test_a_run_too_large_for_memory_is_refused_before_it_starts():
    started = time.perf_counter()
    with pytest.raises(vinculo.OutputTooLargeError) as info:
        # (t_end = 1e12 s with dt = 1e-3 s, the case, is refused earlier still: the times
        # near 1e12 s cannot resolve a millisecond step.)
        vinculo.simulate(pendulum(), t_end=1e9, dt=1e-3)
    assert time.perf_counter() - started < 1.0
    message = str(info.value)
    assert "save_every" in message and "t_eval" in message and "GB" in message
    # 1e12 steps of 112 + 8 bytes: 1.2e14 bytes.
    assert info.value.estimate == pytest.approx(1.2e14, rel=1e-6)
    assert isinstance(info.value, MemoryError)


@pytest.mark.parametrize("save_every", [1, 7])
def test_the_estimate_is_the_size_of_the_arrays_returned(save_every):
    # Reference: numpy's nbytes of the arrays of the same run, made with room to spare.
    system = pendulum()
    solution = vinculo.simulate(system, 1.0, 1e-3, save_every=save_every)
    with pytest.raises(vinculo.OutputTooLargeError) as info:
        vinculo.simulate(system, 1.0, 1e-3, save_every=save_every, max_output_bytes=1.0)
    assert info.value.limit == 1
    assert info.value.estimate == pytest.approx(output_bytes(solution), rel=0.01)


def test_an_adaptive_run_stops_when_its_output_reaches_the_limit():
    # The number of error-controlled steps is not known beforehand: the run stops when what it
    # stored reaches the limit, and keeps it.
    system = pendulum()
    limit = 20_000
    with pytest.raises(vinculo.OutputTooLargeError) as info:
        vinculo.simulate(system, 100.0, 1e-3, adaptive=True, max_output_bytes=limit)
    partial = info.value.solution
    stored = output_bytes(partial)
    assert info.value.estimate == stored
    assert limit < stored <= limit + 112 + 8  # stopped at the first step past the limit
    radius = np.linalg.norm(partial.positions[:, 0, :], axis=1)
    assert np.max(np.abs(radius - LENGTH)) < 1e-9 * LENGTH


@pytest.mark.parametrize("bad", [0.0, -1.0, float("nan")])
def test_a_bad_max_output_bytes_is_refused(bad):
    with pytest.raises(vinculo.InvalidInputError, match="max_output_bytes"):
        vinculo.simulate(pendulum(), 1.0, 1e-3, max_output_bytes=bad)
