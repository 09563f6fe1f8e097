"""Order of accuracy of every time rule, on a pendulum against scipy's solution of its ODE.

A 1 m pendulum released from the horizontal, followed for 1 s. The reference is the pendulum's
own ODE, theta'' = -(g/L) sin(theta), integrated by scipy (DOP853, rtol 1e-12): an independent
solution of the same physics. The error of the bob's position at t = 1 s shrinks as dt^p; the
slope of the log-log line is the observed order p: 2 for the trapezoidal rule (alpha = 1/2) and
for generalised-alpha, 1 for alpha > 1/2 and backward Euler, on both formulations.

    python examples/convergence_order.py [--plot convergence_order.png]
"""

import argparse

import numpy as np
from scipy.integrate import solve_ivp

import vinculo

G, LENGTH, T_END = 9.81, 1.0, 1.0
SCHEMES = {
    "trapezoidal (alpha = 0.5)": {"alpha": 0.5},
    "trapezoidal (alpha = 0.75)": {"alpha": 0.75},
    "backward Euler": {"scheme": "backward-euler"},
    "generalised-alpha (rho_inf = 0.9)": {"scheme": "generalized-alpha", "rho_inf": 0.9},
    "generalised-alpha (rho_inf = 0.5)": {"scheme": "generalized-alpha", "rho_inf": 0.5},
    "GGL, trapezoidal (alpha = 0.5)": {"alpha": 0.5, "formulation": "ggl"},
}


def reference_position() -> np.ndarray:
    """The bob's (x, z) at T_END from the pendulum ODE (theta from the downward vertical)."""
    def rhs(t, y):
        return [y[1], -G / LENGTH * np.sin(y[0])]

    theta = solve_ivp(rhs, (0.0, T_END), [np.pi / 2, 0.0], method="DOP853", rtol=1e-12,
                      atol=1e-12).y[0, -1]
    return LENGTH * np.array([np.sin(theta), -np.cos(theta)])


def position_error(dt: float, reference: np.ndarray, **scheme) -> float:
    """|q(T_END) - reference| of a vinculo run with step dt."""
    system = vinculo.System(gravity=(0.0, 0.0, -G))
    pivot = system.add_particle(mass=1.0, position=(0.0, 0.0, 0.0), fixed=True)
    bob = system.add_particle(mass=1.0, position=(LENGTH, 0.0, 0.0))
    system.add_distance(pivot, bob, length=LENGTH)
    solution = vinculo.simulate(system, t_end=T_END, dt=dt, tolerance=1e-13, **scheme)
    x, _, z = solution.particle(bob)[-1]
    return float(np.hypot(x - reference[0], z - reference[1]))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--plot", metavar="FILE", help="write a PNG figure to FILE")
    args = parser.parse_args()

    reference = reference_position()
    steps = 0.02 / 2.0 ** np.arange(5)
    errors = {name: np.array([position_error(dt, reference, **kw) for dt in steps])
              for name, kw in SCHEMES.items()}
    for name, error in errors.items():
        order = np.polyfit(np.log(steps), np.log(error), 1)[0]
        print(f"{name}: observed order {order:.2f} (error {error[-1]:.1e} m at dt = "
              f"{steps[-1]:g} s)")

    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(7, 4.5), layout="constrained")
        for name, error in errors.items():
            ax.loglog(steps, error, "o-", ms=4, label=name)
        ax.loglog(steps, 0.5 * steps, "k:", lw=1, label="slope 1")
        ax.loglog(steps, 20 * steps**2, "k--", lw=1, label="slope 2")
        ax.set(xlabel="dt (s)", ylabel="position error at t = 1 s (m)",
               title="observed order against scipy's pendulum ODE")
        ax.legend(fontsize=7)
        fig.savefig(args.plot, dpi=110)
        print(f"plot: {args.plot}")


if __name__ == "__main__":
    main()
