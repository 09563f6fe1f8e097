"""Elastic segments that go slack (MoorDyn's): no compression, no force while shorter than
their length.

Reference, derived here: a particle of mass m hanging by a slack segment of length L and
stiffness k = EA / L from a fixed point, released at rest a height h above the point where the
segment becomes taut, falls freely, z(t) = z0 - g t^2 / 2, for t < sqrt(2 h / g); then the
segment stretches, and energy conservation m g (h + x) = k x^2 / 2 gives its largest stretch
x = (m g + sqrt((m g)^2 + 2 k m g h)) / k.
"""

import math

import numpy as np
import pytest

import vinculo
from vinculo.errors import InvalidInputError

G = 9.81


def drop(slack: bool, dt: float = 2e-4):
    system = vinculo.System(gravity=(0.0, 0.0, -G))
    top = system.add_particle(1.0, (0.0, 0.0, 0.0), fixed=True)
    mass = system.add_particle(2.0, (0.0, 0.0, -0.5))
    segment = system.add_elastic_distance(top, mass, length=1.0, ea=2.0e4)
    if slack:
        system.set_slack(segment)
    sol = vinculo.simulate(system, t_end=0.8, dt=dt, rho_inf=1.0, scheme="generalized-alpha")
    return sol, mass, segment


def test_a_slack_segment_lets_the_mass_fall_freely_then_catches_it():
    sol, mass, segment = drop(slack=True)
    z = sol.particle(mass)[:, 2]
    falling = sol.times < math.sqrt(2 * 0.5 / G) - 1e-3
    # Free fall while slack: no tension, positions on the parabola (constant acceleration is
    # integrated exactly by the rule, so to round-off).
    np.testing.assert_allclose(z[falling], -0.5 - G * sol.times[falling] ** 2 / 2, atol=1e-9)
    assert np.abs(sol.multiplier(segment)[falling]).max() == 0.0
    # Caught: the largest stretch from energy conservation (the step across the kink of the
    # tension is first order: 2e-4 s steps keep it within 0.2 %).
    k, m, h = 2.0e4, 2.0, 0.5
    stretch = (m * G + math.sqrt((m * G) ** 2 + 2 * k * m * G * h)) / k
    assert -z.min() - 1.0 == pytest.approx(stretch, rel=2e-3)
    assert sol.multiplier(segment).min() >= 0.0


def test_a_segment_that_is_not_slack_pushes():
    # The bilateral segment pushes the mass down while compressed: not free fall.
    sol, mass, _ = drop(slack=False)
    z = sol.particle(mass)[:, 2]
    early = (sol.times > 0.05) & (sol.times < 0.2)
    assert np.abs(z[early] - (-0.5 - G * sol.times[early] ** 2 / 2)).max() > 0.01


def test_only_elastic_segments_go_slack_or_take_axial_damping():
    system = vinculo.System()
    a = system.add_particle(1.0, (0.0, 0.0, 0.0), fixed=True)
    b = system.add_particle(1.0, (1.0, 0.0, 0.0))
    rod = system.add_distance(a, b)
    with pytest.raises(InvalidInputError, match="elastic segment"):
        system.set_slack(rod)
    with pytest.raises(InvalidInputError, match="elastic segment"):
        system.set_axial_damping(rod, 1.0)
    # The damping coefficient (N s/m) must be finite and >= 0.
    segment = system.add_elastic_distance(a, b, length=1.0, ea=1e4)
    for bad in (-1.0, math.nan, math.inf):
        with pytest.raises(InvalidInputError, match="axial damping"):
            system.set_axial_damping(segment, bad)


def test_a_damped_slack_segment_still_damps_as_moordyn_does():
    # MoorDyn applies a segment's internal damping BA / l whether it is stretched or slack:
    # while the mass falls with the segment slack, m z'' = -m g - c z' (the segment lengthens
    # at -z', its damping tension c (-z') holds the mass back), whose closed form from rest is
    # z = z0 - (m g / c) t + (m^2 g / c^2) (1 - e^(-c t / m)).
    system = vinculo.System(gravity=(0.0, 0.0, -G))
    top = system.add_particle(1.0, (0.0, 0.0, 0.0), fixed=True)
    m, c, z0 = 2.0, 3.0, -0.5
    mass = system.add_particle(m, (0.0, 0.0, z0))
    segment = system.add_elastic_distance(top, mass, length=1.0, ea=2.0e4)
    system.set_slack(segment)
    system.set_axial_damping(segment, c)
    sol = vinculo.simulate(system, t_end=0.25, dt=2e-4)
    t = sol.times
    closed = z0 - m * G / c * t + m * m * G / (c * c) * (1.0 - np.exp(-c * t / m))
    z = sol.particle(mass)[:, 2]
    # Still slack at 0.25 s (it fell 0.27 m of the 0.5 m). The trapezoidal rule's global
    # error, about h^2 / 12 |z'''| t = 1.2e-8 m with |z'''| <= g c / m (measured: 8.4e-9 m);
    # the undamped fall ends 3.5e-2 m lower.
    assert z[-1] > -1.0
    np.testing.assert_allclose(z, closed, rtol=0.0, atol=2e-8)
    assert abs(z[-1] - (z0 - G * t[-1] ** 2 / 2)) > 3e-2
