"""The run as the compiled core returns it (``_core.RunResult``), the one mapping from the core's
errors to exceptions (the same class, details and partial solution through ``simulate()`` and
through ``Simulation.step_to``), and the run options defined once (``RunOptions``)."""

import numpy as np
import pytest

import vinculo
from vinculo import _core, laws
from vinculo.solution import _ARRAY_FIELDS

GRAVITY = 9.81


def pendulum():
    """A 1 kg bob on a 1 m rod from the origin, released horizontally."""
    system = vinculo.System(gravity=(0.0, 0.0, -GRAVITY))
    bob = system.add_particle(1.0, (1.0, 0.0, 0.0))
    system.add_distance_to_point(bob, (0.0, 0.0, 0.0), 1.0)
    return system


def test_the_typed_result_holds_the_arrays_the_solution_exposes():
    system = pendulum()
    t_end, dt = 0.5, 1e-2
    result = _core.simulate(system, vinculo.RunOptions().settings(t_end, dt, None))
    solution = vinculo.simulate(system, t_end, dt)
    assert result.error is None and solution.success
    for name in (*_ARRAY_FIELDS, "accepted_step_sizes"):
        assert np.array_equal(getattr(result, name), getattr(solution, name)), name
        assert getattr(result, name).dtype == getattr(solution, name).dtype, name
    for name in ("steps_taken", "steps_rejected", "factorisations"):
        assert isinstance(getattr(result, name), int)
        assert getattr(result, name) == getattr(solution, name), name
    assert (result.scheme, result.formulation) == ("trapezoidal", "index-3")
    assert result.linear_solver == solution.linear_solver and result.linear_solver
    # Shapes: (s,), (s, n, 3), (s, m); the states on the fixed grid t_k = k dt, and on the rod
    # |q| = 1 to the Newton tolerance (1e-10 of the 1 m length scale).
    s = round(t_end / dt) + 1
    assert result.positions.shape == result.velocities.shape == (s, 1, 3)
    assert result.multipliers.shape == (s, 1)
    np.testing.assert_allclose(result.times, dt * np.arange(s), rtol=0, atol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(result.positions[:, 0], axis=1), 1.0, atol=1e-9)
    assert result.newton_iterations.dtype == np.int64 and result.newton_iterations[0] == 0


def test_the_run_options_defaults_are_the_cores():
    # The options are spelled once in Python (RunOptions); the core's RunSettings has its own
    # defaults for the same names: both give the same SimulationOptions.
    assert repr(vinculo.RunOptions().settings(2.0, 1e-2, None)) == repr(
        _core.RunSettings(2.0, 1e-2)
    )


@pytest.mark.parametrize("run", ["simulate", "Simulation"])
def test_an_unknown_option_is_refused_by_name(run):
    function = vinculo.simulate if run == "simulate" else vinculo.Simulation
    with pytest.raises(TypeError, match=r"simulate\(\) got an unexpected keyword argument 'tol'|"
                                        r"Simulation\(\) got an unexpected keyword argument 'tol'"):
        function(pendulum(), 1.0, 1e-2, tol=1e-8)


def unreachable_tolerance():
    # A Newton tolerance of 1e-30 is below round-off: the first step cannot converge, even halved.
    return pendulum(), 1.0, 1e-2, {"tolerance": 1e-30, "max_halvings": 2}


def vanishing_circle():
    # On the plane z = 0 and at 0.5 m from a point rising as (0, 0, t): the circle where the two
    # constraints meet has radius sqrt(0.25 - t^2) and vanishes at t = 0.5 s.
    system = vinculo.System(gravity=(0.0, 0.0, -GRAVITY))
    particle = system.add_particle(1.0, (0.5, 0.0, 0.0))
    system.add_plane(particle, (0.0, 0.0, 1.0), (0.0, 0.0, 0.0))
    system.add_distance_to_point(particle, (0.0, 0.0, laws.polynomial([0.0, 1.0])), 0.5)
    return system, 1.0, 1e-2, {}


def failing_user_force():
    # A zero force of a user group that raises at its 31st call.
    system = pendulum()
    calls = {"n": 0}

    def force(t, q, v):
        calls["n"] += 1
        if calls["n"] > 30:
            raise KeyError("no such sea state")
        return np.zeros_like(q)

    system.add_force_group([0], force, name="sea")
    return system, 1.0, 1e-2, {}


