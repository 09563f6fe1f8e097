"""Observed order of accuracy of the generalised trapezoidal rule, by step halving."""

import numpy as np
import pytest

import vinculo
from vinculo import demos

T_COMPARE = 1.0  # s; a multiple of every step size below


def pendulum_position(dt: float, alpha: float) -> np.ndarray:
    """Bob position at T_COMPARE of the horizontally released 1 m pendulum."""
    model = demos.build_pendulum()
    solution = vinculo.simulate(model.system, T_COMPARE, dt, alpha)
    assert solution.times[-1] == pytest.approx(T_COMPARE, abs=1e-12)
    return solution.particle(model.bob)[-1]


@pytest.mark.parametrize(
    ("alpha", "expected_order", "reference_dt"),
    [
        # docs/theory/time-rules.md: alpha = 1/2 is the trapezoidal rule, second order ...
        (0.5, 2.0, 1.25e-4),
        # ... and alpha = 1 is backward Euler, first order. Its reference run must be much finer
        # (40x below the finest step) to keep the reference's own error from biasing the fit.
        (1.0, 1.0, 2.5e-5),
    ],
)
def test_observed_order_of_accuracy(alpha, expected_order, reference_dt):
    # Errors of runs at dt = 8, 4, 2, 1 ms against a much finer run, at the same time t = 1 s.
    # The order is the least-squares slope of log(error) against log(dt). For backward Euler the
    # reference's error shifts the slope by about log((8 - 0.025)/(1 - 0.025))/log 8 - 1 = 0.01.
    steps = np.array([8e-3, 4e-3, 2e-3, 1e-3])
    reference = pendulum_position(reference_dt, alpha)
    errors = np.array([np.max(np.abs(pendulum_position(dt, alpha) - reference)) for dt in steps])
    order = np.polyfit(np.log(steps), np.log(errors), 1)[0]
    assert order == pytest.approx(expected_order, abs=0.2), f"errors {errors}"
    # Each halving also divides the error by about 2^order (local check, not only the fit).
    ratios = errors[:-1] / errors[1:]
    assert np.all(np.abs(np.log2(ratios) - expected_order) < 0.3), f"ratios {ratios}"
