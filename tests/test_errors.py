"""Every bad input raises its typed error, naming the offending value."""

import math
import pickle

import numpy as np
import pytest

import vinculo
from vinculo import errors

NAN, INF = float("nan"), float("inf")


def shows(message: str, value: float) -> bool:
    """Whether the message names the value, in any of the usual spellings of a float."""
    text = message.lower()
    spellings = {str(value), repr(value), f"{value:g}"}
    if math.isfinite(value):
        spellings.add(np.format_float_positional(value, trim="-"))  # 1e-10 as 0.0000000001
        if value == int(value):
            spellings.add(str(int(value)))  # 0.0 as 0
    return any(spelling.lower() in text for spelling in spellings)


def pendulum_system() -> tuple[vinculo.System, vinculo.ParticleId, vinculo.ConstraintId]:
    system = vinculo.System(gravity=(0.0, 0.0, -9.81))
    bob = system.add_particle(1.0, (1.0, 0.0, 0.0))
    rod = system.add_distance_to_point(bob, (0.0, 0.0, 0.0), 1.0)
    return system, bob, rod


# ---- the hierarchy ----------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("cls", "builtin"),
    [
        (errors.InvalidInputError, ValueError),
        (errors.UnknownHandleError, LookupError),
        (errors.InconsistentInitialStateError, errors.InvalidInputError),
        (errors.ConvergenceError, RuntimeError),
        (errors.ReentrantRunError, RuntimeError),
        (errors.OutputTooLargeError, MemoryError),
        (errors.InternalError, Exception),
    ],
)
def test_every_error_is_a_vinculo_error_and_its_builtin(cls, builtin):
    assert issubclass(cls, errors.VinculoError)
    assert issubclass(cls, builtin)
    # The package exports the same classes.
    assert getattr(vinculo, cls.__name__) is cls


def test_details_become_attributes_and_survive_pickling():
    # The core raises cls(message, name=..., value=...): each detail is an attribute.
    error = errors.InvalidInputError("mass must be positive, got -1", name="mass", value=-1.0)
    assert str(error) == "mass must be positive, got -1"
    assert (error.name, error.value) == ("mass", -1.0)
    assert error.details == {"name": "mass", "value": -1.0}
    copy = pickle.loads(pickle.dumps(error))
    assert type(copy) is errors.InvalidInputError
    assert (str(copy), copy.name, copy.value) == (str(error), "mass", -1.0)


def test_an_interrupt_is_a_keyboard_interrupt_with_details_not_an_exception():
    # Ctrl-C must not be swallowed by `except Exception`, nor missed by `except KeyboardInterrupt`.
    assert issubclass(errors.Interrupted, KeyboardInterrupt)
    assert not issubclass(errors.Interrupted, Exception)
    assert vinculo.Interrupted is errors.Interrupted
    error = errors.Interrupted("run interrupted at t = 0.5 s", time=0.5)
    assert (str(error), error.time, error.solution) == ("run interrupted at t = 0.5 s", 0.5, None)
    copy = pickle.loads(pickle.dumps(error))
    assert type(copy) is errors.Interrupted and copy.time == 0.5


def test_convergence_error_has_its_attributes_even_when_not_given():
    error = errors.ConvergenceError("no convergence", time=0.5, iterations=25)
    assert (error.time, error.iterations) == (0.5, 25)
    assert error.residual is None and error.solution is None and error.equation is None


# ---- bad particles ----------------------------------------------------------------------------


@pytest.mark.parametrize("mass", [0.0, -1.5, NAN, INF])
def test_bad_mass(mass):
    system = vinculo.System()
    with pytest.raises(vinculo.InvalidInputError) as info:
        system.add_particle(mass, (0.0, 0.0, 0.0))
    assert "mass" in str(info.value)
    assert shows(str(info.value), mass)


@pytest.mark.parametrize("bad", [NAN, INF, -INF])
@pytest.mark.parametrize("argument", ["position", "velocity"])
def test_bad_position_or_velocity(argument, bad):
    system = vinculo.System()
    vector = {"position": (0.0, 0.0, 0.0), "velocity": (0.0, 0.0, 0.0)}
    vector[argument] = (0.0, bad, 0.0)
    with pytest.raises(vinculo.InvalidInputError) as info:
        system.add_particle(1.0, vector["position"], velocity=vector["velocity"])
    assert argument in str(info.value)
    assert shows(str(info.value), bad)


