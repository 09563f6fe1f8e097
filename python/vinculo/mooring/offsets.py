"""The offset curve of a mooring: its restoring force (or moment) and line tensions as a
vessel carrying the coupled points is moved away from its position.

The coupled (Vessel/Coupled) points of a MoorDyn file, a coupled body's among them, are moved
together, by ``s d`` for each offset ``s`` along the unit direction ``d``, or turned by each
angle about an axis ``d`` through a reference point; the static equilibrium is solved again at
each (:func:`vinculo.mooring.statics`, no time step): the mooring's total force on the points
and its moment about the reference (carried along by a translation), the restoring component
(``-F . d``, or ``-M . d`` for a rotation: the sign of the offset where the mooring pulls
back), and every line's end tensions and laid length. The slope of the restoring force at zero
is ``d^T K_uu d`` of the vessel stiffness, of the restoring moment ``d^T K_tt d`` per radian
(:meth:`vinculo.mooring.analysis.MooringStatics.vessel_stiffness`); the curve shows how the
mooring stiffens (or slackens) beyond the linear range, where a line lifts off the seabed or
snaps taut. An offset whose equilibrium is not found leaves NaN in its row and its message in
:attr:`OffsetCurve.failed`: the other offsets are kept.

Example:
    >>> import vinculo.mooring as mooring
    >>> curve = mooring.offset_curve("tests/data/moordyn/oc3_hywind.txt",
    ...                              [-10.0, 0.0, 10.0], heading=0.0)  # doctest: +SKIP
    >>> curve.restoring  # doctest: +SKIP
    >>> yaw = mooring.offset_curve("tests/data/moordyn/oc3_hywind.txt",
    ...                            [-5.0, 0.0, 5.0], rotation_axis=(0, 0, 1))  # doctest: +SKIP
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from vinculo.errors import ConvergenceError, InvalidInputError
from vinculo.mooring.moordyn_file import MoorDynFile, read_moordyn

__all__ = ["OffsetCurve", "offset_curve", "plot_offset_curve"]


@dataclass
class OffsetCurve:
    """A mooring's forces and tensions over offsets of its coupled points.

    Arguments:
        direction: the unit direction of the offsets, or the axis of the rotations.
        offsets: ``(k,)`` the offsets along it (m), or the angles about it (degrees).
        forces: ``(k, 3)`` the mooring's total force on the coupled points (N).
        moments: ``(k, 3)`` its moment about the reference point, which a translation carries
            along (N m).
        end_tensions: ``(k, lines, 2)`` each line's tension at end A and end B (N).
        laid_lengths: ``(k, lines)`` each line's length on the seabed (m).
        lines: the line ids, in file order.
        points: the ids of the points moved.
        failed: the offsets whose equilibrium was not found, with the error's message (their
            rows are NaN).
        rotation: True when the offsets are rotations about ``direction``.
        reference: the reference point (m).
    """

    direction: np.ndarray
    offsets: np.ndarray
    forces: np.ndarray
    moments: np.ndarray
    end_tensions: np.ndarray
    laid_lengths: np.ndarray
    lines: list[int]
    points: list[int]
    failed: dict[float, str] = field(default_factory=dict)
    rotation: bool = False
    reference: np.ndarray = field(default_factory=lambda: np.zeros(3))

    @property
    def restoring(self) -> np.ndarray:
        """``(k,)`` the restoring force ``-F . d`` (N), or moment ``-M . d`` for rotations
        (N m): the mooring's pull against the offsets, with the sign of the offset where it
        pulls the points back towards zero (a spring's ``k s``)."""
        load = self.moments if self.rotation else self.forces
        return -(load @ self.direction)

    def columns(self) -> list[str]:
        """The CSV columns: ``offset, fx, fy, fz, mx, my, mz, restoring``, then each line's
        ``line<k>_A_tension``, ``line<k>_B_tension`` and ``line<k>_laid_length``."""
        names = ["offset", "fx", "fy", "fz", "mx", "my", "mz", "restoring"]
        for k in self.lines:
            names += [f"line{k}_A_tension", f"line{k}_B_tension", f"line{k}_laid_length"]
        return names

    def to_csv(self, path: str | Path) -> Path:
        """Write the curve, one row per offset (m or degrees; N, N m and m; NaN where the
        equilibrium failed).

        Arguments:
            path: the file to write.

        Returns:
            The path written.
        """
        from vinculo.mooring.analysis import write_csv

        def row(i: int) -> list[float]:
            values = [self.offsets[i], *self.forces[i], *self.moments[i], self.restoring[i]]
            for k in range(len(self.lines)):
                values += [*self.end_tensions[i, k], self.laid_lengths[i, k]]
            return [float(x) for x in values]

        return write_csv(path, self.columns(), (row(i) for i in range(len(self.offsets))))

    def table(self) -> str:
        """A text table: offset, restoring force and the largest end tension of each line.

        Returns:
            The table, with a header line.
        """
        head = ("angle (deg)", "restoring (N m)") if self.rotation else ("offset (m)",
                                                                           "restoring (N)")
        lines = [f"{head[0]:>11} {head[1]:>16}"
                 + "".join(f"{f'line {k} max T (N)':>18}" for k in self.lines)]
        for i, s in enumerate(self.offsets):
            largest = np.max(self.end_tensions[i], axis=1)
            lines.append(f"{s:>11.4g} {self.restoring[i]:>16.6g}"
                         + "".join(f"{t:>18.6g}" for t in largest))
        return "\n".join(lines)


def _unit(vector: Any, name: str) -> np.ndarray:
    """``vector`` normalised, or the error naming ``name``."""
    d = np.asarray(vector, dtype=float)
    norm = float(np.linalg.norm(d)) if d.shape == (3,) else 0.0
    if not (math.isfinite(norm) and norm > 0.0):
        raise InvalidInputError(f"give the offsets' {name} as three finite numbers, not all "
                                "zero", name=name, value=vector)
    return d / norm


def _direction(heading: float | None, direction: Any, axis: Any) -> np.ndarray:
    """The unit direction (or axis) of the offsets from a heading (deg), a vector or an axis."""
    if sum(x is not None for x in (heading, direction, axis)) != 1:
        raise InvalidInputError("give the offsets' heading (degrees in the horizontal plane), "
                                "their direction (a vector) or the axis of rotations, one of "
                                "the three", name="heading", value=heading)
    if heading is not None:
        if not math.isfinite(heading):
            raise InvalidInputError("give a finite heading in degrees", name="heading",
                                    value=heading)
        angle = math.radians(heading)
        return np.array([math.cos(angle), math.sin(angle), 0.0])
    return _unit(direction, "direction") if axis is None else _unit(axis, "rotation_axis")


def _turn(axis: np.ndarray, degrees: float) -> np.ndarray:
    """The rotation matrix of ``degrees`` about the unit ``axis`` (Rodrigues)."""
    from vinculo.mooring.analysis import _cross_matrix

    k = _cross_matrix(axis)
    angle = math.radians(degrees)
    return np.eye(3) + math.sin(angle) * k + (1.0 - math.cos(angle)) * k @ k


def offset_curve(path: str | Path | MoorDynFile, offsets: Sequence[float], *,
                 heading: float | None = None, direction: Any = None,
                 rotation_axis: Any = None, reference: Any = (0.0, 0.0, 0.0),
                 progress: bool = False, **statics_options: Any) -> OffsetCurve:
    """The offset curve of the mooring of a MoorDyn file (module documentation).

    Arguments:
        path: the MoorDyn v2 input file (or its content).
        offsets: the offsets (m), or the angles (degrees) with ``rotation_axis``; each a
            static equilibrium.
        heading: the offsets' direction as a heading in the horizontal plane (degrees from +x
            towards +y).
        direction: or as a vector (normalised here).
        rotation_axis: or turn the points about this axis (a vector) through ``reference``.
        reference: the point the moments are taken about and the rotations made about (m).
        progress: print a line per offset on standard error.
        **statics_options: passed to the statics (``tolerance``, ``max_iterations``).

    Returns:
        The curve.

    Raises:
        MooringFileError: for a malformed or unsupported file.
        InvalidInputError: for a file without coupled points, offsets that are not finite
            numbers, a bad reference, or not exactly one of ``heading``, ``direction`` and
            ``rotation_axis``.
    """
    import sys

    from vinculo.mooring.analysis import statics

    model = path if isinstance(path, MoorDynFile) else read_moordyn(path)
    d = _direction(heading, direction, rotation_axis)
    rotation = rotation_axis is not None
    origin = np.asarray(reference, dtype=float)
    if origin.shape != (3,) or not np.all(np.isfinite(origin)):
        raise InvalidInputError("give the reference point as three finite coordinates (m)",
                                name="reference", value=reference)
    values = np.asarray(offsets, dtype=float).reshape(-1)
    if values.size == 0 or not np.all(np.isfinite(values)):
        raise InvalidInputError("give one or more finite offsets (m, or degrees for rotations)",
                                name="offsets", value=offsets)
    moved = [p.id for p in model.coupled_points()]
    if not moved:
        raise InvalidInputError("the file has no coupled (Vessel/Coupled) points to move",
                                name="points", value=[])
    n_lines = len(model.lines)
    forces = np.full((values.size, 3), np.nan)
    moments = np.full((values.size, 3), np.nan)
    tensions = np.full((values.size, n_lines, 2), np.nan)
    laid = np.full((values.size, n_lines), np.nan)
    failed: dict[float, str] = {}
    line_ids = [row.id for row in model.lines]
    for i, s in enumerate(values):
        if rotation:
            turn = _turn(d, s)
            centre = origin

            def place(x: np.ndarray, turn: np.ndarray = turn) -> np.ndarray:
                return origin + turn @ (x - origin)
        else:
            centre = origin + s * d

            def place(x: np.ndarray, shift: np.ndarray = s * d) -> np.ndarray:
                return x + shift
        # A moved point of a body is no longer where the body's pose puts it: it becomes a
        # coupled point of its own at its new position.
        points = tuple(
            dataclasses.replace(p, position=tuple(float(x) for x in place(np.asarray(
                p.position))), body=None, relative=None) if p.id in moved else p
            for p in model.points)
        shifted = dataclasses.replace(model, points=points)
        try:
            result = statics(shifted, **statics_options)
        except ConvergenceError as exc:
            failed[float(s)] = str(exc)
            if progress:
                print(f"offset {s:g}: no equilibrium ({exc})", file=sys.stderr, flush=True)
            continue
        pulls = result.point_forces(moved)
        arms = np.array([shifted.points[k - 1].position for k in moved]) - centre
        forces[i] = pulls.sum(axis=0)
        moments[i] = np.cross(arms, pulls).sum(axis=0)
        for end in result.ends:
            k = line_ids.index(end.line)
            tensions[i, k, "AB".index(end.end)] = end.tension
            laid[i, k] = end.laid_length
        if progress:
            load = moments[i] if rotation else forces[i]
            print(f"offset {s:g} ({i + 1} of {values.size}): restoring {-(load @ d):.6g}",
                  file=sys.stderr, flush=True)
    return OffsetCurve(direction=d, offsets=values, forces=forces, moments=moments,
                       end_tensions=tensions, laid_lengths=laid, lines=line_ids, points=moved,
                       failed=failed, rotation=rotation, reference=origin)


def plot_offset_curve(curve: OffsetCurve, path: str | Path) -> Path:
    """The restoring force and the lines' end tensions against the offset.

    Arguments:
        curve: the curve (:func:`offset_curve`).
        path: the PNG file to write.

    Returns:
        The path written.
    """
    from matplotlib.figure import Figure

    from vinculo.plotting import _save

    figure = Figure(figsize=(10, 6.5), layout="constrained")
    top, bottom = figure.subplots(2, 1, sharex=True)
    top.plot(curve.offsets, curve.restoring / 1e3, "o-")
    top.axhline(0.0, color="0.6", lw=0.8)
    top.set_ylabel("restoring moment (kN m)" if curve.rotation else "restoring force (kN)")
    d = curve.direction
    what = "rotations about" if curve.rotation else "offsets along"
    top.set_title(f"{what} ({d[0]:.3g}, {d[1]:.3g}, {d[2]:.3g}) of points "
                  f"{', '.join(map(str, curve.points))}")
    for k, line in enumerate(curve.lines):
        bottom.plot(curve.offsets, curve.end_tensions[:, k, 1] / 1e3, label=f"line {line}, end B")
        bottom.plot(curve.offsets, curve.end_tensions[:, k, 0] / 1e3, "--",
                    label=f"line {line}, end A")
    bottom.set_xlabel("angle (deg)" if curve.rotation else "offset (m)")
    bottom.set_ylabel("tension (kN)")
    bottom.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize="small")
    return _save(figure, path)