def pushed_string():
    # A 1 kg bob at rest on a 1 m string from a fixed anchor, pushed up by F(t) = 2 m g t: the
    # tension is m g (1 - 2 t) (statics); the trapezoidal multiplier of the step from t_n acts at
    # t_n + dt/2, so the first negative one is that of the step from 0.5 s: the run stops at 0.51 s.
    system = vinculo.System(gravity=(0.0, 0.0, -GRAVITY))
    anchor = system.add_particle(1.0, (0.0, 0.0, 0.0), fixed=True)
    bob = system.add_particle(1.0, (0.0, 0.0, -1.0))
    string = system.add_distance(anchor, bob)
    system.set_tension_only(string)
    system.add_force(bob, (0.0, 0.0, vinculo.polynomial([0.0, 2.0 * GRAVITY])))
    return system, 1.0, 1e-2, {}


def too_strict_for_h_min():
    # Error-controlled steps of a swinging pendulum to 1e-8 cannot be 4e-3 s long.
    options = {"adaptive": True, "rtol": 1e-8, "atol": 1e-8, "h_min": 4e-3, "tolerance": 1e-12}
    return pendulum(), 2.0, 4e-3, options


STOPPED_RUNS = {
    "Newton fails": (unreachable_tolerance, vinculo.ConvergenceError),
    "constraints stop intersecting": (vanishing_circle, vinculo.ConvergenceError),
    "user function raises": (failing_user_force, vinculo.UserFunctionError),
    "string would push": (pushed_string, vinculo.NegativeTensionError),
    "step below h_min": (too_strict_for_h_min, vinculo.StepSizeTooSmallError),
}


@pytest.mark.parametrize("case", list(STOPPED_RUNS))
def test_a_stopped_run_raises_the_same_exception_through_simulate_and_step_to(case):
    build, expected = STOPPED_RUNS[case]
    system, t_end, dt, options = build()
    with pytest.raises(vinculo.VinculoError) as info:
        vinculo.simulate(system, t_end, dt, **options)
    by_simulate = info.value
    system, t_end, dt, options = build()
    simulation = vinculo.Simulation(system, t_end, dt, **options)
    with pytest.raises(vinculo.VinculoError) as info:
        simulation.step_to(t_end)
    by_step_to = info.value
    assert type(by_simulate) is expected and type(by_step_to) is expected
    assert by_simulate.details.keys() == by_step_to.details.keys()
    # The partial solutions: the same states, bit for bit, described as the exception.
    first, second = by_simulate.solution, by_step_to.solution
    assert isinstance(first, vinculo.Solution) and isinstance(second, vinculo.Solution)
    for name in _ARRAY_FIELDS:
        assert np.array_equal(getattr(first, name), getattr(second, name)), name
    assert first.error == second.error
    assert first.error["kind"] == expected.__name__ and not first.success
    assert first.error["message"] == str(by_simulate)
    assert 0 < len(first.times) and first.times[0] == 0.0
    # The simulation keeps the states: its solution is the partial one, and stepping on raises
    # the same error again.
    assert np.array_equal(simulation.solution().times, second.times)
    with pytest.raises(expected):
        simulation.step_to(t_end)
    if expected is vinculo.UserFunctionError:
        # The user's exception, with its traceback, as the cause, through both paths.
        assert isinstance(by_simulate.__cause__, KeyError)
        assert isinstance(by_step_to.__cause__, KeyError)
        assert by_simulate.__cause__.__traceback__ is not None
    if expected is vinculo.NegativeTensionError:
        assert by_simulate.time == pytest.approx(0.51, abs=1e-12)
        assert by_simulate.tension == pytest.approx(GRAVITY * (1.0 - 2.0 * 0.505), rel=1e-8)


def test_a_law_out_of_its_domain_is_refused_by_simulate_and_simulation_alike():
    # A tabulated anchor height defined on [0, 1] s cannot drive a run to 2 s: refused before
    # the first step, so with no partial solution.
    table = laws.tabulated([0.0, 1.0], [0.0, 0.1])
    raised = []
    for run in (vinculo.simulate, vinculo.Simulation):
        system = vinculo.System(gravity=(0.0, 0.0, -GRAVITY))
        bob = system.add_particle(1.0, (1.0, 0.0, 0.0))
        system.add_distance_to_point(bob, (0.0, 0.0, table), 1.0)
        with pytest.raises(vinculo.VinculoError) as info:
            run(system, 2.0, 1e-2)
        raised.append(info.value)
    assert all(type(e) is vinculo.InvalidInputError for e in raised)
    assert str(raised[0]) == str(raised[1]) and "[0, 1] s" in str(raised[0])
    assert all(getattr(e, "solution", None) is None for e in raised)