# ---- bad constraints --------------------------------------------------------------------------


@pytest.mark.parametrize("length", [0.0, -0.5, NAN, INF])
def test_bad_distance_length(length):
    system = vinculo.System()
    a = system.add_particle(1.0, (0.0, 0.0, 0.0))
    b = system.add_particle(1.0, (1.0, 0.0, 0.0))
    with pytest.raises(vinculo.InvalidInputError) as info:
        system.add_distance(a, b, length)
    assert shows(str(info.value), length)
    with pytest.raises(vinculo.InvalidInputError):
        system.add_distance_to_point(a, (1.0, 0.0, 0.0), length)


def test_distance_of_a_particle_to_itself():
    system = vinculo.System()
    a = system.add_particle(1.0, (0.0, 0.0, 0.0))
    with pytest.raises(vinculo.InvalidInputError):
        system.add_distance(a, a, 1.0)


def test_distance_between_coincident_particles_without_length():
    # length=None takes the current distance, here zero: not a valid length.
    system = vinculo.System()
    a = system.add_particle(1.0, (0.5, 0.0, 0.0))
    b = system.add_particle(1.0, (0.5, 0.0, 0.0))
    with pytest.raises(vinculo.InvalidInputError):
        system.add_distance(a, b)


def test_plane_with_zero_normal():
    system = vinculo.System()
    a = system.add_particle(1.0, (0.0, 0.0, 0.0))
    with pytest.raises(vinculo.InvalidInputError):
        system.add_plane(a, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0))


@pytest.mark.parametrize("axis", [3, -1, "w"])
def test_bad_axis(axis):
    system = vinculo.System()
    a = system.add_particle(1.0, (0.0, 0.0, 0.0))
    with pytest.raises(vinculo.InvalidInputError) as info:
        system.add_fixed_coordinate(a, axis)
    assert str(axis) in str(info.value)  # the axis as given


# ---- unknown handles --------------------------------------------------------------------------


def test_handle_from_another_system():
    other = vinculo.System()
    for k in range(3):
        other.add_particle(1.0, (float(k), 0.0, 0.0))
    foreign = other.add_particle(1.0, (5.0, 0.0, 0.0))
    system = vinculo.System()
    own = system.add_particle(1.0, (0.0, 0.0, 0.0))
    with pytest.raises(vinculo.UnknownHandleError):
        system.add_distance(own, foreign, 1.0)
    with pytest.raises(vinculo.UnknownHandleError):
        system.add_force(foreign, (1.0, 0.0, 0.0))


@pytest.mark.parametrize("not_a_handle", [0, 1, "0", None])
def test_raw_index_is_not_a_handle(not_a_handle):
    system = vinculo.System()
    a = system.add_particle(1.0, (0.0, 0.0, 0.0))
    system.add_particle(1.0, (1.0, 0.0, 0.0))
    with pytest.raises(vinculo.UnknownHandleError):
        system.add_distance(a, not_a_handle, 1.0)


def test_solution_rejects_foreign_handles():
    system, bob, _ = pendulum_system()
    solution = vinculo.simulate(system, 0.01, 1e-3)
    with pytest.raises(vinculo.UnknownHandleError):
        solution.particle(0)
    with pytest.raises(vinculo.UnknownHandleError):
        solution.multiplier(bob)  # a particle handle where a constraint handle is expected
    other, *_ = pendulum_system()
    extra = other.add_particle(1.0, (3.0, 0.0, 0.0))
    with pytest.raises(vinculo.UnknownHandleError):
        solution.particle(extra)


# ---- bad run parameters -----------------------------------------------------------------------


