"""The closed-form elastic catenary (vinculo.mooring.catenary) against independent references:
the inextensible catenary (EA -> infinity), the straight elastic bar (w -> 0), and the line's
equilibrium equations integrated numerically from the anchor with scipy's solve_ivp."""

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from vinculo.errors import InvalidInputError
from vinculo.mooring import solve_catenary, weight_in_water

# The chain and the rope of tests/data/moordyn (chain_on_seabed.txt, taut_line.txt).
CHAIN_W = weight_in_water(126.0, 0.137)
ROPE_W = weight_in_water(8.0, 0.08)


def test_weight_in_water_is_weight_less_buoyancy():
    # 1 m of a 0.1 m cylinder of 100 kg: (100 - 1025 pi 0.05^2) g.
    assert weight_in_water(100.0, 0.1, 1025.0, 9.81) == pytest.approx(
        (100.0 - 1025.0 * math.pi * 0.0025) * 9.81, rel=1e-15)


def test_inextensible_hanging_line_matches_the_catenary_cosh():
    # Both ends at the same height, X apart: L = 2 a sinh(X / 2a) with a = H / w (Irvine 1981,
    # eq. 1.9), V = w L / 2 at each end by symmetry.
    w, span, length = 176.0, 80.0, 100.0
    a = brentq(lambda a: 2.0 * a * math.sinh(span / (2.0 * a)) - length, 1.0, 1e4, xtol=1e-14)
    sol = solve_catenary(span, 0.0, length, w, math.inf, seabed_contact=False)
    assert sol.horizontal_tension == pytest.approx(a * w, rel=1e-11)
    assert sol.fairlead_vertical_tension == pytest.approx(w * length / 2.0, rel=1e-11)
    assert sol.anchor_vertical_tension == pytest.approx(-w * length / 2.0, rel=1e-11)
    assert sol.laid_length == 0.0
    # The sag at mid-span: a (cosh(X / 2a) - 1).
    _, z = sol.profile(length / 2.0)
    assert -z == pytest.approx(a * (math.cosh(span / (2.0 * a)) - 1.0), rel=1e-10)


@pytest.mark.parametrize("horizontal_tension", [2.0e3, 2.0e4, 2.0e5])
def test_inextensible_line_on_the_seabed_matches_the_touchdown_catenary(horizontal_tension):
    # Inextensible, touching the seabed: the suspended part of length l_s is a catenary with its
    # vertex at the touchdown point, Z = a (cosh(x_s / a) - 1), l_s = a sinh(x_s / a), so that
    # l_s = sqrt(Z^2 + 2 a Z) and X = L - l_s + a asinh(l_s / a) (Irvine 1981, section 1.3).
    # Pick H, build X from these, and recover H, V and the laid length.
    w, z, length = CHAIN_W, 40.0, 400.0
    a = horizontal_tension / w
    suspended = math.sqrt(z * z + 2.0 * a * z)
    span = length - suspended + a * math.asinh(suspended / a)
    sol = solve_catenary(span, z, length, w, math.inf)
    assert sol.horizontal_tension == pytest.approx(horizontal_tension, rel=1e-9)
    assert sol.fairlead_vertical_tension == pytest.approx(w * suspended, rel=1e-9)
    assert sol.laid_length == pytest.approx(length - suspended, rel=1e-9)
    assert sol.anchor_tension == pytest.approx(horizontal_tension, rel=1e-9)


@pytest.mark.parametrize(("span", "height"), [(60.0, 75.0), (100.0, 0.0), (30.0, 5.0)])
def test_weightless_limit_is_a_straight_elastic_bar(span, height):
    # w -> 0: a straight bar, T = EA (D / L - 1) along the chord D.
    ea, length = 1.0e7, 0.99 * math.hypot(span, height)
    chord = math.hypot(span, height)
    tension = ea * (chord / length - 1.0)
    for w in (0.0, 1e-6):
        sol = solve_catenary(span, height, length, w, ea, seabed_contact=False)
        assert sol.fairlead_tension == pytest.approx(tension, rel=1e-7)
        assert sol.horizontal_tension == pytest.approx(tension * span / chord, rel=1e-7)


