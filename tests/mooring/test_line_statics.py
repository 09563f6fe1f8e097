"""``vinculo.mooring.line`` and ``vinculo.mooring.statics`` against closed forms:

- a line hanging freely between two fixed points, inextensible and elastic, against the
  elastic catenary (Irvine 1981, "Cable Structures", eqs. 2.3-2.5, in
  ``vinculo.mooring.catenary``): the end tensions converge at second order in the segment length
  (measured: the error falls by 4 when the segments halve) and are within 1e-3 from 20
  segments on;
- the axial damping ratio of a segment (MoorDyn's negative BA) against the logarithmic
  decrement of a mass hanging by one segment;
- the point stiffness against finite differences of the statics.
"""

import math

import numpy as np
import pytest

import vinculo
from vinculo.mooring.catenary import solve_catenary, weight_in_water
from vinculo.mooring.line import LineType, Water, add_line
from vinculo.mooring.statics import point_force, point_stiffness, solve_statics

WATER = Water(depth=500.0)
G = WATER.gravity


def _hanging(line_type, segments, length=120.0, end=(100.0, 0.0, 30.0)):
    """A line of ``length`` between fixed points at (0, 0, -100) and ``end`` (+ (0, 0, -100)),
    in equilibrium."""
    s = vinculo.System(gravity=(0.0, 0.0, -G))
    a = s.add_particle(1.0, (0.0, 0.0, -100.0), fixed=True)
    b = s.add_particle(1.0, (end[0], end[1], end[2] - 100.0), fixed=True)
    line = add_line(s, a.index, b.index, line_type, length, segments, WATER)
    eq = solve_statics(s)
    return line, eq


def _reference(line_type, length=120.0, end=(100.0, 0.0, 30.0)):
    w = weight_in_water(line_type.mass_per_length, line_type.diameter, WATER.density, G)
    return solve_catenary(math.hypot(end[0], end[1]), end[2], length, w, line_type.ea,
                          seabed_contact=False)


@pytest.mark.parametrize("ea", [math.inf, 2.0e6])
def test_hanging_line_converges_to_the_elastic_catenary(ea):
    kind = LineType("wire", diameter=0.05, mass_per_length=20.0, ea=ea)
    cat = _reference(kind)
    errors = []
    for n in (10, 20, 40, 80):
        line, eq = _hanging(kind, n)
        fa, fb = (f[-1] for f in line.end_forces(eq))
        errors.append(max(abs(np.linalg.norm(fa) / cat.anchor_tension - 1.0),
                          abs(np.linalg.norm(fb) / cat.fairlead_tension - 1.0)))
        # The horizontal tension is the same all along the line, in the model as in the
        # closed form.
        assert -fb[0] == pytest.approx(fa[0], rel=1e-9)
    # Second order in the segment length: each halving divides the error by about 4.
    ratios = [errors[k] / errors[k + 1] for k in range(3)]
    assert all(3.5 < r < 4.5 for r in ratios), (errors, ratios)
    assert errors[1] < 1e-3, errors


def test_static_stretch_of_an_elastic_line_is_hookes():
    # A vertical line of 50 m hanging a 2 t clump: its stretch is the integral of T / EA,
    # (m_clump g' + w s) / EA over the unstretched length s (closed form).
    kind = LineType("rope", diameter=0.08, mass_per_length=5.0, ea=1.0e7)
    s = vinculo.System(gravity=(0.0, 0.0, -G))
    top = s.add_particle(1.0, (0.0, 0.0, -10.0), fixed=True)
    clump = s.add_particle(2000.0, (0.0, 0.0, -60.0))
    add_line(s, clump.index, top.index, kind, 50.0, 25, WATER)
    eq = solve_statics(s)
    w = weight_in_water(kind.mass_per_length, kind.diameter, WATER.density, G)
    # The clump carries its own weight and the half segment at its end (2 m of line).
    seg = 50.0 / 25
    clump_load = 2000.0 * G + w * seg / 2.0
    stretch = (clump_load * 50.0 + w * (50.0 - seg / 2.0) ** 2 / 2.0) / kind.ea
    # The lumped line's stretch equals the integral's midpoint sum: exact for a linear T(s).
    assert -10.0 - eq.positions[clump.index, 2] - 50.0 == pytest.approx(stretch, rel=1e-6)


def test_damping_ratio_of_a_segment_is_moordyns():
    # A mass m = w L / 4 hanging by one segment of BA = -zeta: MoorDyn's BA = zeta L sqrt(EA w)
    # gives the dashpot c = BA / L and the oscillator m x'' + c x' + (EA / L) x = 0 the damping
    # ratio c / (2 sqrt(EA m / L)) = zeta (closed form), measured by the logarithmic decrement
    # ln(x_k / x_{k+1}) = 2 pi zeta / sqrt(1 - zeta^2) between successive peaks.
    zeta, ea, w, length = 0.05, 1.0e6, 10.0, 5.0
    mass = w * length / 4.0
    kind = LineType("rope", diameter=0.01, mass_per_length=w, ea=ea, ba=-zeta)
    s = vinculo.System(gravity=(0.0, 0.0, 0.0))
    top = s.add_particle(1.0, (0.0, 0.0, 0.0), fixed=True)
    # Released 1 cm below its rest length: the segment pulls it up.
    weight = s.add_particle(mass, (0.0, 0.0, -length - 0.01))
    add_line(s, top.index, weight.index, kind, length, 1, Water(depth=100.0, density=1e-9))
    omega = math.sqrt(ea / (length * mass))
    period = 2.0 * math.pi / omega
    sol = vinculo.simulate(s, 6.0 * period, period / 400.0)
    z = sol.particle(weight)[:, 2] + length
    peaks = [abs(z[k]) for k in range(1, len(z) - 1)
             if abs(z[k]) >= abs(z[k - 1]) and abs(z[k]) > abs(z[k + 1]) and z[k] < 0.0]
    decrement = np.log(peaks[0] / peaks[1])
    measured = decrement / math.sqrt(4.0 * math.pi**2 + decrement**2)
    # Trapezoidal rule at 400 steps per period: the decrement to 1e-3.
    assert measured == pytest.approx(zeta, rel=1e-3)


def test_fairlead_stiffness_matches_finite_differences_of_the_statics():
    kind = LineType("wire", diameter=0.05, mass_per_length=20.0, ea=2.0e6)
    s = vinculo.System(gravity=(0.0, 0.0, -G))
    a = s.add_particle(1.0, (0.0, 0.0, -100.0), fixed=True)
    b = s.add_particle(1.0, (100.0, 10.0, -70.0), fixed=True)
    add_line(s, a.index, b.index, kind, 120.0, 20, WATER)
    eq = solve_statics(s)
    k = point_stiffness(s, eq, b.index)
    h = 1e-3
    fd = np.zeros((3, 3))
    for j in range(3):
        forces = []
        for sign in (1.0, -1.0):
            moved = s.copy()
            q = eq.positions.copy()
            q[b.index, j] += sign * h
            moved.set_initial_state(q)
            forces.append(point_force(moved, solve_statics(moved), b.index))
        fd[:, j] = -(forces[0] - forces[1]) / (2.0 * h)
    # Central differences over re-solved equilibria: O(h^2) truncation.
    np.testing.assert_allclose(k, fd, atol=1e-5 * np.abs(k).max())
    np.testing.assert_allclose(k, k.T, atol=1e-9 * np.abs(k).max())
