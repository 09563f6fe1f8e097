"""Forces and constraints written in Python, against the built-in elements they reproduce.

A *group* is many elements computed by one Python function on numpy arrays, once per evaluation
point for the whole group. Two groups, each checked against the built-in element that computes
the same physics in Rust:

- a force group: quadratic drag f = -c |v| v on every bead of a chain released horizontally,
  with its analytic Jacobian; the run must match the run with ``add_quadratic_drag``;
- a constraint group: a spherical pendulum, the bob held on a sphere of radius R about the
  origin, Phi = R^2 - |q|^2 with its gradient, Hessian and gamma; the run must match the run
  with ``add_distance_to_point``, and its multiplier gives the same rod tension.

    python examples/user_groups.py [--beads 10] [--plot user_groups.png]
"""

import argparse
from itertools import pairwise

import numpy as np

import vinculo

G, DRAG = 9.81, 0.05


def quadratic_drag(t, q, v):
    """Forces -c |v| v on k particles: q and v are (k, 3), so is the result."""
    return -DRAG * np.linalg.norm(v, axis=1)[:, None] * v


def quadratic_drag_jacobian(t, q, v):
    """(df/dq, df/dv), each (k, 3, 3): df/dq = 0, df/dv = -c (|v| I + v v^T / |v|)."""
    speed = np.linalg.norm(v, axis=1)
    outer = np.einsum("ki,kj->kij", v, v) / np.where(speed > 0.0, speed, 1.0)[:, None, None]
    df_dv = -DRAG * (speed[:, None, None] * np.eye(3) + outer)
    return np.zeros_like(df_dv), df_dv


def chain(beads: int, python_drag: bool):
    """A 1 m chain released horizontally, with drag on every bead."""
    system = vinculo.System(gravity=(0.0, 0.0, -G))
    pivot = system.add_particle(mass=1.0, position=(0.0, 0.0, 0.0), fixed=True)
    particles = [system.add_particle(mass=0.05, position=(k / beads, 0.0, 0.0))
                 for k in range(1, beads + 1)]
    for a, b in pairwise([pivot, *particles]):
        system.add_distance(a, b, length=1.0 / beads)
    group = None
    if python_drag:
        group = system.add_force_group([p.index for p in particles], quadratic_drag,
                                       jacobian=quadratic_drag_jacobian, name="drag")
    else:
        for p in particles:
            system.add_quadratic_drag(p, DRAG)
    return system, particles, group


RADIUS = 0.5


def on_sphere(t, q):
    """Phi = R^2 - |q|^2 for k particles, q (k, 3): k residuals."""
    return RADIUS**2 - np.einsum("ki,ki->k", q, q)


def on_sphere_gradient(t, q):
    """dPhi/dq = -2 q^T: (k, 1, 3) for elements of one particle."""
    return (-2.0 * q)[:, None, :]


def on_sphere_hessian(t, q):
    """d2Phi/dq2 = -2 I: (k, 3, 3)."""
    return np.broadcast_to(-2.0 * np.eye(3), (len(q), 3, 3)).copy()


def on_sphere_gamma(t, q, v):
    """Phi'' - Phi_q q'' = -2 |v|^2."""
    return -2.0 * np.einsum("ki,ki->k", v, v)


def spherical_pendulum(python_constraint: bool):
    """A bob on a sphere of radius R about the origin, launched sideways."""
    system = vinculo.System(gravity=(0.0, 0.0, -G))
    start = RADIUS * np.array([np.sin(0.6), 0.0, -np.cos(0.6)])
    bob = system.add_particle(mass=1.0, position=tuple(start), velocity=(0.0, 1.2, 0.0))
    if python_constraint:
        group = system.add_constraint_group(
            [bob.index], on_sphere, gradient=on_sphere_gradient, hessian=on_sphere_hessian,
            gamma=on_sphere_gamma, scale=0.5 / RADIUS, name="sphere")
        return system, bob, group
    rod = system.add_distance_to_point(bob, (0.0, 0.0, 0.0), length=RADIUS)
    return system, bob, rod


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--beads", type=int, default=10, help="beads of the chain (default 10)")
    parser.add_argument("--plot", metavar="FILE", help="write a PNG figure to FILE")
    args = parser.parse_args()

    built_in, _, _ = chain(args.beads, python_drag=False)
    python, beads, drag = chain(args.beads, python_drag=True)
    reference = vinculo.simulate(built_in, t_end=1.5, dt=1e-3)
    run = vinculo.simulate(python, t_end=1.5, dt=1e-3)
    gap = np.max(np.abs(run.positions - reference.positions))
    print(f"force group: largest position gap to the built-in drag: {gap:.1e} m")
    print(f"force group calls: {drag.calls}, seconds: "
          f"{ {name: round(s, 4) for name, s in drag.seconds.items()} }")

    ref_system, ref_bob, rod = spherical_pendulum(python_constraint=False)
    user_system, user_bob, sphere = spherical_pendulum(python_constraint=True)
    ref_run = vinculo.simulate(ref_system, t_end=3.0, dt=1e-3)
    user_run = vinculo.simulate(user_system, t_end=3.0, dt=1e-3)
    gap = np.max(np.abs(user_run.particle(user_bob) - ref_run.particle(ref_bob)))
    # Same Phi = R^2 - |q|^2 as the built-in distance: the tension is 2 lambda R for both.
    user_tension = 2.0 * RADIUS * user_run.multipliers[:, sphere.constraint_indices[0]]
    ref_tension = ref_run.distance_tension(rod, RADIUS)
    print(f"constraint group: largest position gap to the built-in distance: {gap:.1e} m")
    print(f"constraint group: largest tension gap: "
          f"{np.max(np.abs(user_tension - ref_tension)):.1e} N")

    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, axes = plt.subplots(1, 2, figsize=(11, 3.8), layout="constrained")
        last = beads[-1]
        axes[0].plot(reference.times, reference.particle(last)[:, 2], label="add_quadratic_drag")
        axes[0].plot(run.times, run.particle(last)[:, 2], "--", label="Python force group")
        axes[0].set(xlabel="t (s)", ylabel="z (m)", title="chain with drag: last bead")
        axes[0].legend(fontsize=8)
        axes[1].plot(ref_run.times, ref_tension, label="add_distance_to_point")
        axes[1].plot(user_run.times, user_tension, "--", label="Python constraint group")
        axes[1].set(xlabel="t (s)", ylabel="tension (N)", title="spherical pendulum")
        axes[1].legend(fontsize=8)
        fig.savefig(args.plot, dpi=110)
        print(f"plot: {args.plot}")


if __name__ == "__main__":
    main()