@pytest.mark.parametrize(
    ("arguments", "name"),
    [
        ({"t_end": -1.0, "dt": 1e-3}, "t_end"),
        ({"t_end": NAN, "dt": 1e-3}, "t_end"),
        ({"t_end": 1.0, "dt": 0.0}, "dt"),
        ({"t_end": 1.0, "dt": -1e-3}, "dt"),
        ({"t_end": 1.0, "dt": NAN}, "dt"),
        ({"t_end": 1.0, "dt": 1e-3, "alpha": 0.49}, "alpha"),
        ({"t_end": 1.0, "dt": 1e-3, "alpha": 1.01}, "alpha"),
        ({"t_end": 1.0, "dt": 1e-3, "alpha": 0.0}, "alpha"),
        ({"t_end": 1.0, "dt": 1e-3, "tolerance": 0.0}, "tolerance"),
        ({"t_end": 1.0, "dt": 1e-3, "tolerance": -1e-10}, "tolerance"),
        ({"t_end": 0.5, "dt": 1e-3, "t_start": 1.0}, "t_end"),
    ],
)
def test_bad_simulation_parameters(arguments, name):
    system, _, _ = pendulum_system()
    with pytest.raises(vinculo.InvalidInputError) as info:
        vinculo.simulate(system, **arguments)
    message = str(info.value)
    assert name in message
    assert shows(message, arguments[name])


def test_bad_progress_argument():
    system, _, _ = pendulum_system()
    with pytest.raises(vinculo.InvalidInputError):
        vinculo.simulate(system, 0.01, 1e-3, progress="yes")


# ---- inconsistent initial state ---------------------------------------------------------------


def test_inconsistent_positions_are_reported_then_projected():
    # Two particles 1 m apart joined by a 1.2 m link (and hung from a 1 m rod): the initial state
    # violates the link; the error names it.
    system = vinculo.System(gravity=(0.0, 0.0, -9.81))
    upper = system.add_particle(1.0, (0.0, 0.0, -1.0))
    lower = system.add_particle(1.0, (0.3, 0.0, -2.0))
    system.add_distance_to_point(upper, (0.0, 0.0, 0.0), 1.0)
    link = system.add_distance(upper, lower, 1.2)
    with pytest.raises(vinculo.InconsistentInitialStateError) as info:
        vinculo.simulate(system, 0.1, 1e-3)
    assert isinstance(info.value, vinculo.InvalidInputError)
    name = system.constraint_names()[link.index]
    assert name in str(info.value)

    report = system.project_initial_state()
    assert report["position_change"] > 0.05  # it had to move a particle by a good part of 0.2 m
    q = system.initial_positions()
    assert np.linalg.norm(q[0] - q[1]) == pytest.approx(1.2, abs=1e-12)
    assert np.linalg.norm(q[0]) == pytest.approx(1.0, abs=1e-12)
    solution = vinculo.simulate(system, 0.5, 1e-3)
    assert np.max(solution.constraint_residual) < 1e-12


def test_inconsistent_velocities_are_reported_then_projected():
    # A pendulum bob moving along its rod (radially) at 1 m/s violates Phi_q v = 0.
    system = vinculo.System(gravity=(0.0, 0.0, -9.81))
    bob = system.add_particle(1.0, (0.0, 0.0, -1.0), velocity=(0.5, 0.0, -1.0))
    rod = system.add_distance_to_point(bob, (0.0, 0.0, 0.0), 1.0)
    with pytest.raises(vinculo.InconsistentInitialStateError) as info:
        vinculo.simulate(system, 0.1, 1e-3)
    assert system.constraint_names()[rod.index] in str(info.value)

    report = system.project_initial_state()
    # The least mass-weighted change removes only the radial component: v = (0.5, 0, 0).
    np.testing.assert_allclose(system.initial_velocities(), [[0.5, 0.0, 0.0]], atol=1e-12)
    assert report["velocity_change"] == pytest.approx(1.0, abs=1e-12)
    assert report["position_change"] == pytest.approx(0.0, abs=1e-12)
    solution = vinculo.simulate(system, 0.5, 1e-3)
    assert np.max(solution.constraint_residual) < 1e-12


def test_messages_say_what_was_wrong():
    system = vinculo.System()
    with pytest.raises(vinculo.VinculoError) as info:
        system.add_particle(-2.0, (0.0, 0.0, 0.0))
    error = info.value
    assert "-2" in str(error)
    # ... and carries the facts as details (the binding raises cls(message, name=..., value=...)).
    assert error.details.get("value") == -2.0
