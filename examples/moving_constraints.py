"""Constraints that move by prescribed laws, and the forces they need.

Three models, each with a closed form for its constraint force:

- an elevator: a particle resting on a horizontal plane whose point rises as z0(t) = a t^2 / 2
  (``vinculo.polynomial``); the plane pushes with the normal force m (g + a);
- a prescribed coordinate: a particle whose x follows A sin(2 pi f t) (``vinculo.sine``), free in
  y and z; the multiplier is the force that moves it, m x'' = -m A (2 pi f)^2 sin(2 pi f t);
- a pendulum whose pivot is shaken horizontally (a distance to a moving point, with a smooth
  ``ramp_time`` start): no closed form; its path is drawn.

    python examples/moving_constraints.py [--plot moving_constraints.png]
"""

import argparse

import numpy as np

import vinculo

G, MASS = 9.81, 2.0


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--plot", metavar="FILE", help="write a PNG figure to FILE")
    args = parser.parse_args()

    # The elevator: Phi = n . (q - p0(t)) with n = +z and p0 = (0, 0, a t^2 / 2).
    accel = 3.0
    elevator = vinculo.System(gravity=(0.0, 0.0, -G))
    box = elevator.add_particle(mass=MASS, position=(0.0, 0.0, 0.0))
    floor = elevator.add_plane(box, normal=(0.0, 0.0, 1.0),
                               point=(0.0, 0.0, vinculo.polynomial([0.0, 0.0, accel / 2])))
    ride = vinculo.simulate(elevator, t_end=2.0, dt=1e-2)
    normal = ride.multiplier(floor)
    print(f"elevator: normal force {normal[-1]:.10f} N, m (g + a) = {MASS * (G + accel):.10f} N")
    error = np.max(np.abs(normal - MASS * (G + accel)))
    print(f"elevator: largest normal force error {error:.1e} N")

    # The prescribed coordinate: q_x = A sin(2 pi f t); the multiplier is the force along +x.
    amplitude, frequency = 0.05, 1.5
    omega = 2.0 * np.pi * frequency
    shaker = vinculo.System(gravity=(0.0, 0.0, -G))
    mass = shaker.add_particle(mass=MASS, position=(0.0, 0.0, 0.0),
                               velocity=(amplitude * omega, 0.0, 0.0))
    drive = shaker.add_fixed_coordinate(mass, "x", vinculo.sine(amplitude, frequency))
    shaken = vinculo.simulate(shaker, t_end=2.0, dt=1e-3)
    t_mid = 0.5 * (shaken.times[1:] + shaken.times[:-1])  # trapezoidal: force at mid-step
    exact = -MASS * amplitude * omega**2 * np.sin(omega * t_mid)
    force = shaken.multiplier(drive)[1:]
    drive_error = np.max(np.abs(force - exact)) / (MASS * amplitude * omega**2)
    print(f"prescribed coordinate, index-3: largest force error {drive_error:.1e} of m A omega^2")
    # The index-3 multipliers come from second differences of positions and ring a little; the
    # stabilised index-2 (GGL) formulation also enforces the velocity constraint.
    stabilised = vinculo.simulate(shaker, t_end=2.0, dt=1e-3, formulation="ggl")
    ggl_force = stabilised.multiplier(drive)[1:]
    ggl_error = np.max(np.abs(ggl_force - exact)) / (MASS * amplitude * omega**2)
    print(f"prescribed coordinate, GGL: largest force error {ggl_error:.1e} of m A omega^2")

    # The shaken pendulum: pivot at (X(t), 0, 0), X = 2 cm sin(2 pi 0.6 t), ramped over 2 s.
    pendulum = vinculo.System(gravity=(0.0, 0.0, -G))
    bob = pendulum.add_particle(mass=1.0, position=(0.0, 0.0, -0.4))
    pivot_x = vinculo.sine(amplitude=0.02, frequency=0.6, ramp_time=2.0)
    string = pendulum.add_distance_to_point(bob, (pivot_x, 0.0, 0.0), length=0.4)
    swing = vinculo.simulate(pendulum, t_end=10.0, dt=2e-3)
    print(f"shaken pendulum: largest swing {np.max(np.abs(swing.particle(bob)[:, 0])):.4f} m, "
          f"tension between {np.min(swing.distance_tension(string, 0.4)):.3f} and "
          f"{np.max(swing.distance_tension(string, 0.4)):.3f} N")

    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, axes = plt.subplots(1, 3, figsize=(12, 3.6), layout="constrained")
        axes[0].plot(ride.times, normal, label="vinculo: lambda")
        axes[0].axhline(MASS * (G + accel), color="k", ls="--", label="m (g + a)")
        axes[0].set(xlabel="t (s)", ylabel="normal force (N)", title="elevator floor",
                    ylim=(0, 1.5 * MASS * (G + accel)))
        axes[0].legend(fontsize=8)
        scale = MASS * amplitude * omega**2
        axes[1].plot(t_mid, np.abs(force - exact) / scale, lw=0.8, label="index-3")
        axes[1].plot(t_mid, np.abs(ggl_force - exact) / scale, lw=0.8, label="GGL")
        axes[1].set(xlabel="t (s)", ylabel="|lambda - m x''| / (m A omega^2)", yscale="log",
                    title="prescribed coordinate: force error")
        axes[1].legend(fontsize=8, loc="lower right")
        pivot = np.array([pivot_x(t) for t in swing.times])
        axes[2].plot(swing.times, swing.particle(bob)[:, 0], label="bob x")
        axes[2].plot(swing.times, pivot, label="pivot x")
        axes[2].set(xlabel="t (s)", ylabel="x (m)", title="shaken pendulum")
        axes[2].legend(fontsize=8)
        fig.savefig(args.plot, dpi=110)
        print(f"plot: {args.plot}")


if __name__ == "__main__":
    main()
