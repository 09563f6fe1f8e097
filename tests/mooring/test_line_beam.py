"""A line with bending stiffness against the small-deflection theory of a tensioned beam.

A line of unstretched length L, bending stiffness EI and axial stiffness EA is held straight
between two fixed points L apart (pinned: MoorDyn's and vinculo's line ends carry no moment)
and sags under its weight in water q (N/m). Small-deflection theory of a beam under an axial
tension H (Timoshenko and Gere, "Theory of Elastic Stability", 2nd ed., 1961, section 1.11,
the beam-column with its sign of the axial force reversed; Irvine, "Cable Structures", 1981,
section 3.8, for the cable with flexural rigidity): with w(x) the deflection (down) and
k^2 = H / EI,

    EI w'''' - H w'' = q,    w(0) = w(L) = 0,    w''(0) = w''(L) = 0 (pinned),

    w(x) = q x (L - x) / (2 H) - q / (H k^2) (1 - cosh(k (x - L/2)) / cosh(k L / 2)),

and the tension follows from the stretch, since the line must be longer than the span by the
sag: H / EA = (1 / 2L) integral_0^L w'^2 dx (the arc length to second order in the slope).
That scalar equation for H is solved here by ``scipy.optimize.brentq``; the integral by
``scipy.integrate.quad``. The parameters give k L / 2 = 0.8 and a slope of at most 0.04, so
bending and tension share the load and the theory's neglected terms (the square of the slope)
are below 2e-3 of the result.
"""

import math

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.optimize import brentq

import vinculo
from vinculo.mooring.catenary import weight_in_water
from vinculo.mooring.line import LineType, Water, add_line
from vinculo.mooring.statics import solve_statics

WATER = Water(depth=500.0)
SPAN = 10.0
KIND = LineType("cable", diameter=0.1, mass_per_length=18.0, ea=1.0e7, ei=1.0e5)


def _beam(q: float) -> tuple[float, float]:
    """The horizontal tension H (N) and the midspan deflection (m) of the closed form."""
    ei, ea, length = KIND.ei, KIND.ea, SPAN

    def slope(x: float, h: float) -> float:
        k = math.sqrt(h / ei)
        return q * (length - 2.0 * x) / (2.0 * h) \
            + q / (h * k) * math.sinh(k * (x - length / 2.0)) / math.cosh(k * length / 2.0)

    def mismatch(h: float) -> float:
        stretch = quad(lambda x: slope(x, h) ** 2, 0.0, length, epsabs=0.0, epsrel=1e-13)[0]
        return h / ea - stretch / (2.0 * length)

    h = brentq(mismatch, 1.0, 1.0e6, xtol=1e-12, rtol=1e-14)
    k = math.sqrt(h / ei)
    middle = q * length**2 / (8.0 * h) - q / (h * k * k) * (1.0 - 1.0 / math.cosh(k * length / 2))
    return h, middle


def _line(segments: int) -> tuple[float, float, float]:
    """vinculo's horizontal tension (N), midspan deflection (m) and vertical force on end A (N)
    with ``segments``."""
    s = vinculo.System(gravity=(0.0, 0.0, -WATER.gravity))
    a = s.add_particle(1.0, (0.0, 0.0, -100.0), fixed=True)
    b = s.add_particle(1.0, (SPAN, 0.0, -100.0), fixed=True)
    line = add_line(s, a.index, b.index, KIND, SPAN, segments, WATER)
    eq = solve_statics(s)
    force_a = line.end_forces(eq)[0][-1]
    z = eq.positions[line.nodes, 2]
    return float(force_a[0]), float(-100.0 - z[segments // 2]), float(force_a[2])


def test_the_closed_form_is_in_its_small_deflection_range():
    q = weight_in_water(KIND.mass_per_length, KIND.diameter, WATER.density, WATER.gravity)
    h, middle = _beam(q)
    k = math.sqrt(h / KIND.ei)
    # Bending and tension both matter (k L / 2 of order one) and the slopes are small.
    assert 0.5 < k * SPAN / 2.0 < 1.5
    assert 4.0 * middle / SPAN < 0.1


def test_line_with_bending_stiffness_matches_the_tensioned_beam():
    q = weight_in_water(KIND.mass_per_length, KIND.diameter, WATER.density, WATER.gravity)
    h_ref, middle_ref = _beam(q)
    errors = []
    for n in (10, 20, 40):
        h, middle, vertical = _line(n)
        errors.append((abs(h / h_ref - 1.0), abs(middle / middle_ref - 1.0)))
        # Each end carries half the line's weight in water (the line's equilibrium and its
        # symmetry, whatever the discretisation): the end force holds the bending element's
        # shear besides the end segment's tension.
        assert vertical == pytest.approx(-q * SPAN / 2.0, rel=1e-8)
    # Measured: 6e-4 in tension and 1e-4 in deflection at 40 segments.
    h_err, middle_err = errors[-1]
    assert h_err < 2e-3 and middle_err < 1e-3, errors
    # The discretisation error shrinks as the segments do.
    assert errors[0][1] > 10.0 * errors[-1][1], errors


def test_a_finely_divided_cable_steps_without_halving():
    # 500 segments of 6 cm with EI = 2e4 N m^2: the bending stiffness EI / l^3 = 9e7 N/m times the
    # rounding of 30 m positions puts each step's residual round-off (about 3e-10 of the scaled
    # residual at 0.1 s steps) above Newton's tolerance 1e-10. Newton stops at that round-off
    # (integrators/newton.rs) instead of failing, so no step is halved; before, every 0.1 s step
    # was halved down to a few milliseconds (50 times more factorisations).
    from vinculo.mooring.analysis import run
    from vinculo.mooring.bench import bending_line, motion_for

    model = bending_line(500)
    result = run(model, motion_for(model), 1.0, dt=0.1)
    assert np.diff(result.times).min() == pytest.approx(0.1, rel=1e-9)
