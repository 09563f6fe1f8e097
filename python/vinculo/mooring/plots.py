"""PNG plots of a mooring run: line shapes and end tensions (matplotlib, off-screen Agg).

The shapes are drawn in the vertical plane of each line's ends: the horizontal distance from
end A against the height, at a few times of the run, with the seabed.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.figure import Figure

from vinculo.plotting import _save

__all__ = ["plot_shapes", "plot_tensions"]


def _horizontal(points: np.ndarray, origin: np.ndarray) -> np.ndarray:
    """Signed horizontal distance of ``points`` from ``origin`` along the line's mean heading."""
    offsets = points[..., :2] - origin[:2]
    heading = offsets.reshape(-1, 2).mean(axis=0)
    norm = np.linalg.norm(heading)
    heading = heading / norm if norm > 0 else np.array([1.0, 0.0])
    return offsets @ heading


#: The least width of a shape's horizontal axis, as a share of its height: a vertical line (a
#: float's tether) keeps a readable axis instead of one spread over the round-off of its nodes'
#: horizontal positions.
LEAST_WIDTH = 0.2


def _widen(ax: Any, horizontal: np.ndarray, heights: np.ndarray) -> None:
    """Widen ``ax``'s horizontal axis about the shapes' middle to at least
    :data:`LEAST_WIDTH` of their height."""
    low, high = float(horizontal.min()), float(horizontal.max())
    least = LEAST_WIDTH * float(heights.max() - heights.min())
    if high - low < least:
        middle = 0.5 * (low + high)
        ax.set_xlim(middle - 0.5 * least, middle + 0.5 * least)


def plot_shapes(run: Any, path: str | Path, snapshots: int = 6) -> Path:
    """The lines' shapes at a few times of a run, each in the vertical plane of its ends.

    Arguments:
        run: a :class:`vinculo.mooring.analysis.MooringRun`.
        path: the PNG file to write.
        snapshots: how many times to draw, evenly spread over the run.

    Returns:
        The path written.
    """
    positions = np.asarray(run.solution.positions)
    times = np.asarray(run.times)
    picks = np.unique(np.linspace(0, times.size - 1, max(1, snapshots)).round().astype(int))
    lines = run.model.lines
    figure = Figure(figsize=(10, 3.2 * len(lines)), layout="constrained")
    axes = np.atleast_1d(figure.subplots(len(lines), 1, squeeze=False)[:, 0])
    colours = [f"C{k}" for k in range(len(picks))]
    for ax, line, row in zip(axes, lines, run.model.file.lines, strict=True):
        nodes = np.asarray(line.nodes, dtype=int)
        origin = positions[0, nodes[0]]
        reach = []
        for colour, i in zip(colours, picks, strict=True):
            shape = positions[i, nodes]
            reach.append(_horizontal(shape, origin))
            ax.plot(reach[-1], shape[:, 2], "-", color=colour, lw=1.2,
                    label=f"t = {times[i]:.3g} s")
        _widen(ax, np.concatenate(reach), positions[picks][:, nodes, 2])
        if run.model.file.options.seafloor is None:
            ax.axhline(run.model.seabed_z, color="saddlebrown", lw=1.0, label="seabed")
        else:
            # The 3D seafloor under the line's first shape, along its horizontal path.
            first = positions[picks[0], nodes]
            ax.plot(_horizontal(first, origin), run.model.seabed_height(first[:, 0], first[:, 1]),
                    color="saddlebrown", lw=1.0, label="seabed (under the first shape)")
        ax.set_ylabel("z (m)")
        ax.set_title(f"line {row.id}")
        ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize="small")
    axes[-1].set_xlabel("horizontal distance from end A (m)")
    return _save(figure, path)


def plot_tensions(run: Any, path: str | Path) -> Path:
    """The end tensions of every line over time.

    Arguments:
        run: a :class:`vinculo.mooring.analysis.MooringRun`.
        path: the PNG file to write.

    Returns:
        The path written.
    """
    tensions = run.end_tensions
    figure = Figure(figsize=(10, 4.5), layout="constrained")
    ax = figure.subplots()
    for k, row in enumerate(run.model.file.lines):
        ax.plot(run.times, tensions[:, k, 1] / 1e3, label=f"line {row.id}, end B")
        ax.plot(run.times, tensions[:, k, 0] / 1e3, "--", label=f"line {row.id}, end A")
    ax.set_xlabel("time (s)")
    ax.set_ylabel("tension (kN)")
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize="small")
    return _save(figure, path)