def test_the_two_forms_meet_where_the_line_touches_down_at_the_anchor():
    # V_B = w L: the suspended form (V_A = 0) and the seabed form (L_B = 0) give the same spans.
    w, length, ea, h = CHAIN_W, 300.0, 5e8, 3.0e5
    from vinculo.mooring.catenary import _spans

    on_bed = _spans(h, w * length * (1 - 1e-13), length, w, ea, True)
    hanging = _spans(h, w * length, length, w, ea, False)
    assert on_bed[0] == pytest.approx(hanging[0], rel=1e-12)
    assert on_bed[1] == pytest.approx(hanging[1], rel=1e-12)


def _integrate(sol, s_start, state0):
    """Integrate the equilibrium of the suspended line in its unstretched arc length s:
    dH/ds = 0, dV/ds = w, dx/ds = (H / T)(1 + T / EA), dz/ds = (V / T)(1 + T / EA)."""
    h, w, ea = sol.horizontal_tension, sol.weight, sol.ea

    def rhs(_s, y):
        v = y[2]
        t = math.hypot(h, v)
        stretch = 1.0 + t / ea
        return [h / t * stretch, v / t * stretch, w]

    return solve_ivp(rhs, (s_start, sol.length), state0, method="DOP853", rtol=1e-12,
                     atol=1e-10, dense_output=True)


@pytest.mark.parametrize(
    ("span", "height", "length", "w", "ea", "contact"),
    [
        (300.0, 40.0, 315.0, CHAIN_W, 5e8, True),    # chain_on_seabed.txt: slack, on the seabed
        (60.0, 75.0, 95.0, ROPE_W, 1e7, True),       # taut_line.txt: taut, anchor lifted
        (80.0, 0.0, 100.0, 176.0, 1e8, False),        # hanging_line.txt: hanging between points
        (50.0, 20.0, 60.0, CHAIN_W, 2e6, True),       # very stretchy, on the seabed
    ],
)
def test_integrating_the_equilibrium_from_the_anchor_lands_on_the_fairlead(
    span, height, length, w, ea, contact
):
    sol = solve_catenary(span, height, length, w, ea, seabed_contact=contact)
    if sol.laid_length > 0.0:
        # From the touchdown point: the laid part is straight, stretched by H.
        start = sol.laid_length
        y0 = [start * (1.0 + sol.horizontal_tension / ea), 0.0, 0.0]
    else:
        start = 0.0
        y0 = [0.0, 0.0, sol.anchor_vertical_tension]
    result = _integrate(sol, start, y0)
    x, z, v = result.y[:, -1]
    assert x == pytest.approx(span, abs=1e-7 * length)
    assert z == pytest.approx(height, abs=1e-7 * length)
    assert v == pytest.approx(sol.fairlead_vertical_tension, rel=1e-9)
    # The closed-form profile follows the integrated one all along.
    s = np.linspace(start, length, 9)
    xs, zs = sol.profile(s)
    xi, zi, _ = result.sol(s)
    np.testing.assert_allclose(xs, xi, rtol=0, atol=1e-7 * length)
    np.testing.assert_allclose(zs, zi, rtol=0, atol=1e-7 * length)
    # The laid part lies on the seabed.
    if sol.laid_length > 0.0:
        _, z_bed = sol.profile(np.linspace(0.0, sol.laid_length, 5))
        assert np.all(z_bed == 0.0)


def test_a_line_too_long_to_be_taut_is_rejected():
    # 500 m of chain for a fairlead 100 m away and 40 m up lies slack on the seabed: H = 0.
    with pytest.raises(InvalidInputError, match="slack"):
        solve_catenary(100.0, 40.0, 500.0, CHAIN_W, 5e8)


@pytest.mark.parametrize("bad", [{"horizontal_span": -1.0}, {"vertical_span": -2.0},
                                 {"length": 0.0}, {"weight": -1.0}, {"ea": 0.0}])
def test_out_of_domain_arguments_name_the_argument(bad):
    args = {"horizontal_span": 100.0, "vertical_span": 40.0, "length": 150.0,
            "weight": 100.0, "ea": 1e8} | bad
    with pytest.raises(InvalidInputError) as info:
        solve_catenary(**args)
    assert info.value.name == next(iter(bad))
