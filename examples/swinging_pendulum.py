"""A pendulum built step by step: period, rod tension and energy against closed forms.

A bob of mass m = 1 kg on a massless rod of L = 1 m, released at rest from the horizontal under
g = 9.81 m/s^2. Three exact results to compare with: the period 4 sqrt(L/g) K(sin 45 deg)
(K the complete elliptic integral of the first kind, from scipy), the rod tension
T = m g (3 cos(theta) - 2 cos(theta_0)) = 3 m g cos(theta) for theta_0 = 90 deg (theta from
the downward vertical), and the constant energy.

    python examples/swinging_pendulum.py [--dt 1e-3] [--plot swinging_pendulum.png]
"""

import argparse

import numpy as np
from scipy.special import ellipk

import vinculo

G, LENGTH, MASS = 9.81, 1.0, 1.0


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--dt", type=float, default=1e-3, help="step size in s (default 1e-3)")
    parser.add_argument("--plot", metavar="FILE", help="write a PNG figure to FILE")
    args = parser.parse_args()

    # 1. The model: a fixed pivot, a free bob, a distance constraint between them.
    system = vinculo.System(gravity=(0.0, 0.0, -G))
    pivot = system.add_particle(mass=1.0, position=(0.0, 0.0, 0.0), fixed=True)
    bob = system.add_particle(mass=MASS, position=(LENGTH, 0.0, 0.0))
    rod = system.add_distance(pivot, bob, length=LENGTH)

    # 2. The run: the trapezoidal rule (alpha = 1/2) conserves energy.
    exact_period = 4.0 * np.sqrt(LENGTH / G) * ellipk(np.sin(np.pi / 4) ** 2)  # m = k^2
    solution = vinculo.simulate(system, t_end=2.0 * exact_period, dt=args.dt)
    print(solution.summary())

    # 3. The period: x changes sign from - to + once per period (on the way back from x = -L),
    # so the time between two such crossings, interpolated linearly within a step, is a period.
    t = solution.times
    x, _, z = solution.particle(bob).T
    up = np.flatnonzero((x[:-1] < 0.0) & (x[1:] >= 0.0))
    crossings = t[up] - x[up] * (t[up + 1] - t[up]) / (x[up + 1] - x[up])
    period = crossings[1] - crossings[0]
    print(f"period: {period:.8f} s, exact {exact_period:.8f} s, "
          f"relative error {abs(period / exact_period - 1):.1e}")

    # 4. The tension: the multiplier of a step acts at its midpoint (alpha = 1/2), where the
    # bob's height is the mean of the step's ends; T = 3 m g cos(theta) = -3 m g z / L.
    tension = solution.distance_tension(rod, LENGTH)[1:]
    z_mid = 0.5 * (z[1:] + z[:-1])
    exact_tension = -3.0 * MASS * G * z_mid / LENGTH
    tension_error = np.max(np.abs(tension - exact_tension)) / (3.0 * MASS * G)
    print(f"largest tension error: {tension_error:.1e} of 3 m g")

    energy = solution.energy()
    drift = np.max(np.abs(energy - energy[0])) / (MASS * G * LENGTH)
    print(f"largest energy change: {drift:.1e} of m g L")

    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, axes = plt.subplots(1, 3, figsize=(12, 3.6), layout="constrained")
        axes[0].plot(x, z, lw=1)
        axes[0].plot([0.0], [0.0], "ko")
        axes[0].set(xlabel="x (m)", ylabel="z (m)", title="path of the bob", aspect="equal")
        axes[1].plot(t[1:], tension, label="vinculo: 2 lambda L")
        axes[1].plot(t[1:], exact_tension, "--", label="3 m g cos(theta)")
        axes[1].set(xlabel="t (s)", ylabel="tension (N)", title="rod tension")
        axes[1].legend(loc="upper right", fontsize=8)
        axes[2].plot(t, (energy - energy[0]) / (MASS * G * LENGTH))
        axes[2].set(xlabel="t (s)", ylabel="(E - E0) / (m g L)", title="energy change")
        fig.savefig(args.plot, dpi=110)
        print(f"plot: {args.plot}")


if __name__ == "__main__":
    main()
