"""Adaptive steps on a pendulum that idles, then is kicked: step sizes, and error against rtol.

A 1 m pendulum hangs at rest for 1.5 s; then its pivot moves 0.3 m sideways in 0.3 s (a smooth
C2 step, ``vinculo.sine`` with a ramp) and the bob swings until t = 2.5 s. While it idles no step
is hard; the kick and the swing need small ones: where step-size control pays. The reference is
the pendulum's ODE in its angle, theta'' = -(g/L) sin(theta) - (x_p''/L) cos(theta), integrated
by scipy (DOP853, rtol 1e-12). The error of a run is proportional to the tolerance (the steps are
controlled per unit step), and smaller than that of fixed steps of the same count.

    python examples/adaptive_steps.py [--plot adaptive_steps.png]
"""

import argparse

import numpy as np
from scipy.integrate import solve_ivp

import vinculo

G, LENGTH, T_END, H_MAX = 9.81, 1.0, 2.5, 0.02
T_EVAL = np.arange(0.0, T_END, 0.00731)  # off any step grid: dense output


def pivot_law() -> vinculo.Law:
    """x_p(t): 0 until 1.5 s, then a C2 quintic step to 0.3 m over 0.3 s."""
    return vinculo.sine(amplitude=0.3, frequency=1e-3, phase=np.pi / 2, ramp_time=0.3,
                        t_start=1.5)


def reference(times: np.ndarray) -> np.ndarray:
    """The bob's (x, z) at ``times`` from the angle ODE (theta from the downward vertical)."""
    law = pivot_law()

    def rhs(t, y):
        acceleration = law.derivatives(t)[2]
        return [y[1], -(G * np.sin(y[0]) + acceleration * np.cos(y[0])) / LENGTH]

    theta = solve_ivp(rhs, (0.0, T_END), [0.0, 0.0], method="DOP853", rtol=1e-12, atol=1e-12,
                      t_eval=times, max_step=0.01).y[0]
    pivot = np.array([law(t) for t in times])
    return np.column_stack([pivot + LENGTH * np.sin(theta), -LENGTH * np.cos(theta)])


def run(**options) -> tuple[vinculo.Solution, vinculo.ParticleId]:
    """The kicked pendulum, simulated with ``options``."""
    system = vinculo.System(gravity=(0.0, 0.0, -G))
    bob = system.add_particle(mass=1.0, position=(0.0, 0.0, -LENGTH))
    system.add_distance_to_point(bob, (pivot_law(), 0.0, 0.0), length=LENGTH)
    return vinculo.simulate(system, T_END, tolerance=1e-12, **options), bob


def largest_error(solution: vinculo.Solution, bob: vinculo.ParticleId) -> float:
    """Largest distance between the bob and the reference over the stored times (m)."""
    exact = reference(solution.times)
    q = solution.particle(bob)
    return float(np.max(np.hypot(q[:, 0] - exact[:, 0], q[:, 2] - exact[:, 1])))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--plot", metavar="FILE", help="write a PNG figure to FILE")
    args = parser.parse_args()

    tolerances = [1e-4, 1e-5, 1e-6]
    rows = []
    for rtol in tolerances:
        adaptive, bob = run(dt=1e-3, adaptive=True, rtol=rtol, atol=rtol, h_max=H_MAX,
                            t_eval=T_EVAL)
        steps = len(adaptive.accepted_step_sizes)
        fixed, fixed_bob = run(dt=T_END / steps)
        rows.append((rtol, steps, adaptive.steps_rejected, largest_error(adaptive, bob),
                     largest_error(fixed, fixed_bob)))
        if rtol == tolerances[-1]:
            shown = adaptive
    for rtol, steps, rejected, error, fixed_error in rows:
        print(f"rtol {rtol:.0e}: {steps} steps ({rejected} rejected), largest error "
              f"{error:.1e} m = {error / rtol:.1f} rtol; fixed steps of the same count: "
              f"{fixed_error:.1e} m, {fixed_error / error:.1f} times larger")

    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, axes = plt.subplots(1, 2, figsize=(11, 3.8), layout="constrained")
        h = shown.accepted_step_sizes
        ends = np.cumsum(h)
        axes[0].semilogy(ends, h, ".", ms=3, label="accepted step (s)")
        twin = axes[0].twinx()
        law = pivot_law()
        twin.plot(T_EVAL, [law(t) for t in T_EVAL], "C1", lw=1)
        twin.set_ylabel("pivot x (m)", color="C1")
        axes[0].set(xlabel="t (s)", ylabel="step size (s)",
                    title=f"steps at rtol = {tolerances[-1]:.0e} (trapezoidal)")
        table = np.array(rows)
        axes[1].loglog(table[:, 0], table[:, 3], "o-", label="adaptive")
        axes[1].loglog(table[:, 0], table[:, 4], "s--", label="fixed, same step count")
        axes[1].loglog(table[:, 0], table[:, 0], "k:", lw=1, label="error = rtol")
        axes[1].set(xlabel="rtol = atol (m)", ylabel="largest position error (m)",
                    title="error against the tolerance")
        axes[1].legend(fontsize=8)
        fig.savefig(args.plot, dpi=110)
        print(f"plot: {args.plot}")


if __name__ == "__main__":
    main()
