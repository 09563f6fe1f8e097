"""Error-controlled adaptive steps and dense output, against the scipy reference of the moving-pivot
pendulum in minimal coordinates (``pendulum_reference``: DOP853 at 1e-12).

The test problem swings through large angles: released at 150 degrees from the downward vertical,
with the pivot shaken as x_p = 0.1 sin(2 pi t) m, the bob creeps near the top and whips through the
bottom at about 6 m/s. Its accelerations change fastest at the bottom, so the step that meets a
tolerance there is several times smaller than near the top: the case where step-size control pays,
and where a fixed step must be as small as the worst moment of the run needs.
"""

import numpy as np
import pytest
from pendulum_reference import MovingPivot

import vinculo

CASE = MovingPivot(theta0=np.radians(150.0))
T_END = 2.0
# Off-grid output times: 0.00731 s apart, not a multiple of any step the runs take.
T_EVAL = np.arange(0.0, T_END, 0.00731)

SCHEMES = [
    ({"scheme": "trapezoidal"}, 2.0, "trapezoidal"),
    ({"scheme": "backward-euler"}, 1.0, "backward Euler"),
    ({"scheme": "generalized-alpha", "rho_inf": 0.5}, 2.0, "generalised-alpha"),
]
IDS = [s[2] for s in SCHEMES]

_REFERENCE = {}


