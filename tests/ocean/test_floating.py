"""Free-floating bodies in still water: equilibrium against Archimedes, small heave
oscillations against the closed-form natural period with the added mass used.

References (closed forms derived here):
- a sphere of radius R floating with its centre at z_c displaces the cap of depth d = R - z_c,
  V = pi d^2 (3R - d) / 3; a vertical cylinder of radius R at draft T displaces pi R^2 T;
- small heave oscillations about equilibrium have the natural period
  T_n = 2 pi sqrt((m + m_a) / (rho g A_wp)), A_wp the waterplane area (pi (R^2 - z_c^2) for the
  sphere, pi R^2 for the cylinder), m_a the added mass (here given, Ca rho V at equilibrium).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import optimize

import vinculo
from vinculo.errors import InvalidInputError
from vinculo.ocean import Sea, cylinder, sphere

RHO, G = 1025.0, 9.80665


def free_heave(mass, inertia, hull, start_z, added_mass, t_end, dt=0.005):
    """A rigid body of `mass` released at rest with its centre at `start_z` in still water."""
    system = vinculo.System(gravity=(0.0, 0.0, -G))
    body = system.add_rigid_body(mass, (0.0, 0.0, start_z), inertia)
    system.add_floating_body(body, hull, added_mass=added_mass, density=RHO)
    system.set_water(Sea(depth=50.0, density=RHO, g=G).water())
    sol = vinculo.simulate(system, t_end=t_end, dt=dt)
    return sol.times, sol.particle(body["centre"])[:, 2]


def period_and_mean(t, z):
    """The period from the upward crossings of the mean (linear interpolation between
    samples), and the mean over the whole number of periods between the first and last."""
    mean = z.mean()
    for _ in range(2):
        s = z - mean
        i = np.nonzero((s[:-1] < 0) & (s[1:] >= 0))[0]
        crossings = t[i] - s[i] * (t[i + 1] - t[i]) / (s[i + 1] - s[i])
        window = (t >= crossings[0]) & (t <= crossings[-1])
        mean = np.trapezoid(z[window], t[window]) / (crossings[-1] - crossings[0])
    return np.diff(crossings).mean(), mean


def test_floating_sphere_equilibrium_and_heave_period():
    radius = 1.0
    draft = 1.3  # deeper than half: the waterplane narrows with the draft
    volume = math.pi * draft**2 * (3 * radius - draft) / 3
    mass = RHO * volume
    z_eq = radius - draft
    added = 0.5 * RHO * volume
    inertia = np.eye(3) * 0.4 * mass * radius**2
    t, z = free_heave(mass, inertia, sphere(radius), z_eq + 0.01, added, t_end=16.0)
    period, mean = period_and_mean(t, z)
    area = math.pi * (radius**2 - z_eq**2)
    expected = 2 * math.pi * math.sqrt((mass + added) / (RHO * G * area))
    assert period == pytest.approx(expected, rel=2e-3), (period, expected)
    # Archimedes: the mean of the oscillation is the equilibrium (to the second-order shift
    # of a 1 cm oscillation, below 0.1 mm here).
    assert mean == pytest.approx(z_eq, abs=5e-4), (mean, z_eq)


def test_floating_cylinder_equilibrium_and_heave_period():
    radius, height, draft = 0.8, 3.0, 1.7
    mass = RHO * math.pi * radius**2 * draft
    added = 0.3 * mass
    # A ballasted cylinder: its centre (of mass) 0.5 m above the keel, so that it floats
    # upright. The metacentric height is GM = KB + BM - KG = T/2 + R^2/(4T) - KG = 0.44 m; with
    # its centre at half height (KG = 1.5 m) GM would be -0.56 m, and the upright cylinder
    # would capsize from the round-off of its first steps (the tilt grows as exp(2.5 t), at
    # the rate sqrt(m g |GM| / I)).
    keel_to_centre = 0.5
    hull = cylinder(radius, -keel_to_centre, height - keel_to_centre)
    z_centre_eq = keel_to_centre - draft
    inertia = np.diag([mass * (3 * radius**2 + height**2) / 12] * 2 + [mass * radius**2 / 2])
    t, z = free_heave(mass, inertia, hull, z_centre_eq - 0.02, added, t_end=16.0)
    period, mean = period_and_mean(t, z)
    expected = 2 * math.pi * math.sqrt((mass + added) / (RHO * G * math.pi * radius**2))
    assert period == pytest.approx(expected, rel=2e-3), (period, expected)
    assert mean == pytest.approx(z_centre_eq, abs=5e-4), (mean, z_centre_eq)


def test_sphere_draft_solves_archimedes_for_any_mass():
    # The closed form's root against the simulated equilibrium, lighter than half submerged.
    radius, mass = 0.6, 250.0

    def displaced(d):
        return math.pi * d * d * (3 * radius - d) / 3 - mass / RHO

    draft = optimize.brentq(displaced, 0.0, 2 * radius)
    t, z = free_heave(mass, np.eye(3) * 0.4 * mass * radius**2, sphere(radius),
                      radius - draft + 0.005, 0.0, t_end=8.0)
    _, mean = period_and_mean(t, z)
    assert mean == pytest.approx(radius - draft, abs=3e-4)


def test_bad_floating_input_is_named():
    system = vinculo.System(gravity=(0.0, 0.0, -G))
    body = system.add_rigid_body(100.0, (0.0, 0.0, 0.0), np.eye(3) * 10.0)
    with pytest.raises(InvalidInputError, match="radius of hull section #0"):
        system.add_floating_body(body, sphere(-1.0))
    with pytest.raises(InvalidInputError, match="top of hull section #0"):
        system.add_floating_body(body, cylinder(1.0, 2.0, 1.0))
    tetra = system.add_rigid_body(100.0, (5.0, 0.0, 0.0), np.eye(3) * 10.0, particles=4)
    with pytest.raises(InvalidInputError, match="centre particle"):
        system.add_floating_body(tetra, sphere(1.0), origin=(5.0, 0.0, 0.0), ca=1.0)
