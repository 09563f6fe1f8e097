"""Measures where index-3 generalised-alpha is stable on a plain pendulum.

A 1 m, 1 kg pendulum released from the horizontal (period T = 2.3607 s at g = 9.81: the
complete elliptic integral, T = 4 sqrt(L/g) K(sin^2(pi/4))) is integrated for 20 periods with
the index-3 generalised-alpha scheme at each rho_inf and step dt = T / steps_per_period. The
energy error is max |E(t) - E(0)| / (m g L) over the run (the scheme damps, so a stable run loses
a little energy; an unstable one grows without bound or stops). Prints the table of
docs/theory/time-rules.md.

Usage: .venv/bin/python tools/generalized_alpha_stability.py [--growth-check]
(--growth-check leaves the run's growth detection on and reports the runs it stopped.)
"""

from __future__ import annotations

import math
import sys

import numpy as np
from scipy.special import ellipk

import vinculo

G, L, M = 9.81, 1.0, 1.0
PERIOD = 4.0 * math.sqrt(L / G) * float(ellipk(0.5))
RHOS = (0.0, 0.3, 0.5, 0.6, 0.7, 0.8, 0.85, 0.9, 0.95, 1.0)
STEPS_PER_PERIOD = (20, 47, 100, 200, 1000)


def pendulum() -> vinculo.System:
    system = vinculo.System(gravity=(0.0, 0.0, -G))
    pivot = system.add_particle(mass=M, position=(0.0, 0.0, 0.0), fixed=True)
    bob = system.add_particle(mass=M, position=(L, 0.0, 0.0))
    system.add_distance(pivot, bob, length=L)
    return system


def energy_error(rho_inf: float, steps: int, periods: float = 20.0) -> tuple[float, str]:
    """max |E - E0| / (m g L) and how the run ended ('ok' or the exception's class)."""
    try:
        solution = vinculo.simulate(
            pendulum(), t_end=periods * PERIOD, dt=PERIOD / steps,
            scheme="generalized-alpha", rho_inf=rho_inf, save_every=1,
        )
        status = "ok"
    except vinculo.VinculoError as error:
        solution = getattr(error, "solution", None)
        status = type(error).__name__
    if solution is None or len(solution.times) < 2:
        return math.inf, status
    energy = solution.energy()
    with np.errstate(all="ignore"):
        drift = float(np.max(np.abs(energy - energy[0]))) / (M * G * L)
    return drift, status


def main() -> None:
    print("| rho_inf | " + " | ".join(f"T/dt = {s}" for s in STEPS_PER_PERIOD) + " |")
    print("|---|" + "---|" * len(STEPS_PER_PERIOD))
    for rho in RHOS:
        cells = []
        for steps in STEPS_PER_PERIOD:
            drift, status = energy_error(rho, steps)
            cell = f"{drift:.1e}" if math.isfinite(drift) else "inf"
            cells.append(cell if status == "ok" else f"{cell} ({status})")
        print(f"| {rho} | " + " | ".join(cells) + " |")
        sys.stdout.flush()


if __name__ == "__main__":
    main()
