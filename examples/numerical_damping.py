"""Numerical damping of the time rules, measured on an undamped oscillator against closed forms.

A mass m on a linear spring of stiffness k (no gravity, no constraint) oscillates at
omega = sqrt(k/m) forever. A time rule with step h multiplies the oscillation's amplitude by a
factor |R| per step that depends only on Omega = omega h. For the generalised trapezoidal rule
(the theta-method in (q, v)) the closed form is

    |R(i Omega)| = sqrt((1 + (1 - alpha)^2 Omega^2) / (1 + alpha^2 Omega^2)),

1 for alpha = 1/2 and (1 - alpha)/alpha as Omega grows. Generalised-alpha keeps |R| near 1 for
small Omega and tends to rho_inf for large Omega. The script measures |R| from the energy, which
a step of the theta-method multiplies by exactly |R|^2, and from the energy decay of
generalised-alpha once its dominant root has taken over.

    python examples/numerical_damping.py [--plot numerical_damping.png]
"""

import argparse

import numpy as np

import vinculo

# omega = 1 rad/s, so Omega = h. The spring is long (1 km) and the motion small (0.1 m) along it,
# so that even the first guess of a very long step stays on the anchor's side: the spring's force
# is then exactly linear in the displacement.
MASS, STIFFNESS, REST = 1.0, 1.0, 1000.0


def measured_factor(h: float, steps: int, skip: int = 0, **scheme) -> float:
    """|R| per step of ``scheme`` at Omega = h, from the energy ratio over steps skip..steps."""
    system = vinculo.System(gravity=(0.0, 0.0, 0.0))
    anchor = system.add_particle(mass=1.0, position=(0.0, 0.0, 0.0), fixed=True)
    body = system.add_particle(mass=MASS, position=(REST + 0.1, 0.0, 0.0))
    system.add_spring_damper(anchor, body, stiffness=STIFFNESS, rest_length=REST)
    solution = vinculo.simulate(system, t_end=steps * h, dt=h, tolerance=1e-12, **scheme)
    if solution.num_steps != steps:  # a halved step would change Omega
        raise RuntimeError(f"{solution.num_steps} steps instead of {steps} at h = {h}")
    energy = solution.energy()  # kinetic + spring potential (no gravity)
    # Stop where the energy reaches round-off (a strongly damped motion dies within a few steps),
    # and fit log E = c + 2 n log|R| over the steps kept.
    end = int(np.flatnonzero(energy > 1e-12 * energy[0])[-1])
    start = min(skip, end // 2)
    if end - start < 2:
        return 0.0
    n = np.arange(start, end + 1)
    slope = np.polyfit(n, np.log(energy[start : end + 1]), 1)[0]
    return float(np.exp(slope / 2))


def trapezoidal_factor(alpha: float, omega_h: np.ndarray) -> np.ndarray:
    """The closed form |R(i Omega)| of the generalised trapezoidal rule."""
    return np.sqrt((1 + (1 - alpha) ** 2 * omega_h**2) / (1 + alpha**2 * omega_h**2))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--plot", metavar="FILE", help="write a PNG figure to FILE")
    args = parser.parse_args()

    omega_h = np.geomspace(0.05, 100.0, 13)  # beyond ~100 the motion dies below round-off at once
    trapezoidal = {alpha: [measured_factor(h, 4, alpha=alpha) for h in omega_h]
                   for alpha in (0.5, 0.6, 0.75, 1.0)}
    worst = max(np.max(np.abs(np.array(measured) - trapezoidal_factor(alpha, omega_h)))
                for alpha, measured in trapezoidal.items())
    print(f"generalised trapezoidal rule: largest gap to the closed form {worst:.1e}")
    # Generalised-alpha's amplification matrix is 3 x 3 (it carries accelerations): its energy
    # settles on the dominant root after a few steps, so the first 20 are skipped.
    alpha_runs = {rho: [measured_factor(h, 80, 20, scheme="generalized-alpha", rho_inf=rho)
                        for h in omega_h] for rho in (1.0, 0.9, 0.5, 0.0)}
    for rho, measured in alpha_runs.items():
        print(f"generalised-alpha rho_inf = {rho}: |R| = {measured[0]:.6f} at Omega = "
              f"{omega_h[0]:g}, {measured[-1]:.4f} at Omega = {omega_h[-1]:g}")

    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, axes = plt.subplots(1, 2, figsize=(11, 3.8), layout="constrained", sharey=True)
        fine = np.geomspace(omega_h[0], omega_h[-1], 200)
        for alpha, measured in trapezoidal.items():
            line, = axes[0].semilogx(fine, trapezoidal_factor(alpha, fine), lw=1)
            axes[0].semilogx(omega_h, measured, "o", ms=4, color=line.get_color(),
                             label=f"alpha = {alpha}")
        axes[0].set(xlabel="omega h", ylabel="|R| per step",
                    title="generalised trapezoidal (lines: closed form)")
        axes[0].legend(fontsize=8)
        for rho, measured in alpha_runs.items():
            line, = axes[1].semilogx(omega_h, measured, "o-", ms=4, label=f"rho_inf = {rho}")
            axes[1].axhline(rho, color=line.get_color(), ls=":", lw=1)
        axes[1].set(xlabel="omega h", title="generalised-alpha (dotted: rho_inf)")
        axes[1].legend(fontsize=8)
        fig.savefig(args.plot, dpi=110)
        print(f"plot: {args.plot}")


if __name__ == "__main__":
    main()