def reference(times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    key = (len(times), float(times[0]), float(times[-1]))
    if key not in _REFERENCE:
        _REFERENCE[key] = CASE.bob_states(times)
    return _REFERENCE[key]


def adaptive_run(kwargs: dict, rtol: float, **extra) -> vinculo.Solution:
    system, _ = CASE.build()
    return vinculo.simulate(
        system,
        T_END,
        1e-3,
        adaptive=True,
        rtol=rtol,
        atol=rtol,
        t_eval=T_EVAL,
        tolerance=1e-12,
        **kwargs,
        **extra,
    )


def max_errors(solution: vinculo.Solution) -> tuple[float, float]:
    """Largest position (m) and velocity (m/s) errors of the bob over the stored times."""
    positions, velocities = reference(solution.times)
    bob = solution.system.particles()[0]
    return (
        float(np.max(np.abs(solution.particle(bob) - positions))),
        float(np.max(np.abs(solution.particle_velocity(bob) - velocities))),
    )


# Measured, for the record (make test runs them all): the largest error over the run divided by the
# tolerance stays between 0.5 and 6 for every scheme and tolerance here. The bound below (10) says
# "within an order of magnitude": a local error per step of at most the tolerance accumulates over
# the run, and the pendulum's swing amplifies errors made near the top.
ERROR_FACTOR = 10.0


@pytest.mark.parametrize(("kwargs", "order", "label"), SCHEMES, ids=IDS)
def test_adaptive_meets_the_tolerance_and_beats_fixed_steps(kwargs, order, label):
    rtol = 1e-4
    solution = adaptive_run(kwargs, rtol)
    assert solution.success
    np.testing.assert_array_equal(solution.times, T_EVAL)
    position_error, velocity_error = max_errors(solution)
    # Weights: atol + rtol |x| with |x| <= 1.1 m for positions; the velocity weights are larger
    # (atol U / L with U = sqrt(g L) = 3.1 m/s, plus rtol |v| with |v| up to 6 m/s).
    assert position_error < ERROR_FACTOR * 2.1 * rtol, f"{label}: {position_error}"
    assert velocity_error < ERROR_FACTOR * (3.1 + 6.0) * rtol, f"{label}: {velocity_error}"
    # The steps varied (smallest and largest accepted differ by more than a factor 2).
    sizes = solution.accepted_step_sizes
    assert np.max(sizes) > 2.0 * np.min(sizes), f"{label}: {np.min(sizes)} .. {np.max(sizes)}"
    assert solution.steps_taken == solution.steps_accepted + solution.steps_rejected
    assert np.sum(sizes) == pytest.approx(T_END, rel=1e-12)
    # A fixed step with as many steps as the adaptive run attempted (rejected ones included) is
    # less accurate: the adaptive run spends its steps where the motion needs them.
    system, bob = CASE.build()
    fixed = vinculo.simulate(
        system, T_END, T_END / solution.steps_taken, tolerance=1e-12, **kwargs
    )
    fixed_error = max_errors(fixed)[0]
    assert fixed_error > 1.5 * position_error, f"{label}: fixed {fixed_error}, adaptive {position_error}"


@pytest.mark.parametrize(("kwargs", "order", "label"), SCHEMES, ids=IDS)
def test_error_falls_with_the_tolerance_at_the_schemes_order(kwargs, order, label):
    # Two tolerances 100 times apart: a scheme of order p needs 100^(1/(p+1)) times more steps
    # for 100 times smaller local errors, and its global error falls like N^-p with the number
    # of steps N. The observed -log(error ratio)/log(steps ratio) must be p within 0.5: the order
    # survives the variable steps (for generalised-alpha, with its algorithmic accelerations kept
    # as they are when the step changes).
    rtols = (1e-4, 1e-6) if order == 2.0 else (1e-3, 1e-5)
    runs = [adaptive_run(kwargs, rtol) for rtol in rtols]
    errors = [max_errors(run)[0] for run in runs]
    steps = [run.steps_accepted for run in runs]
    observed = -np.log(errors[1] / errors[0]) / np.log(steps[1] / steps[0])
    assert abs(observed - order) < 0.5, f"{label}: errors {errors}, steps {steps}"
    assert errors[1] < ERROR_FACTOR * 2.1 * rtols[1], f"{label}: {errors[1]}"


def test_dense_output_between_step_ends():
    # Output times are not step ends: the states there come from the cubic Hermite interpolant of
    # the step that contains them, and still meet the tolerance (against the scipy reference); the
    # statistics of each row are those of that step.
    solution = adaptive_run({"scheme": "trapezoidal"}, 1e-5)
    ends = np.cumsum(solution.accepted_step_sizes)
    gaps = np.min(np.abs(T_EVAL[1:, None] - ends[None, :]), axis=1)
    assert np.mean(gaps > 1e-9) > 0.95  # almost every output time is strictly inside a step
    position_error, velocity_error = max_errors(solution)
    assert position_error < ERROR_FACTOR * 2.1e-5
    assert velocity_error < ERROR_FACTOR * 9.1e-5
    assert np.all(np.isin(solution.step_sizes[1:], solution.accepted_step_sizes))
    assert np.all(solution.newton_iterations[1:] >= 1)
    # The interpolated positions are off the constraint by the interpolation error only, far below
    # the tolerance (the step ends hold it to the Newton tolerance).
    assert np.max(solution.position_violation) < 1e-6


def test_without_t_eval_every_accepted_step_is_stored():
    system, bob = CASE.build()
    solution = vinculo.simulate(system, 0.5, 1e-3, adaptive=True, rtol=1e-5, atol=1e-5)
    assert solution.num_steps == solution.steps_accepted
    np.testing.assert_allclose(np.diff(solution.times), solution.accepted_step_sizes, rtol=1e-9)
    np.testing.assert_array_equal(solution.step_sizes[1:], solution.accepted_step_sizes)
    positions, _ = reference(solution.times)
    assert np.max(np.abs(solution.particle(bob) - positions)) < ERROR_FACTOR * 2.1e-5


@pytest.mark.parametrize("kwargs", [s[0] for s in SCHEMES], ids=IDS)
def test_modified_newton_with_adaptive_steps(kwargs):
    # jacobian_reuse: the iteration matrix depends on h, so every change of step costs a new
    # factorisation; the hold band (proposals within 10 % keep h) lets steps share one. The run
    # meets the same tolerance as with full Newton, with fewer factorisations.
    full = adaptive_run(kwargs, 1e-5)
    modified = adaptive_run(kwargs, 1e-5, jacobian_reuse=True)
    assert modified.success
    assert modified.factorisations < full.factorisations
    assert max_errors(modified)[0] < ERROR_FACTOR * 2.1e-5


def test_progress_is_called_per_accepted_step():
    calls = []
    system, _ = CASE.build()
    solution = vinculo.simulate(
        system, 0.2, 1e-3, adaptive=True, progress=lambda t, t_end: calls.append(t)
    )
    # The callback is throttled to twice a second of wall time: at least the times it saw are
    # accepted step ends, in order.
    assert all(np.isclose(solution.times, t).any() for t in calls)
    assert calls == sorted(calls)


def test_h_min_too_large_stops_with_the_partial_solution():
    # With h_min = 4 ms the slow part of the swing meets rtol = 1e-6, the fast part near the
    # bottom does not: the run stops there with StepSizeTooSmallError, keeping what it computed,
    # which is still accurate (against the reference).
    system, bob = CASE.build()
    with pytest.raises(vinculo.StepSizeTooSmallError) as info:
        vinculo.simulate(
            system, T_END, 4e-3, adaptive=True, rtol=1e-6, atol=1e-6, h_min=4e-3, tolerance=1e-12
        )
    error = info.value
    assert isinstance(error, vinculo.ConvergenceError)
    assert error.h_min == 4e-3
    assert error.step_size < 4e-3
    assert error.error_norm > 1.0
    partial = error.solution
    assert 0.0 < partial.times[-1] < T_END
    assert partial.times[-1] == pytest.approx(error.time)
    positions, _ = reference(partial.times)
    assert np.max(np.abs(partial.particle(bob) - positions)) < ERROR_FACTOR * 2.1e-6


@pytest.mark.parametrize(
    ("options", "name"),
    [
        ({"rtol": 0.0}, "rtol"),
        ({"rtol": -1e-6}, "rtol"),
        ({"atol": float("nan")}, "atol"),
        ({"h_min": 0.0}, "h_min"),
        ({"h_min": 1e-2, "h_max": 1e-3}, "h_max"),
        ({"h_min": 1e-2}, "dt"),  # the first step dt = 1e-3 is below h_min
        ({"t_eval": [0.0, 0.2, 0.1]}, "output time t_eval[2]"),
        ({"t_eval": [0.0, 0.1, 0.1]}, "output time t_eval[2]"),
        ({"t_eval": [0.1, 0.6]}, "output time t_eval[1]"),
        ({"t_eval": [-0.1]}, "output time t_eval[0]"),
        ({"t_eval": [[0.1, 0.2]]}, "t_eval"),
    ],
)
def test_bad_options_are_named(options, name):
    system, _ = CASE.build()
    with pytest.raises(vinculo.InvalidInputError) as info:
        vinculo.simulate(system, 0.5, 1e-3, adaptive=True, **options)
    assert info.value.name == name


def test_t_eval_needs_adaptive_steps():
    system, _ = CASE.build()
    with pytest.raises(vinculo.InvalidInputError, match="adaptive") as info:
        vinculo.simulate(system, 0.5, 1e-3, t_eval=[0.1])
    assert info.value.name == "output time t_eval[0]"
