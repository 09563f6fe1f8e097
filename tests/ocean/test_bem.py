"""The BEM option: a floating vertical cylinder's heave in regular waves, with Capytaine's added
mass, radiation damping (as a fitted state-space memory) and excitation, against Capytaine's own
frequency-domain response X / (C - (m + A) w^2 - i w B) at small amplitude."""

from __future__ import annotations

import math

import numpy as np
import pytest

import vinculo
from vinculo.ocean import Sea, cylinder
from vinculo.ocean.moored_buoy import _harmonic

bem = pytest.importorskip("vinculo.ocean.bem")
pytest.importorskip("capytaine")

RHO, G = 1025.0, 9.80665
RADIUS, DRAFT = 1.0, 2.0
TESTED = (1.0, 1.4, 2.6)  # rad/s: below, near (1.9) and above the heave resonance


@pytest.fixture(scope="module")
def coefficients():
    omegas = np.unique(np.concatenate([np.linspace(0.05, 6.0, 60), TESTED]))
    return bem.heave_coefficients(RADIUS, DRAFT, omegas, density=RHO, g=G)


def test_fitted_memory_reproduces_the_added_mass_and_damping(coefficients):
    # The state-space model's A(w) = A_inf + Im K / w and B(w) = Re K against Capytaine's
    # samples (order 6; the samples reach 6 rad/s, where the kernel has died out).
    model = bem.fit_radiation(coefficients, order=6)
    assert np.all(np.linalg.eigvals(model.a).real < 0)
    a, b = model.coefficients(coefficients.omegas)
    scale = np.abs(coefficients.damping).max()
    assert np.abs(b - coefficients.damping).max() < 0.06 * scale
    # The added mass away from w = 0 (where Im K / w divides a small error by a small w).
    away = coefficients.omegas > 0.5
    assert np.abs(a - coefficients.added_mass)[away].max() < 0.05 * model.added_mass_infinite
    assert model.fit_error < 0.06


def test_heave_in_regular_waves_matches_capytaines_response(coefficients):
    model = bem.fit_radiation(coefficients, order=6)
    mass = RHO * math.pi * RADIUS**2 * DRAFT
    reference = bem.response(coefficients, mass)
    amplitude = 0.05
    for omega in TESTED:
        period = 2 * math.pi / omega
        system = vinculo.System(gravity=(0.0, 0.0, -G))
        body = system.add_rigid_body(
            mass, (0.0, 0.0, -DRAFT / 2),
            np.diag([mass * (3 * RADIUS**2 + 16) / 12] * 2 + [mass * RADIUS**2 / 2]))
        # The hydrostatics from the wetted volume in still water; A_inf on the body; the
        # memory; the excitation (Froude-Krylov and diffraction) as an applied force.
        system.add_floating_body(body, cylinder(RADIUS, -DRAFT / 2, 3 - DRAFT / 2), ca=0.0,
                                 added_mass=coefficients.added_mass_infinite, density=RHO)
        system.set_water(Sea(depth=math.inf, density=RHO, g=G).water())
        bem.add_heave_radiation(system, body, model)
        t_end = 30 * period
        law = bem.excitation_law(coefficients, omega, amplitude, t_end, ramp=10 * period,
                                 dt=period / 100)
        system.add_force(body["centre"], (0.0, 0.0, law))
        dt = period / 60
        sol = vinculo.simulate(system, t_end=t_end, dt=dt,
                               t_eval=np.arange(0.0, t_end - dt / 2, dt))
        heave = sol.particle(body["centre"])[:, 2] + DRAFT / 2
        keep = sol.times >= 20 * period
        measured = abs(_harmonic(sol.times[keep], heave[keep], omega)) / amplitude
        expected = abs(reference[np.argmin(np.abs(coefficients.omegas - omega))])
        # Measured: 1.3e-3, 1.8e-3, 2.8e-3 (the memory's fit, the steps, the ramp's transient).
        assert measured == pytest.approx(expected, rel=0.01), (omega, measured, expected)
