"""PNG plots of the demo models (matplotlib, drawn off-screen with the Agg canvas).

The figures are built with ``matplotlib.figure.Figure`` directly rather than pyplot, so nothing
here touches a GUI backend or global pyplot state.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from vinculo.demos import (
    DoublePendulumResult,
    HangingChainResult,
    InclinedPlaneResult,
    PendulumResult,
    pendulum_tension,
)

__all__ = [
    "plot_double_pendulum",
    "plot_hanging_chain",
    "plot_inclined_plane",
    "plot_pendulum",
]


def _legend_outside(axes) -> None:
    """Put the legend to the right of the axes, where it hides no curve."""
    axes.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize="small")


def _save(figure: Figure, path: str | Path) -> Path:
    """Write a figure as PNG, creating the folder if needed."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    FigureCanvasAgg(figure)
    figure.savefig(path, dpi=110)
    return path


def plot_pendulum(result: PendulumResult, path: str | Path) -> Path:
    """Bob coordinates and rod tension (computed and closed form) over time.

    Arguments:
        result: from :func:`vinculo.demos.run_pendulum`.
        path: the PNG file to write.

    Returns:
        The path written.
    """
    model, solution = result.model, result.solution
    t, q = solution.times, solution.particle(model.bob)
    figure = Figure(figsize=(10, 6), layout="constrained")
    top, bottom = figure.subplots(2, 1, sharex=True)
    top.plot(t, q[:, 0], label="x")
    top.plot(t, q[:, 2], label="z")
    top.set_ylabel("position (m)")
    top.set_title(
        f"Pendulum L = {model.length:g} m: period {result.period:.7f} s "
        f"(exact {result.exact_period:.7f} s)"
    )
    _legend_outside(top)
    bottom.plot(t, solution.distance_tension(model.rod, model.length), label="2 lambda L")
    bottom.plot(t, pendulum_tension(model, q), "--", label="m g (3 cos th - 2 cos th0)")
    bottom.set_xlabel("time (s)")
    bottom.set_ylabel("rod tension (N)")
    _legend_outside(bottom)
    return _save(figure, path)


def plot_double_pendulum(result: DoublePendulumResult, path: str | Path) -> Path:
    """Rod angles and normal-mode coordinates over time.

    Arguments:
        result: from :func:`vinculo.demos.run_double_pendulum`.
        path: the PNG file to write.

    Returns:
        The path written.
    """
    t = result.solution.times
    figure = Figure(figsize=(10, 6), layout="constrained")
    top, bottom = figure.subplots(2, 1, sharex=True)
    top.plot(t, result.angles[:, 0], label="upper rod")
    top.plot(t, result.angles[:, 1], label="lower rod")
    top.set_ylabel("angle from vertical (rad)")
    top.set_title("Double pendulum, small amplitude")
    _legend_outside(top)
    (w1, w2), (e1, e2) = result.frequencies, result.exact_frequencies
    bottom.plot(t, result.modal[:, 0], label=f"slow: {w1:.5f} rad/s\n(exact {e1:.5f})")
    bottom.plot(t, result.modal[:, 1], label=f"fast: {w2:.5f} rad/s\n(exact {e2:.5f})")
    bottom.set_xlabel("time (s)")
    bottom.set_ylabel("modal coordinate")
    _legend_outside(bottom)
    return _save(figure, path)


def plot_hanging_chain(result: HangingChainResult, path: str | Path) -> Path:
    """Snapshots of the chain's shape and its energy error over time.

    Arguments:
        result: from :func:`vinculo.demos.run_hanging_chain`.
        path: the PNG file to write.

    Returns:
        The path written.
    """
    model, solution = result.model, result.solution
    figure = Figure(figsize=(10, 5), layout="constrained")
    left, right = figure.subplots(1, 2)
    indices = [model.anchor.index] + [p.index for p in model.particles]
    for k in np.linspace(0, len(solution.times) - 1, 8).astype(int):
        shape = solution.positions[k, indices, :]
        left.plot(shape[:, 0], shape[:, 2], "o-", ms=3, label=f"t = {solution.times[k]:.2f} s")
    left.set_aspect("equal")
    left.set_xlabel("x (m)")
    left.set_ylabel("z (m)")
    left.set_title(f"Chain of {len(model.links)} links")
    left.legend(fontsize="small", loc="lower left")
    right.plot(solution.times, (result.energy - result.energy[0]) / result.energy_scale)
    right.set_xlabel("time (s)")
    right.set_ylabel("(E - E0) / (m g L)")
    right.set_title("Energy error")
    return _save(figure, path)


def plot_inclined_plane(result: InclinedPlaneResult, path: str | Path) -> Path:
    """Distance slid and normal force over time, against the closed forms.

    Arguments:
        result: from :func:`vinculo.demos.run_inclined_plane`.
        path: the PNG file to write.

    Returns:
        The path written.
    """
    model, solution = result.model, result.solution
    t = solution.times
    figure = Figure(figsize=(8, 6), layout="constrained")
    top, bottom = figure.subplots(2, 1, sharex=True)
    top.plot(t, solution.particle(model.block) @ model.downhill, label="simulated")
    top.plot(t, 0.5 * result.exact_acceleration * t**2, "--", label="g sin(th) t^2 / 2")
    top.set_ylabel("distance down the slope (m)")
    top.set_title(f"Particle on a {np.degrees(model.angle):g} degree frictionless plane")
    top.legend(loc="upper left")
    bottom.plot(t, result.normal_force, label="lambda |n|")
    bottom.axhline(result.exact_normal_force, ls="--", color="C1", label="m g cos(th)")
    bottom.set_xlabel("time (s)")
    bottom.set_ylabel("normal force (N)")
    # Show the force on a scale from zero: its ~1e-9 relative round-off is not worth magnifying.
    largest = float(np.max(np.abs(result.normal_force))) or 1.0
    bottom.set_ylim(min(0.0, 1.25 * float(np.min(result.normal_force))), 1.25 * largest)
    bottom.legend(loc="lower right")
    return _save(figure, path)
