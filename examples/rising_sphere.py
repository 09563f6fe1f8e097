"""A buoyant sphere released in still water: buoyancy, added mass and drag against closed forms.

The buoy's sphere (D = 0.1 m, 366.69 kg/m^3) is released at rest in still water with the
Morison element of the buoy study (``System.add_morison``). Vertically, with m_s its mass,
m_f = rho V the displaced mass, m_a = Ca m_f the added mass and k = rho Cd A / 2,

    (m_s + m_a) v' = (m_f - m_s) g - k v |v|,

whose solution from rest is v(t) = v_t tanh(a_0 t / v_t), with the initial acceleration
a_0 = (m_f - m_s) g / (m_s + m_a) and the terminal velocity v_t = sqrt((m_f - m_s) g / k). The added
mass appears only in a_0 (the time to reach v_t), the drag only in v_t.

    python examples/rising_sphere.py [--plot rising_sphere.png]
"""

import argparse

import numpy as np

import vinculo

G, RHO, RHO_S, D, CD, CA = 9.81, 1000.0, 366.69, 0.1, 0.22, 0.52


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--plot", metavar="FILE", help="write a PNG figure to FILE")
    args = parser.parse_args()

    volume, area = np.pi * D**3 / 6, np.pi * D**2 / 4
    m_s, m_f = RHO_S * volume, RHO * volume
    m_a, k = CA * m_f, 0.5 * RHO * CD * area
    a_0 = (m_f - m_s) * G / (m_s + m_a)
    v_t = np.sqrt((m_f - m_s) * G / k)

    system = vinculo.System(gravity=(0.0, 0.0, -G))
    sphere = system.add_particle(mass=m_s, position=(0.0, 0.0, 0.0))
    system.add_morison(sphere, volume=volume, area=area, drag_coefficient=CD,
                       added_mass_coefficient=CA, density=RHO)
    solution = vinculo.simulate(system, t_end=2.0, dt=1e-3)
    t = solution.times
    v = solution.particle_velocity(sphere)[:, 2]
    exact = v_t * np.tanh(a_0 * t / v_t)
    print(f"mass {m_s:.4f} kg, displaced {m_f:.4f} kg, added {m_a:.4f} kg")
    print(f"initial acceleration: {(v[1] - v[0]) / (t[1] - t[0]):.5f} m/s^2 "
          f"(closed form {a_0:.5f})")
    print(f"velocity at 2 s: {v[-1]:.6f} m/s, terminal velocity {v_t:.6f} m/s")
    print(f"largest velocity error: {np.max(np.abs(v - exact)):.1e} m/s")

    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(7, 3.8), layout="constrained")
        ax.plot(t, v, label="vinculo (add_morison)")
        ax.plot(t[::80], exact[::80], "k.", label="v_t tanh(a_0 t / v_t)")
        ax.axhline(v_t, color="0.6", ls=":", label="terminal velocity v_t")
        ax.set(xlabel="t (s)", ylabel="upward velocity (m/s)",
               title="a buoyant sphere released in still water")
        ax.legend(fontsize=8)
        fig.savefig(args.plot, dpi=110)
        print(f"plot: {args.plot}")


if __name__ == "__main__":
    main()
