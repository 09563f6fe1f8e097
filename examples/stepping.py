"""A coupling loop: a pendulum whose anchor another code moves, step by step, with a snapshot.

A 1 m pendulum hangs from an anchor that an outside code (here a function standing in for it)
moves along x as X(t) = A (1 - cos(w t)), A = 1 cm, w = 2 rad/s. Every 10 ms the loop sets the
anchor's next position on a driven law (``vinculo.driven``) and advances the simulation to that
time (``Simulation.step_to``). Halfway, it takes a snapshot, runs to the end, restores the
snapshot and runs to the end again: the second pass repeats the first bit for bit. The run is
also saved to and continued from a snapshot file.

The reference is linear theory: for small angles theta'' + w0^2 theta = -X''/L, w0^2 = g/L, from
rest, so theta(t) = -(A w^2 / L) (cos(w t) - cos(w0 t)) / (w0^2 - w^2) and the bob is at
x = X + L sin(theta). The anchor moves linearly between the samples the loop sets (their
spacing, 10 ms, limits the agreement together with the angle's nonlinearity, theta ~ 1e-2).

    python examples/stepping.py [--plot stepping.png]
"""

import argparse
import tempfile
from pathlib import Path

import numpy as np

import vinculo

G, LENGTH, AMPLITUDE, OMEGA = 9.81, 1.0, 0.01, 2.0
T_END, COUPLING = 4.0, 0.01


def anchor(t: float) -> float:
    """The outside code: the anchor's x position at time t."""
    return AMPLITUDE * (1.0 - np.cos(OMEGA * t))


def linear_theory(t: float) -> float:
    """The bob's x position at time t for small angles (module docstring)."""
    w0_squared = G / LENGTH
    theta = -(AMPLITUDE * OMEGA**2 / LENGTH) * (
        np.cos(OMEGA * t) - np.cos(np.sqrt(w0_squared) * t)
    ) / (w0_squared - OMEGA**2)
    return anchor(t) + LENGTH * np.sin(theta)


def build(law: vinculo.Law) -> vinculo.System:
    """The pendulum, at rest below the anchor at (law(t), 0, 0)."""
    system = vinculo.System(gravity=(0.0, 0.0, -G))
    bob = system.add_particle(mass=1.0, position=(0.0, 0.0, -LENGTH))
    system.add_distance_to_point(bob, (law, 0.0, 0.0), length=LENGTH)
    return system


def couple(sim: vinculo.Simulation, law: vinculo.Law, times: np.ndarray, drive: bool) -> None:
    """The coupling loop: set the anchor at each time (unless already set), then step there."""
    for t in times:
        if drive:
            law.set(float(t), float(anchor(t)))
        sim.step_to(float(t))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--plot", metavar="FILE", help="write a PNG plot to FILE")
    args = parser.parse_args()
    times = np.arange(1, round(T_END / COUPLING) + 1) * COUPLING
    half = len(times) // 2
    law = vinculo.driven(anchor(0.0), 0.0)
    sim = vinculo.Simulation(build(law), t_end=T_END, dt=COUPLING)
    couple(sim, law, times[:half], drive=True)
    snapshot = sim.snapshot()
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "halfway.snap"
        sim.save_snapshot(path)
        couple(sim, law, times[half:], drive=True)
        first = sim.solution()
        # The driven law keeps the values set after the snapshot: the second pass reuses them.
        sim.restore(snapshot)
        couple(sim, law, times[half:], drive=False)
        second = sim.solution()
        # A new simulation of the same model continues from the file.
        from_file = vinculo.Simulation(build(law), t_end=T_END, dt=COUPLING)
        from_file.load_snapshot(path)
        from_file.step_to(T_END)

    bob_x = second.positions[:, 0, 0]
    theory = np.array([linear_theory(t) for t in second.times])
    print(f"snapshot at t = {snapshot.time:.2f} s, run to t = {second.times[-1]:.2f} s")
    repeat = np.max(np.abs(second.positions - first.positions))
    print(f"restored pass vs first pass, max |dx|: {repeat:.3e} m")
    continued = np.max(np.abs(from_file.positions - second.positions[-1]))
    print(f"continued from the file vs in memory, max |dx|: {continued:.3e} m")
    print(f"bob swing amplitude: {np.max(np.abs(bob_x - [anchor(t) for t in second.times])):.4e} m")
    error = np.max(np.abs(bob_x - theory))
    print(f"max deviation from linear theory: {error:.3e} m")
    if args.plot:
        import matplotlib.pyplot as plt

        figure, axes = plt.subplots(figsize=(7, 3.5), constrained_layout=True)
        anchor_x = [anchor(t) for t in second.times]
        axes.plot(second.times, 100 * np.asarray(anchor_x), label="anchor (set by the loop)")
        axes.plot(second.times, 100 * bob_x, label="bob")
        axes.plot(second.times, 100 * theory, "k:", label="bob, linear theory")
        axes.axvline(snapshot.time, color="0.6", lw=0.8)
        axes.set_xlabel("t (s)")
        axes.set_ylabel("x (cm)")
        axes.legend(loc="upper left")
        figure.savefig(args.plot, dpi=120)
        plt.close(figure)
        print(f"plot: {args.plot}")


if __name__ == "__main__":
    main()
