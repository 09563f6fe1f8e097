"""Water kinematics against closed forms; generated seas against their spectra.

The closed forms are those of linear (Airy) wave theory in finite depth (Dean and Dalrymple,
*Water Wave Mechanics for Engineers and Scientists*, 1991, ch. 4), written out here in numpy
independently of the core: with theta = k x - omega t + eps and omega^2 = g k tanh(k h),

    eta = a cos(theta)
    u = a omega cosh(k(z+h))/sinh(kh) cos(theta),   w = a omega sinh(k(z+h))/sinh(kh) sin(theta)
    du/dt = a omega^2 cosh(k(z+h))/sinh(kh) sin(theta)
    dw/dt = -a omega^2 sinh(k(z+h))/sinh(kh) cos(theta)
    p = rho g a cosh(k(z+h))/cosh(kh) cos(theta)
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import integrate, optimize, signal

import vinculo
from vinculo.errors import InvalidInputError
from vinculo.ocean import Current, Sea, from_elevation, jonswap, pierson_moskowitz, spreading

G = 9.80665
RHO = 1025.0


def airy(a, omega, k, h, x, z, t, eps=0.0):
    """The closed forms of the module docstring, for a wave travelling along x."""
    th = k * x - omega * t + eps
    ch, sh = np.cosh(k * (z + h)), np.sinh(k * (z + h))
    u = a * omega * ch / np.sinh(k * h) * np.cos(th)
    w = a * omega * sh / np.sinh(k * h) * np.sin(th)
    du = a * omega**2 * ch / np.sinh(k * h) * np.sin(th)
    dw = -a * omega**2 * sh / np.sinh(k * h) * np.cos(th)
    p = RHO * G * a * ch / np.cosh(k * h) * np.cos(th)
    return a * np.cos(th), np.column_stack([u, 0 * u, w]), np.column_stack([du, 0 * du, dw]), p


def test_wave_number_solves_the_dispersion_relation():
    # Reference: the root of omega^2 = g k tanh(k h) bracketed and found by scipy's brentq.
    for depth, period in [(5.0, 12.0), (30.0, 8.0), (200.0, 6.0)]:
        sea = Sea.regular(1.0, period, depth)
        omega = 2 * math.pi / period

        def dispersion(k, depth=depth, omega=omega):
            return G * k * math.tanh(k * depth) - omega**2

        k = optimize.brentq(dispersion, 1e-8, 10.0, xtol=1e-15)
        assert sea.wave_numbers[0] == pytest.approx(k, rel=1e-12)


@pytest.mark.parametrize("depth", [12.0, 40.0])
def test_regular_wave_kinematics_against_airy_closed_forms(depth):
    height, period, eps = 2.0, 8.0, 0.4
    # Vertical stretching leaves the linear field as it is below z = 0.
    sea = Sea.regular(height, period, depth, phase=eps, stretching="vertical")
    k = sea.wave_numbers[0]
    omega = 2 * math.pi / period
    x = np.linspace(-30.0, 30.0, 7)
    z = np.linspace(-depth, 0.0, 7)
    points = np.column_stack([x, np.zeros_like(x), z])
    for t in (0.0, 1.3, 5.9):
        flow = sea.flow(points, t)
        eta, u, a, p = airy(height / 2, omega, k, depth, x, z, t, eps)
        scale = height / 2 * omega
        np.testing.assert_allclose(flow["velocity"], u, rtol=0, atol=1e-12 * scale)
        np.testing.assert_allclose(flow["acceleration"], a, rtol=0, atol=1e-12 * scale * omega)
        np.testing.assert_allclose(flow["pressure"], p, rtol=0, atol=1e-9 * RHO * G)
        np.testing.assert_allclose(flow["elevation"], eta, rtol=0, atol=1e-13)


def test_wheeler_stretching_evaluates_the_linear_field_at_the_stretched_height():
    # Wheeler (1970): the flow at z is the linear flow at z' = h (z - eta) / (h + eta).
    depth, height, period = 20.0, 3.0, 9.0
    sea = Sea.regular(height, period, depth)
    k, omega = sea.wave_numbers[0], 2 * math.pi / period
    t = 0.0  # a crest at x = 0: eta = 1.5 m
    x = np.zeros(5)
    z = np.array([-20.0, -10.0, -1.0, 0.0, 1.4])
    eta = height / 2
    z_stretched = depth * (z - eta) / (depth + eta)
    _, u, a, _ = airy(height / 2, omega, k, depth, x, z_stretched, t)
    flow = sea.flow(np.column_stack([x, x, z]), t)
    np.testing.assert_allclose(flow["velocity"], u, atol=1e-12)
    np.testing.assert_allclose(flow["acceleration"], a, atol=1e-12)


def test_current_profiles_against_their_formulas():
    depth = 50.0
    z = np.array([-50.0, -40.0, -12.5, -1.0, 0.0, 2.0])
    points = np.column_stack([0 * z, 0 * z, z])
    power = Sea(depth, current=Current.power_law((1.2, 0.0, 0.0), 1 / 7)).flow(points, 0.0)
    expected = 1.2 * ((np.minimum(z, 0.0) + depth) / depth) ** (1 / 7)
    np.testing.assert_allclose(power["velocity"][:, 0], expected, rtol=1e-14)
    table = Current.table([-50.0, -10.0, 0.0], [[0.1, 0, 0], [0.5, 0, 0], [0.7, 0.1, 0]])
    flow = Sea(depth, current=table).flow(points, 0.0)
    np.testing.assert_allclose(flow["velocity"][:, 0],
                               np.interp(np.minimum(z, 0.0), [-50, -10, 0], [0.1, 0.5, 0.7]),
                               rtol=1e-14)


def test_jonswap_and_pierson_moskowitz_spectra():
    hs, tp = 4.0, 10.0
    wp = 2 * math.pi / tp
    # Normalised exactly: the zeroth moment is hs^2 / 16.
    for gamma in (1.0, 3.3, 7.0):
        w = np.linspace(1e-3, 60 * wp, 400_001)
        m0 = integrate.simpson(jonswap(w, hs, tp, gamma), x=w)
        assert m0 == pytest.approx(hs**2 / 16, rel=1e-6)
        # DNV-RP-C205 3.5.5.4: A_gamma = 1 - 0.287 ln(gamma) approximates that normalisation.
        ratio = jonswap(wp, hs, tp, gamma) / pierson_moskowitz(wp, hs, tp)
        assert ratio == pytest.approx((1 - 0.287 * math.log(gamma)) * gamma, rel=0.02)
    # Pierson-Moskowitz in closed form (DNV-RP-C205 eq. 3.5.3): 5/16 hs^2 wp^4 w^-5 e^-5/4(w/wp)^-4.
    w = np.linspace(0.3, 3.0, 50)
    closed = 5 / 16 * hs**2 * wp**4 * w**-5 * np.exp(-1.25 * (w / wp) ** -4)
    np.testing.assert_allclose(pierson_moskowitz(w, hs, tp), closed, rtol=2e-4)
    # The cos^n spreading integrates to one.
    total, _ = integrate.quad(lambda th: float(spreading(th, 4.0, 0.3)), -math.pi, math.pi,
                              points=[0.3 - math.pi / 2, 0.3 + math.pi / 2])
    assert total == pytest.approx(1.0, rel=1e-10)


def test_irregular_sea_has_the_target_hs_and_tp():
    """A three-hour record at one point of a generated JONSWAP sea: its significant height
    4 std(eta) and its peak period (of the Welch spectrum) against the targets, within the
    statistical error of a record of that length."""
    hs, tp = 3.0, 10.0
    sea = Sea.irregular(hs, tp, depth=200.0, count=400, seed=7)
    t = np.arange(0.0, 3 * 3600.0, 0.25)
    eta = sea.elevation(t, (15.0, -4.0))
    # Random phases with deterministic amplitudes: the record's variance differs from
    # sum a^2 / 2 only through components closer than 1/T in frequency; the band and the
    # random frequencies in each bin keep sum a^2 / 2 within 1 % of hs^2 / 16.
    assert 4 * math.sqrt(sea.waves.variance) == pytest.approx(hs, rel=0.01)
    assert 4 * eta.std() == pytest.approx(hs, rel=0.03)
    # Welch spectrum with 0.0039 Hz resolution (256 s segments, 84 averages): the peak within
    # a resolution bin of 1 / tp = 0.1 Hz, and the band energies within 10 %.
    f, psd = signal.welch(eta, fs=4.0, nperseg=1024)
    assert f[np.argmax(psd)] == pytest.approx(1 / tp, abs=0.0041)
    for lo, hi in [(0.07, 0.09), (0.09, 0.11), (0.11, 0.15), (0.15, 0.25)]:
        band = (f >= lo) & (f < hi)
        measured = np.trapezoid(psd[band], f[band])
        w = 2 * math.pi * f[band]
        target = np.trapezoid(jonswap(w, hs, tp) * 2 * math.pi, f[band])
        assert measured == pytest.approx(target, rel=0.10), (lo, hi)


def test_short_crested_sea_spreads_its_energy_about_the_main_direction():
    sea = Sea.irregular(2.0, 8.0, depth=100.0, direction=0.5, spreading_exponent=4.0,
                        directions=15, count=50)
    w = sea.waves
    energy = w.amplitudes**2
    assert energy.sum() / 2 == pytest.approx(2.0**2 / 16, rel=0.01)
    mean = math.atan2(np.sum(energy * np.sin(w.directions)), np.sum(energy * np.cos(w.directions)))
    assert mean == pytest.approx(0.5, abs=1e-12)
    # The share of the energy within +-pi/4 of the main direction: the integral of cos^4.
    inside = np.abs(w.directions - 0.5) < math.pi / 4
    share, _ = integrate.quad(lambda th: float(spreading(th, 4.0)), -math.pi / 4, math.pi / 4)
    bins = np.linspace(-math.pi / 2, math.pi / 2, 16)
    assert energy[inside].sum() / energy.sum() == pytest.approx(share, abs=np.diff(bins)[0] / 2)


def test_components_from_a_measured_record_reproduce_it():
    rng = np.random.default_rng(3)
    t = 100.0 + np.arange(0.0, 600.0, 0.5)
    record = np.convolve(rng.normal(size=t.size), np.ones(12) / 12, mode="same") + 0.3
    sea = Sea(50.0, from_elevation(t, record))
    np.testing.assert_allclose(sea.elevation(t), record - record.mean(), atol=1e-10)


def test_fk_driven_particle_follows_the_closed_form_acceleration():
    """A neutrally buoyant line node without drag or added mass (m = rho V) obeys
    x'' = a_w(x, t), the water's local acceleration at its position: vinculo's trajectory
    against scipy's DOP853 on that ODE with the closed-form acceleration (rtol 1e-11)."""
    depth, height, period = 30.0, 1.0, 7.0
    sea = Sea.regular(height, period, depth, stretching="vertical")
    k, omega = sea.wave_numbers[0], 2 * math.pi / period
    d, length = 0.2, 1.0
    mass = RHO * math.pi * d * d / 4 * length
    x0 = np.array([0.0, 0.0, -4.0])

    def accel(x, t):
        _, _, a, _ = airy(height / 2, omega, k, depth, np.array([x[0]]), np.array([x[2]]), t)
        return a[0]

    def rhs(t, y):
        return np.concatenate([y[3:], accel(y[:3], t)])

    ref = integrate.solve_ivp(rhs, (0.0, 14.0), np.concatenate([x0, np.zeros(3)]),
                              method="DOP853", rtol=1e-11, atol=1e-12, dense_output=True)
    system = vinculo.System(gravity=(0.0, 0.0, -G))
    n = system.add_particle(mass, tuple(x0))
    system.add_line_hydrodynamics(n, diameter=d, length=length, density=RHO)
    system.set_water(sea.water())
    errors = []
    for dt in (0.02, 0.01):
        sol = vinculo.simulate(system, t_end=14.0, dt=dt)
        errors.append(np.abs(sol.particle(n) - ref.sol(sol.times)[:3].T).max())
    # Second order: the error shrinks fourfold when the step halves.
    assert errors[1] < 1e-4 and errors[0] / errors[1] == pytest.approx(4.0, rel=0.15), errors


def test_bad_sea_input_is_named():
    with pytest.raises(InvalidInputError, match="current velocity"):
        Current.uniform((0.0, 1.0))
    with pytest.raises(InvalidInputError, match="period"):
        Sea.regular(1.0, 0.0, 10.0)
    with pytest.raises(InvalidInputError, match="water depth"):
        Sea.regular(1.0, 5.0, -3.0).water()
    with pytest.raises(InvalidInputError, match="height #1 of the current table"):
        Sea(30.0, current=Current.table([-5.0, -10.0], [[0, 0, 0], [1, 0, 0]])).water()
    with pytest.raises(InvalidInputError, match="gamma"):
        Sea.irregular(2.0, 8.0, 50.0, gamma=12.0)
    with pytest.raises(InvalidInputError, match="equally spaced"):
        from_elevation([0.0, 1.0, 3.0, 4.0, 5.0], [0.0, 1.0, 0.0, 1.0, 0.0])
