"""A four-bar linkage of planar bodies and revolute joints, its crank turned at constant speed.

The crank (pivot O2 at the origin), the coupler and the rocker (pivot O4) are planar bars in the
x-z plane, joined by four revolute joints; the crank's pin is held on a plane through O2 whose
normal turns with the crank angle phi(t) = phi0 + omega t, a formula of laws. The coupler's end B
is where the circles about the pin A (radius r3) and about O4 (radius r4) meet: the example
prints the largest distance between the simulated B and that closed form, and the peak torque the
driver applies (its multiplier times the pin's lever), checked against the power balance
tau omega = dE/dt of the mechanical energy. ``--plot FILE`` draws the path of the
coupler's midpoint (the coupler curve) and the driving torque.

Run:  .venv/bin/python examples/four_bar.py [--plot four_bar.png]
"""

import argparse
import math

import numpy as np

import vinculo
from vinculo import laws

R2, R3, R4, D = 0.25, 0.7, 0.5, 0.8  # crank, coupler, rocker, ground (m): a crank-rocker
OMEGA, PHI0 = 2 * math.pi, 0.3  # rad/s, rad
Y = (0.0, 1.0, 0.0)


def closed_form(phi: float) -> tuple[np.ndarray, np.ndarray]:
    """The pin A and the coupler's end B (x, z) for the crank angle phi (open branch)."""
    a = np.array([R2 * math.cos(phi), R2 * math.sin(phi)])
    gap = np.array([D, 0.0]) - a
    dist = np.linalg.norm(gap)
    along = (R3**2 - R4**2 + dist**2) / (2 * dist)
    height = math.sqrt(R3**2 - along**2)
    return a, a + along * gap / dist + height * np.array([-gap[1], gap[0]]) / dist


def xz(p) -> tuple[float, float, float]:
    return (float(p[0]), 0.0, float(p[1]))


def bar(system, mass, start, end):
    """A planar bar in the x-z plane: inertia m L^2 / 12 about y."""
    start, end = np.asarray(start, float), np.asarray(end, float)
    length = np.linalg.norm(end - start)
    return system.add_planar_body(mass, xz((start + end) / 2), mass * length**2 / 12, normal="y")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--plot", help="write the coupler curve and the torque to this file")
    args = parser.parse_args()

    a0, b0 = closed_form(PHI0)
    system = vinculo.System(gravity=(0.0, 0.0, -9.81))
    crank = bar(system, 0.5, (0, 0), a0)
    coupler = bar(system, 1.2, a0, b0)
    rocker = bar(system, 0.9, (D, 0), b0)
    system.add_joint("revolute", None, crank, (0.0, 0.0, 0.0), Y)
    system.add_joint("revolute", crank, coupler, xz(a0), Y)
    system.add_joint("revolute", coupler, rocker, xz(b0), Y)
    system.add_joint("revolute", rocker, None, (D, 0.0, 0.0), Y)
    phi = laws.polynomial([PHI0, OMEGA])
    pin = system.point(crank, xz(a0))
    driver = system.add_plane(pin, (-laws.sin(phi), 0.0, laws.cos(phi)), (0.0, 0.0, 0.0))
    system.project_initial_state()  # the bodies start with the driven motion's velocities

    end = system.point(coupler, xz(b0))
    middle = system.point(coupler, xz((a0 + b0) / 2))
    solution = vinculo.simulate(system, t_end=2.0, dt=1e-3)
    t = solution.times
    expected = np.array([xz(closed_form(PHI0 + OMEGA * s)[1]) for s in t])
    error = np.max(np.linalg.norm(solution.point(end) - expected, axis=1))
    # The driver's force on the pin is lambda n(t) (Phi = n . x). The crank turns from +x
    # towards +z, about -y: the driving torque in that sense is the moment about O2 along -y,
    # -(x_pin x lambda n)_y = lambda (x n_z - z n_x).
    lam = solution.multiplier(driver)
    pin_xyz = solution.point(pin)
    angle = PHI0 + OMEGA * t
    torque = lam * (pin_xyz[:, 0] * np.cos(angle) + pin_xyz[:, 2] * np.sin(angle))
    # Power balance: with no dissipation the driver's work over a step, the mean of its power
    # tau omega at the step's ends times dt, is the change of the mechanical energy
    # E = 1/2 sum m v^2 + sum m g z over the step. The index-3 multipliers of the trapezoidal
    # rule are first-order accurate: the imbalance halves with dt (5.9e-3 of the peak power at
    # 1 ms, 2.9e-3 at 0.5 ms).
    masses = system.masses()
    energy = 0.5 * np.einsum("i,tij,tij->t", masses, solution.velocities, solution.velocities)
    energy += 9.81 * np.einsum("i,ti->t", masses, solution.positions[:, :, 2])
    power = torque * OMEGA
    work = 0.5 * (power[1:] + power[:-1]) * np.diff(t)
    imbalance = np.max(np.abs(np.diff(energy) - work) / np.diff(t)) / np.max(np.abs(power))
    print(f"largest distance of the coupler's end from the closed form: {error:.3e} m")
    print(f"power balance, largest |dE - work| / dt / peak power: {imbalance:.3e}")
    print(f"peak driving torque: {np.max(np.abs(torque)):.4f} N m")
    print(
        f"after two turns, largest distance from the start: "
        f"{np.max(np.abs(solution.positions[-1] - solution.positions[0])):.3e} m"
    )

    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, (left, right) = plt.subplots(1, 2, figsize=(10, 4))
        curve = solution.point(middle)
        left.plot(curve[:, 0], curve[:, 2], label="coupler midpoint")
        left.plot([0, a0[0], b0[0], D], [0, a0[1], b0[1], 0], "o-", color="grey", label="at t = 0")
        left.set_aspect("equal")
        left.set_xlabel("x (m)")
        left.set_ylabel("z (m)")
        left.legend()
        right.plot(t, torque)
        right.set_xlabel("t (s)")
        right.set_ylabel("driving torque, in the sense of the crank (N m)")
        fig.tight_layout()
        fig.savefig(args.plot, dpi=100)


if __name__ == "__main__":
    main()
