"""Error-controlled steps from rtol = 1e-3 to 1e-10 on smooth problems, against references
computed without vinculo (``vinculo.bench.problems``: the same motions in minimal coordinates,
integrated by scipy's DOP853 at 1e-13).

The problems: a 1 m pendulum released horizontally (2 s), a chain of three 0.5 m links released
60 degrees from the vertical (1.5 s) and a two-particle mechanism whose slider is held on a moving
plane x = 0.2 sin(2 pi t) (2 s). Before step doubling, rtol = atol = 1e-8 stopped at once with
StepSizeTooSmallError on the pendulum and 1e-7 on the moving plane.
"""

import numpy as np
import pytest

import vinculo
from vinculo.bench.problems import PROBLEMS, max_error

SCHEMES = {
    "trapezoidal": {"scheme": "trapezoidal"},
    "generalized-alpha": {"scheme": "generalized-alpha", "rho_inf": 0.5},
}

# The largest position error of a run over its tolerance (rtol = atol, m), per scheme, measured
# over the three problems and rtol = 1e-3 ... 1e-10 (`python -m vinculo.bench work-precision`):
# trapezoidal 2.0 to 11.8, generalised-alpha (rho_inf = 0.5) 4.5 to 49.9 (5 to 40 and 16 to 174
# when the runs kept the one step's answer instead of the two half steps'). The local errors are
# controlled per unit step against the model's time scale T = L / U (0.32 s for the 1 m
# pendulum), so a run of t_end / T time scales adds about that many of the estimated errors
# before the motion amplifies them (these runs are 4.7 to 6.3 time scales long); the answer kept,
# the two half steps', has a quarter of the estimated error. Generalised-alpha's position error
# grows further through its velocity error, which the step-doubling estimate of its positions
# sees only in part.
ERROR_FACTOR = {"trapezoidal": 15.0, "generalized-alpha": 60.0}


def adaptive_run(key: str, scheme: str, tol: float) -> tuple[vinculo.Solution, list]:
    problem = PROBLEMS[key]
    system, bobs = problem.build()
    times = np.linspace(0.0, problem.t_end, 201)
    solution = vinculo.simulate(
        system, problem.t_end, 1e-3, adaptive=True, rtol=tol, atol=tol, t_eval=times,
        **SCHEMES[scheme],
    )
    return solution, bobs


@pytest.mark.parametrize("scheme", SCHEMES)
@pytest.mark.parametrize("key", PROBLEMS)
@pytest.mark.parametrize("tol", [1e-3, 1e-7, 1e-10])
def test_tight_tolerances_are_met(key, scheme, tol):
    solution, bobs = adaptive_run(key, scheme, tol)
    assert solution.success
    position_error, _ = max_error(PROBLEMS[key], solution, bobs)
    assert position_error < ERROR_FACTOR[scheme] * tol, (position_error, position_error / tol)


@pytest.mark.parametrize("scheme", SCHEMES)
@pytest.mark.parametrize("key", ["pendulum", "moving-plane"])
def test_error_falls_with_the_tolerance(key, scheme):
    # Three decades of tolerance: the error falls 2.5 to 3 decades (measured: 395 to 704 times;
    # generalised-alpha's factor over the tolerance grows slowly, see ERROR_FACTOR).
    errors = [max_error(PROBLEMS[key], *adaptive_run(key, scheme, tol))[0] for tol in (1e-5, 1e-8)]
    assert errors[0] / errors[1] > 300.0, errors


@pytest.mark.parametrize("scheme", SCHEMES)
@pytest.mark.parametrize("key", PROBLEMS)
def test_steps_close_to_the_best_fixed_step(key, scheme):
    # The fixed step of the same accuracy: two fixed-step runs (200 and 800 steps) give the error
    # constant of the second-order scheme (error = C n^-2, the order checked from the pair), and
    # with it the number of fixed steps that reaches the adaptive run's error. The adaptive run
    # takes at most 2.5 times as many steps (measured at rtol 1e-5, 1e-7, 1e-9: 0.46 to 0.93, the
    # answer kept being the two half steps'; its step doubling solves those two half steps per
    # step besides the step, so 1.4 to 2.8 times the fixed step's Newton solves, which the
    # work-precision table counts in CPU time).
    problem = PROBLEMS[key]
    solution, bobs = adaptive_run(key, scheme, 1e-7)
    error = max_error(problem, solution, bobs)[0]
    times = np.linspace(0.0, problem.t_end, 201)
    reference, _ = problem.reference(times)
    fixed_errors = []
    for n in (200, 800):
        system, bobs = problem.build()
        fixed = vinculo.simulate(system, problem.t_end, problem.t_end / n, **SCHEMES[scheme])
        rows = np.round(np.linspace(0, n, 201)).astype(int)
        q = np.stack([fixed.particle(b) for b in bobs], axis=1)[rows]
        fixed_errors.append(np.max(np.abs(q - reference)))
    order = np.log(fixed_errors[0] / fixed_errors[1]) / np.log(4.0)
    assert 1.9 < order < 2.1
    equal_accuracy = 800 * (fixed_errors[1] / error) ** (1.0 / order)
    assert solution.steps_taken < 2.5 * equal_accuracy, (solution.steps_taken, equal_accuracy)
