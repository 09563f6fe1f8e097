"""Consistent initial conditions: an inconsistent start is refused, then projected.

A bob tied to a fixed point by a 1 m link is placed 4 cm too far out, moving partly along the
link. ``vinculo.simulate`` refuses the start with ``InconsistentInitialStateError``, naming the
constraint; ``System.project_initial_state`` moves the state onto Phi = 0 and
Phi_q v + Phi_t = 0 with the least mass-weighted change. For one particle that change has a
closed form: the position moves radially onto the sphere of radius L, q* = p + L (q - p)/|q - p|,
and the velocity loses its radial part, v* = v - (v . e) e with e the unit radial direction.

    python examples/consistent_start.py [--plot consistent_start.png]
"""

import argparse

import numpy as np

import vinculo

G, LENGTH = 9.81, 1.0
START = np.array([0.6, 0.0, -0.85])       # |START| = 1.0404 m: off the 1 m circle
VELOCITY = np.array([0.5, 0.0, 0.4])      # partly along the link


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--plot", metavar="FILE", help="write a PNG figure to FILE")
    args = parser.parse_args()

    system = vinculo.System(gravity=(0.0, 0.0, -G))
    bob = system.add_particle(mass=1.0, position=tuple(START), velocity=tuple(VELOCITY))
    system.add_distance_to_point(bob, (0.0, 0.0, 0.0), length=LENGTH)
    try:
        vinculo.simulate(system, t_end=1.0, dt=1e-3)
    except vinculo.InconsistentInitialStateError as error:
        print(f"refused: {error}")

    change = system.project_initial_state()
    print(f"projection: {change}")
    q, v = system.initial_positions()[0], system.initial_velocities()[0]
    e = START / np.linalg.norm(START)
    print(f"position gap to the radial projection: {np.max(np.abs(q - LENGTH * e)):.1e} m")
    print(f"velocity gap to the tangential part: "
          f"{np.max(np.abs(v - (VELOCITY - VELOCITY @ e * e))):.1e} m/s")

    solution = vinculo.simulate(system, t_end=2.0, dt=1e-3)
    print(f"then simulated: {solution.num_steps} steps, largest constraint residual "
          f"{np.max(solution.constraint_residual):.1e} m")

    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(5.5, 4.5), layout="constrained")
        angle = np.linspace(0.0, 2.0 * np.pi, 200)
        ax.plot(LENGTH * np.cos(angle), LENGTH * np.sin(angle), color="0.7", lw=1,
                label="|q| = L")
        path = solution.particle(bob)
        ax.plot(path[:, 0], path[:, 2], lw=1, label="path after the projection")
        ax.plot(START[0], START[2], "rx", label="given start")
        ax.plot(q[0], q[2], "ko", ms=4, label="projected start")
        ax.annotate("", xy=(q[0] + 0.3 * v[0], q[2] + 0.3 * v[2]), xytext=(q[0], q[2]),
                    arrowprops={"arrowstyle": "->"})
        ax.set(xlabel="x (m)", ylabel="z (m)", aspect="equal", title="projected initial state")
        ax.legend(fontsize=7, loc="upper left")
        fig.savefig(args.plot, dpi=110)
        print(f"plot: {args.plot}")


if __name__ == "__main__":
    main()
