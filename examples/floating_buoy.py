"""A vertical cylinder floating freely in regular waves: its heave RAO against the closed form.

The cylinder (radius 1 m, draft 2 m, Ca = 0.5) floats in deep water; vinculo's floating-body
loads (docs/theory/ocean.md) integrate the hydrostatic pressure of the moving surface and the
Froude-Krylov and added-mass share of the water's acceleration over the wetted volume. For
that model the heave response amplitude operator is, with k = omega^2 / g and A = pi R^2,

    |Z / a| = |e^{-kT} - Ca (1 - e^{-kT})| / |1 - (m + m_a) omega^2 / (rho g A)|,

resonant at the heave natural period 2 pi sqrt((m + m_a) / (rho g A)) = 3.47 s and with a zero
of the excitation where the added-mass share cancels the Froude-Krylov force. The example runs
the regular-wave sweep of :func:`vinculo.ocean.moored_buoy.rao` (each period from rest, the
waves ramped over two periods) and prints the largest relative difference from the closed form
away from resonance. ``--plot FILE`` draws both.

Run:  .venv/bin/python examples/floating_buoy.py [--plot floating_buoy.png]
"""

import argparse
import math

import numpy as np

from vinculo.ocean import Sea, cylinder
from vinculo.ocean import moored_buoy as mb

RHO, G = 1025.0, 9.80665
RADIUS, DRAFT, CA = 1.0, 2.0, 0.5


def closed_form(period: np.ndarray, mass: float) -> np.ndarray:
    omega = 2 * np.pi / period
    decay = np.exp(-omega**2 / G * DRAFT)
    area = math.pi * RADIUS**2
    return np.abs(decay - CA * (1 - decay)) / np.abs(
        1 - (1 + CA) * mass * omega**2 / (RHO * G * area))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--plot", metavar="FILE", help="draw the RAO into FILE")
    args = parser.parse_args()
    mass = RHO * math.pi * RADIUS**2 * DRAFT
    # Ballasted: the centre of gravity 0.5 m above the keel, so that pitch (natural period
    # 2.6 s, GM = 0.625 m) stays clear of the heave response measured.
    case = mb.MooredBuoyCase(
        mass=mass, centre=(0.0, 0.0, -DRAFT + 0.5),
        inertia=np.diag([mass * RADIUS**2 / 3] * 2 + [mass * RADIUS**2 / 2]),
        hull=cylinder(RADIUS, -0.5, 2.5), sea=Sea(depth=math.inf), ca=CA)
    periods = np.array([2.0, 2.5, 3.0, 4.5, 5.0, 6.0, 7.0, 8.0, 10.0, 12.0, 15.0])
    table = mb.rao(case, periods=periods, height=0.1, cycles=10)
    heave = table.amplitude[:, 2]
    expected = closed_form(periods, mass)
    natural = 2 * math.pi * math.sqrt((1 + CA) * mass / (RHO * G * math.pi * RADIUS**2))
    # Away from the resonance (where the undamped response has no finite amplitude) and from
    # the zero of the excitation (where the relative difference of tiny amplitudes means little).
    away = (np.abs(periods - natural) > 1.0) & (expected > 0.3)
    print(f"heave natural period: {natural:.3f} s")
    for p, h, e in zip(periods, heave, expected, strict=True):
        print(f"  T = {p:5.1f} s  heave RAO {h:.4f}  closed form {e:.4f}")
    worst = np.max(np.abs(heave[away] / expected[away] - 1))
    print(f"largest relative difference away from resonance: {worst:.2e}")
    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fine = np.linspace(1.6, 16.0, 400)
        fig, ax = plt.subplots(figsize=(7, 4))
        ax.plot(fine, closed_form(fine, mass), color="0.5", label="closed form")
        ax.plot(periods, heave, "o", color="tab:blue", label="vinculo, regular waves")
        ax.axvline(natural, color="0.8", ls="--", lw=1)
        ax.set_ylim(0, 4)
        ax.set_xlabel("wave period (s)")
        ax.set_ylabel("heave RAO (m/m)")
        ax.set_title("Floating cylinder, R = 1 m, draft 2 m, Ca = 0.5")
        ax.legend()
        fig.tight_layout()
        fig.savefig(args.plot, dpi=110)


if __name__ == "__main__":
    main()
