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
    # A preload of 2e4 N stretches it by 0.1 m, so that it stays taut (a MoorDyn segment goes
    # slack rather than push); released 1 cm below that equilibrium, it is pulled back up.
    preload = 2.0e4
    rest = length + preload * length / ea
    weight = s.add_particle(mass, (0.0, 0.0, -rest - 0.01))
    s.add_force(weight, (0.0, 0.0, -preload))
    add_line(s, top.index, weight.index, kind, length, 1, Water(depth=100.0, density=1e-9))
    omega = math.sqrt(ea / (length * mass))
    period = 2.0 * math.pi / omega
    sol = vinculo.simulate(s, 6.0 * period, period / 400.0)
    z = sol.particle(weight)[:, 2] + rest
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


def test_chain_on_the_seabed_from_a_compressed_straight_start():
    # The chain of tests/data/moordyn/chain_on_seabed.txt (315 m over a 302.6 m chord, part of it
    # on the seabed) started on the straight chord, 4 % compressed: Newton's method fails there
    # and the continuation buckles it down onto the seabed, to the equilibrium that Newton's
    # method reaches from the catenary start, to round-off.
    from vinculo.mooring.model import build_model

    built = build_model("tests/data/moordyn/chain_on_seabed.txt", solve=False)
    system, line = built.system, built.lines[0]
    reference = solve_statics(system.copy(), apply=False)
    assert reference.method == "newton"
    q = np.array(system.initial_positions())
    a, b = q[line.nodes[0]], q[line.nodes[-1]]
    u = np.linspace(0.0, 1.0, len(line.nodes))[1:-1, None]
    q[line.nodes[1:-1]] = a + u * (b - a)
    straight = system.copy()
    straight.set_initial_state(q)
    eq = solve_statics(straight, apply=False)
    assert eq.method == "continuation"
    np.testing.assert_allclose(eq.positions, reference.positions, atol=1e-9)
    np.testing.assert_allclose(eq.multipliers, reference.multipliers, rtol=1e-7)


def test_winch_pays_out_a_line_to_the_statics_of_its_new_length():
    # A clump hanging by a 50 m rope that a winch pays out at 0.2 m/s (L(t) = 50 + 0.2 t, each
    # of the 10 segments keeping its tenth): slowly against the axial period (0.3 s), so the
    # clump follows the equilibrium of the current length; after 10 s it is where the statics
    # at t = 10 s put it (backward Euler damps the start's oscillation), to 1 mm.
    kind = LineType("rope", diameter=0.05, mass_per_length=5.0, ea=2.0e7)
    s = vinculo.System(gravity=(0.0, 0.0, -G))
    top = s.add_particle(1.0, (0.0, 0.0, -5.0), fixed=True)
    clump = s.add_particle(500.0, (0.0, 0.0, -55.0))
    add_line(s, top.index, clump.index, kind, vinculo.laws.polynomial([50.0, 0.2]), 10, WATER)
    later = solve_statics(s.copy(), t=10.0, apply=False)
    solve_statics(s)
    sol = vinculo.simulate(s, 10.0, 0.01, alpha=1.0)
    z = sol.particle(clump)[-1, 2]
    assert z == pytest.approx(later.positions[clump.index, 2], abs=1e-3)
    # 2 m paid out: the clump 2 m (and the stretch of the added line) lower.
    assert z < -57.0
