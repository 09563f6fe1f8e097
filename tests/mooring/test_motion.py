"""Motions of the coupled points: the laws that vinculo and the MoorDyn peer both follow."""

import math

import numpy as np
import pytest

from vinculo.errors import InvalidInputError
from vinculo.mooring import Motion


def test_a_recorded_motion_passes_through_its_samples_and_is_exact_for_linear_data(tmp_path):
    # A natural cubic spline interpolates its samples and reproduces linear data exactly
    # (vinculo.tabulated): a point drifting at (0.1, -0.2, 0.05) m/s.
    times = np.linspace(0.0, 10.0, 11)
    start = np.array([1.0, 2.0, -5.0])
    rate = np.array([0.1, -0.2, 0.05])
    samples = start + times[:, None] * rate
    path = Motion.from_table(times, samples[:, None, :]).to_csv(tmp_path / "m.csv", times)
    motion = Motion.from_csv(path)
    assert motion.num_points == 1 and motion.domain() == (0.0, 10.0)
    for t in (0.0, 3.3, 7.25, 10.0):
        np.testing.assert_allclose(motion.positions(t)[0], start + t * rate, atol=1e-12)
        np.testing.assert_allclose(motion.velocities(t)[0], rate, atol=1e-12)


def test_harmonic_motion_is_the_sine_law_about_the_start():
    # p0 + a sin(2 pi t / T) after the ramp; its rate a 2 pi / T cos(2 pi t / T).
    motion = Motion.harmonic([[0.0, 0.0, -10.0], [5.0, 0.0, -10.0]], (2.0, 0.0, 0.0),
                             period=10.0)
    t = 1.7
    expected = 2.0 * math.sin(2.0 * math.pi * t / 10.0)
    np.testing.assert_allclose(motion.positions(t), [[expected, 0.0, -10.0],
                                                     [5.0 + expected, 0.0, -10.0]])
    assert motion.velocities(t)[1, 0] == pytest.approx(
        2.0 * 2.0 * math.pi / 10.0 * math.cos(2.0 * math.pi * t / 10.0))
    # A smooth start: at rest at t = 0.
    ramped = Motion.harmonic([[0.0, 0.0, -10.0]], (2.0, 0.0, 0.0), period=10.0, ramp_time=10.0)
    np.testing.assert_allclose(ramped.velocities(0.0), 0.0, atol=1e-15)


def test_a_motion_table_of_the_wrong_shape_is_rejected():
    with pytest.raises(InvalidInputError, match="do not match"):
        Motion.from_table([0.0, 1.0], np.zeros((3, 1, 3)))
    with pytest.raises(InvalidInputError, match="period"):
        Motion.harmonic([[0.0, 0.0, 0.0]], (1.0, 0.0, 0.0), period=0.0)
