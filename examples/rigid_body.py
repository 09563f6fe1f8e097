"""A rigid body from particles, spinning freely: conservation laws and the tennis-racket flip.

``System.add_rigid_body`` builds a body of 7 particles (an octahedron around a centre particle)
with a given mass, centre of mass and inertia tensor, held rigid by 15 distances. Spun in zero
gravity about its intermediate principal axis, with a small perturbation, a body with three
different moments of inertia tumbles: the spin axis flips over and back periodically (the
intermediate-axis theorem), while its angular momentum L = sum m r x v and its kinetic energy
stay constant, which is what the run is checked against. Spun about the major axis, it turns
steadily: a vertex's angle grows as omega t.

    python examples/rigid_body.py [--plot rigid_body.png]
"""

import argparse

import numpy as np

import vinculo

MASS = 2.0
INERTIA = np.diag([0.20, 0.30, 0.40])  # kg m^2: minor, intermediate, major axis along x, y, z


def spinning_body(angular_velocity):
    """A free body at the origin spinning with ``angular_velocity`` (rad/s), and its handles."""
    system = vinculo.System(gravity=(0.0, 0.0, 0.0))
    body = system.add_rigid_body(MASS, (0.0, 0.0, 0.0), INERTIA.tolist(),
                                 angular_velocity=tuple(angular_velocity))
    return system, body


def angular_momentum(solution, system):
    """L = sum_i m_i q_i x v_i about the origin (the centre of mass stays there), per time."""
    masses = system.masses()[None, :, None]
    return np.sum(masses * np.cross(solution.positions, solution.velocities), axis=1)


def vertex_pair(solution, body, direction):
    """The two opposite vertices (+e_k, -e_k) whose axis lies along ``direction`` at the start."""
    vertices = body["vertices"]
    pairs = [(vertices[2 * k], vertices[2 * k + 1]) for k in range(3)]
    start = [solution.positions[0, a.index] - solution.positions[0, b.index] for a, b in pairs]
    alignment = [abs(np.dot(d, direction)) / np.linalg.norm(d) for d in start]
    return pairs[int(np.argmax(alignment))]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--plot", metavar="FILE", help="write a PNG figure to FILE")
    args = parser.parse_args()

    # Intermediate axis (y) with a small perturbation: the flip.
    system, body = spinning_body((0.01, 2.0, 0.01))
    print(f"particles: {system.num_particles}, constraints: {system.num_constraints}")
    solution = vinculo.simulate(system, t_end=30.0, dt=5e-3)
    print(solution.summary())
    momentum = angular_momentum(solution, system)
    change = np.max(np.linalg.norm(momentum - momentum[0], axis=1)) / np.linalg.norm(momentum[0])
    energy = solution.kinetic_energy()
    print(f"largest change of angular momentum: {change:.1e} of |L|")
    print(f"largest change of kinetic energy: {np.max(np.abs(energy / energy[0] - 1)):.1e}")
    # The body's intermediate axis: the pair of opposite vertices along y at the start.
    plus, minus = vertex_pair(solution, body, (0.0, 1.0, 0.0))
    axis = solution.particle(plus) - solution.particle(minus)
    axis /= np.linalg.norm(axis, axis=1)[:, None]
    along = axis @ (momentum[0] / np.linalg.norm(momentum[0]))
    flips = np.count_nonzero(np.diff(np.sign(along)) != 0)
    print(f"the intermediate axis turned over {flips} times in {solution.times[-1]:.0f} s")

    # Major axis (z): steady rotation at omega = 2 rad/s.
    omega = 2.0
    steady_system, steady = spinning_body((0.0, 0.0, omega))
    steady_run = vinculo.simulate(steady_system, t_end=5.0, dt=5e-3)
    vertex = steady_run.particle(vertex_pair(steady_run, steady, (1.0, 0.0, 0.0))[0])
    angle = np.unwrap(np.arctan2(vertex[:, 1], vertex[:, 0]))
    angle -= angle[0]
    error = np.max(np.abs(angle - omega * steady_run.times))
    print(f"major axis: largest angle error against omega t: {error:.1e} rad")

    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, axes = plt.subplots(1, 2, figsize=(11, 3.6), layout="constrained")
        axes[0].plot(solution.times, along)
        axes[0].set(xlabel="t (s)", ylabel="e2 . L / |L|",
                    title="intermediate axis against the angular momentum")
        later = slice(1, None)  # the first values are 0, off a log scale
        axes[1].plot(solution.times[later], np.linalg.norm(momentum - momentum[0], axis=1)[later]
                     / np.linalg.norm(momentum[0]), label="|L - L0| / |L0|")
        axes[1].plot(solution.times[later], np.abs(energy / energy[0] - 1)[later],
                     label="|E / E0 - 1|")
        axes[1].set(xlabel="t (s)", yscale="log", title="conserved quantities")
        axes[1].legend(fontsize=8)
        fig.savefig(args.plot, dpi=110)
        print(f"plot: {args.plot}")


if __name__ == "__main__":
    main()
