"""Measures where index-3 generalised-alpha is stable on a plain pendulum.

A 1 m, 1 kg pendulum released from the horizontal (period T = 2.3607 s at g = 9.81: the
complete elliptic integral, T = 4 sqrt(L/g) K(sin^2(pi/4))) is integrated for 20 periods with
the index-3 generalised-alpha scheme at each rho_inf and step dt = T / steps_per_period. The
energy error is max |E(t) - E(0)| / (m g L) over the run (the scheme damps, so a stable run loses
a little energy; an unstable one grows until the run's growth guard stops it with an
InstabilityError, once the energy exceeds its initial value by m g L). Prints the table of
docs/theory/time-rules.md: the energy error of each stable run, and the time at which each
unstable one was stopped.

Usage: .venv/bin/python tools/generalized_alpha_stability.py
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
STEPS_PER_PERIOD = (10, 20, 30, 47, 70, 100, 200, 1000)


def pendulum() -> vinculo.System:
    system = vinculo.System(gravity=(0.0, 0.0, -G))
    pivot = system.add_particle(mass=M, position=(0.0, 0.0, 0.0), fixed=True)
    bob = system.add_particle(mass=M, position=(L, 0.0, 0.0))
    system.add_distance(pivot, bob, length=L)
    return system


def energy_error(
    rho_inf: float, steps: int, periods: float = 20.0, formulation: str = "index-3"
) -> tuple[float, str]:
    """max |E - E0| / (m g L) and how the run ended ('ok', or the exception's class and the
    time it was raised at)."""
    try:
        solution = vinculo.simulate(
            pendulum(), t_end=periods * PERIOD, dt=PERIOD / steps,
            scheme="generalized-alpha", rho_inf=rho_inf, formulation=formulation,
        )
        status = "ok"
    except vinculo.VinculoError as error:
        solution = getattr(error, "solution", None)
        status = f"{type(error).__name__} at t = {getattr(error, 'time', math.nan):.1f} s"
    if solution is None or len(solution.times) < 2:
        return math.inf, status
    energy = solution.energy()
    with np.errstate(all="ignore"):
        drift = float(np.max(np.abs(energy - energy[0]))) / (M * G * L)
    return drift, status


def main() -> None:
    print("| rho_inf | " + " | ".join(f"T/dt = {s}" for s in STEPS_PER_PERIOD) + " |")
    print("|---|" + "---|" * len(STEPS_PER_PERIOD))
    rows = [(rho, "index-3") for rho in RHOS] + [(0.9, "ggl"), (1.0, "ggl")]
    for rho, formulation in rows:
        cells = []
        for steps in STEPS_PER_PERIOD:
            drift, status = energy_error(rho, steps, formulation=formulation)
            if status == "ok":
                cells.append(f"{drift:.1e}")
            else:
                cells.append("**unstable** " + status.split(" at ")[-1].replace(" s", "s"))
        label = f"{rho}" if formulation == "index-3" else f"{rho} (GGL)"
        print(f"| {label} | " + " | ".join(cells) + " |")
        sys.stdout.flush()


if __name__ == "__main__":
    main()
