"""The prescribed motion of a mooring's coupled (Vessel/Coupled) points.

A :class:`Motion` gives each coupled point's x, y and z as a vinculo :class:`~vinculo.Law` of
time, so that the vinculo run and the peer run (MoorDyn) see exactly the same motion: vinculo
prescribes the points' coordinates with the laws, and the peer runner evaluates the same laws
(value and rate) to feed MoorDyn.

A motion file is a CSV table with a header line and the columns ``time`` (s), then ``x``, ``y``,
``z`` (m) of each coupled point in the order of the file's POINTS section::

    time,x1,y1,z1,x2,y2,z2
    0.0,0.0,0.0,-10.0,50.0,0.0,-10.0
    0.1,0.01,0.0,-10.0,50.01,0.0,-10.0

Each column becomes a natural cubic spline (:func:`vinculo.tabulated`), twice continuously
differentiable, so the points' velocities and accelerations are continuous.

A file with Coupled bodies (BODIES) moves each body in six degrees of freedom: its columns come
first, in the order of the BODIES section, ``x, y, z`` of the body's reference point (m) and its
``roll, pitch, yaw`` (degrees, composed as the file's r0 p0 y0 are), then ``x, y, z`` of each
coupled point that is not on a body (:func:`read_motion`; MoorDyn's order of coupled degrees of
freedom). The points of a body follow it rigidly: at each row they are placed by its pose, and
their coordinates become the splines, through those exact positions.
"""

from __future__ import annotations

import csv
import dataclasses
import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from vinculo import laws
from vinculo._core import Law
from vinculo.errors import InvalidInputError

__all__ = ["Motion", "read_motion", "still_motion"]


class Motion:
    """The positions of ``n`` coupled points as laws of time.

    Arguments:
        laws: one ``(x, y, z)`` triple of :class:`~vinculo.Law` per point (or plain numbers for
            a coordinate that does not move).
        source: where the motion came from (a file name), for messages.

    Raises:
        InvalidInputError: when a point does not have three coordinates.
    """

    def __init__(self, laws: Sequence[Sequence[Law | float]], source: str = "the motion"
                 ) -> None:
        triples = []
        for k, triple in enumerate(laws):
            if len(triple) != 3:
                raise InvalidInputError(
                    f"{source}: point {k + 1} has {len(triple)} coordinates; give x, y, z",
                    name="laws", value=len(triple))
            triples.append(tuple(_law(c) for c in triple))
        self._laws: list[tuple[Law, Law, Law]] = triples
        self.source = source
        #: Coupled bodies' poses, six laws each (x, y, z in m; roll, pitch, yaw in degrees), in
        #: the order of the file's coupled bodies (:func:`read_motion`); empty without bodies.
        self.poses: list[tuple[Law, ...]] = []
        #: The indices, among the points, of the coupled points that are not on a body.
        self.own: list[int] = list(range(len(triples)))

    def coupled_dofs(self, t: float) -> np.ndarray:
        """MoorDyn's coupled degrees of freedom at time ``t``: each coupled body's x, y, z (m)
        and roll, pitch, yaw (rad), then each other coupled point's x, y, z (m).

        Arguments:
            t: time (s).

        Returns:
            The flat array.
        """
        return self._dofs(t, rates=False)

    def coupled_dof_rates(self, t: float) -> np.ndarray:
        """The rates of :meth:`coupled_dofs` at time ``t`` (m/s; the angles' in rad/s).

        Arguments:
            t: time (s).

        Returns:
            The flat array.
        """
        return self._dofs(t, rates=True)

    def _dofs(self, t: float, rates: bool) -> np.ndarray:
        """:meth:`coupled_dofs`, or their rates."""
        def value(law: Law) -> float:
            return law.derivatives(t)[1] if rates else law(t)

        poses = [[value(law) for law in pose] for pose in self.poses]
        dofs = [v for pose in poses for v in (*pose[:3], *map(math.radians, pose[3:]))]
        points = self.velocities(t) if rates else self.positions(t)
        own = points[self.own].ravel() if self.own else np.empty(0)
        return np.concatenate([np.asarray(dofs, dtype=float), own])

    @property
    def laws(self) -> list[tuple[Law, Law, Law]]:
        """The ``(x, y, z)`` laws of each point."""
        return list(self._laws)

    @property
    def num_points(self) -> int:
        """The number of points moved."""
        return len(self._laws)

    def domain(self) -> tuple[float, float]:
        """The times on which every law is defined.

        Returns:
            ``(start, end)`` in s (infinite for laws defined at all times).
        """
        start, end = -math.inf, math.inf
        for triple in self._laws:
            for law in triple:
                low, high = law.domain()
                start, end = max(start, low), min(end, high)
        return start, end

    def positions(self, t: float) -> np.ndarray:
        """The points' positions at time ``t``.

        Arguments:
            t: time (s).

        Returns:
            An ``(n, 3)`` array (m).
        """
        return np.array([[law(t) for law in triple] for triple in self._laws]).reshape(-1, 3)

    def velocities(self, t: float) -> np.ndarray:
        """The points' velocities at time ``t``.

        Arguments:
            t: time (s).

        Returns:
            An ``(n, 3)`` array (m/s).
        """
        return np.array(
            [[law.derivatives(t)[1] for law in triple] for triple in self._laws]
        ).reshape(-1, 3)

    @classmethod
    def still(cls, positions: np.ndarray | Sequence[Sequence[float]]) -> Motion:
        """Points that stay where they are.

        Arguments:
            positions: ``(n, 3)`` positions (m).

        Returns:
            The motion.
        """
        array = np.asarray(positions, dtype=float).reshape(-1, 3)
        return cls([[float(c) for c in row] for row in array], source="still points")

    @classmethod
    def harmonic(cls, positions: np.ndarray | Sequence[Sequence[float]],
                 amplitude: Sequence[float], period: float, ramp_time: float = 0.0
                 ) -> Motion:
        """Every point oscillating about its position with the same amplitude and period.

        Arguments:
            positions: ``(n, 3)`` mean positions (m).
            amplitude: the amplitude of x, y, z (m).
            period: the period (s, > 0).
            ramp_time: the duration of the smooth start (s; see :func:`vinculo.sine`).

        Returns:
            The motion ``p0 + a s(t) sin(2 pi t / period)``.

        Raises:
            InvalidInputError: for a period that is not positive.
        """
        if not (math.isfinite(period) and period > 0.0):
            raise InvalidInputError(f"Motion.harmonic: period = {period!r}; give a period > 0 s",
                                    name="period", value=period)
        array = np.asarray(positions, dtype=float).reshape(-1, 3)
        triples = []
        for row in array:
            triples.append([
                laws.sine(a, 1.0 / period, offset=p, ramp_time=ramp_time) if a != 0.0 else p
                for p, a in zip(row, amplitude, strict=True)
            ])
        return cls(triples, source=f"harmonic motion (period {period:g} s)")

    @classmethod
    def from_table(cls, times: Sequence[float] | np.ndarray, positions: np.ndarray,
                   source: str = "the motion table") -> Motion:
        """A recorded motion: natural cubic splines through samples.

        Arguments:
            times: strictly increasing sample times (s).
            positions: ``(len(times), n, 3)`` or ``(len(times), 3 n)`` samples (m).
            source: where the samples came from, for messages.

        Returns:
            The motion.

        Raises:
            InvalidInputError: for mismatched shapes, fewer than two samples or unsorted times.
        """
        t = np.asarray(times, dtype=float)
        p = np.asarray(positions, dtype=float)
        if p.ndim == 2 and p.shape[1] % 3 == 0:
            p = p.reshape(p.shape[0], -1, 3)
        if p.ndim != 3 or p.shape[0] != t.size or p.shape[2] != 3:
            raise InvalidInputError(
                f"{source}: positions of shape {np.shape(positions)} do not match "
                f"{t.size} times; give (times, points, 3)", name="positions",
                value=np.shape(positions))
        try:
            triples = [[laws.tabulated(t, p[:, k, c]) for c in range(3)]
                       for k in range(p.shape[1])]
        except InvalidInputError as exc:
            raise InvalidInputError(f"{source}: {exc}", name="times", value=None) from None
        return cls(triples, source=source)

    @classmethod
    def from_csv(cls, path: str | Path) -> Motion:
        """Read a motion file (see the module's description).

        Arguments:
            path: the CSV file: a header line, then ``time, x1, y1, z1, x2, ...`` rows.

        Returns:
            The motion.

        Raises:
            InvalidInputError: when the file cannot be read, a value is not a number, the
                number of columns is not 1 + 3 n, or the times are not increasing; the message
                names the file and the row.
        """
        path = Path(path)
        header, values = _read_table(path)
        columns = len(header)
        if columns < 4 or (columns - 1) % 3 != 0:
            raise InvalidInputError(
                f"{path}: the header has {columns} columns; give time, then x, y, z of each "
                f"coupled point (1 + 3 n columns)", name="motion", value=columns)
        return cls.from_table(values[:, 0], values[:, 1:], source=str(path))

    def to_csv(self, path: str | Path, times: Sequence[float] | np.ndarray) -> Path:
        """Write the motion sampled at ``times`` as a motion file.

        Arguments:
            path: the CSV file to write.
            times: the sample times (s).

        Returns:
            The path written.
        """
        path = Path(path)
        header = ["time"] + [f"{c}{k + 1}" for k in range(self.num_points) for c in "xyz"]
        with path.open("w", newline="", encoding="utf-8") as handle:
            writer = csv.writer(handle)
            writer.writerow(header)
            for t in np.asarray(times, dtype=float):
                writer.writerow([repr(float(t))] + [repr(float(v))
                                                     for v in self.positions(t).ravel()])
        return path


def _read_table(path: Path) -> tuple[list[str], np.ndarray]:
    """The header and the numbers of a motion file, its rows complete, finite and in
    increasing time (the errors name the file and the row)."""
    try:
        with path.open(newline="", encoding="utf-8") as handle:
            rows = [row for row in csv.reader(handle) if row and any(c.strip() for c in row)]
    except OSError as exc:
        raise InvalidInputError(f"cannot read the motion file {str(path)!r}: {exc.strerror}",
                                name="motion", value=str(path)) from None
    if len(rows) < 3:
        raise InvalidInputError(
            f"{path}: a motion file needs a header line and at least two rows of time, "
            f"x, y, z per coupled point", name="motion", value=str(path))
    header, body = rows[0], rows[1:]
    columns = len(header)
    values = np.empty((len(body), columns))
    for r, row in enumerate(body, start=2):
        if len(row) != columns:
            raise InvalidInputError(
                f"{path}, row {r}: {len(row)} values where the header has {columns}",
                name="motion", value=len(row))
        for c, text in enumerate(row):
            try:
                values[r - 2, c] = float(text)
            except ValueError:
                raise InvalidInputError(
                    f"{path}, row {r}, column {header[c].strip()!r}: {text!r} is not a "
                    f"number", name="motion", value=text) from None
    if not np.all(np.isfinite(values)):
        raise InvalidInputError(f"{path}: the motion has values that are not finite",
                                name="motion", value=str(path))
    if np.any(np.diff(values[:, 0]) <= 0.0):
        r = int(np.argmax(np.diff(values[:, 0]) <= 0.0)) + 3
        raise InvalidInputError(f"{path}, row {r}: the times must increase",
                                name="motion", value=float(values[r - 2, 0]))
    return header, values


def read_motion(model: Any, path: str | Path) -> Motion:
    """Read the motion file of a MoorDyn file's coupled bodies and points (module
    description): the motion of every coupled point, a body's points placed by its pose.

    Arguments:
        model: the :class:`~vinculo.mooring.moordyn_file.MoorDynFile`.
        path: the CSV file: a header line, then ``time``, ``x, y, z, roll, pitch, yaw`` of each
            coupled body (m, degrees), ``x, y, z`` of each coupled point not on a body (m).

    Returns:
        The motion of the coupled points (:meth:`MoorDynFile.coupled_points`'s order).

    Raises:
        InvalidInputError: as :meth:`Motion.from_csv`, and for a number of columns that does
            not match the file's coupled bodies and points.
    """
    path = Path(path)
    bodies = model.coupled_bodies()
    if not bodies:
        return Motion.from_csv(path)
    header, values = _read_table(path)
    coupled = model.coupled_points()
    own = [k for k, point in enumerate(coupled) if point.body is None]
    expected = 1 + 6 * len(bodies) + 3 * len(own)
    if len(header) != expected:
        raise InvalidInputError(
            f"{path}: the header has {len(header)} columns; the file has {len(bodies)} coupled "
            f"bodies and {len(own)} coupled points of their own: give time, then x, y, z, "
            f"roll, pitch, yaw (m, degrees) of each body, then x, y, z of each point "
            f"({expected} columns)", name="motion", value=len(header))
    times = values[:, 0]
    poses = values[:, 1:1 + 6 * len(bodies)].reshape(len(times), len(bodies), 6)
    positions = np.empty((len(times), len(coupled), 3))
    positions[:, own] = values[:, 1 + 6 * len(bodies):].reshape(len(times), len(own), 3)
    for b, body in enumerate(bodies):
        on = [k for k, point in enumerate(coupled) if point.body == body.id]
        arms = [coupled[k].relative for k in on]
        for r, pose in enumerate(poses[:, b]):
            moved = dataclasses.replace(body, position=tuple(pose[:3]),
                                        rotation=tuple(pose[3:]))
            positions[r, on] = moved.place_all(arms)
    motion = Motion.from_table(times, positions, source=str(path))
    return _with_poses(motion, [[laws.tabulated(times, poses[:, b, j]) for j in range(6)]
                                for b in range(len(bodies))], own)


def still_motion(model: Any) -> Motion:
    """The coupled points and bodies of a MoorDyn file where the file puts them, at rest.

    Arguments:
        model: the :class:`~vinculo.mooring.moordyn_file.MoorDynFile`.

    Returns:
        The motion (with the bodies' poses, as :func:`read_motion`'s).
    """
    coupled = model.coupled_points()
    motion = Motion.still([p.position for p in coupled])
    poses = [[laws.constant(v) for v in (*b.position, *b.rotation)]
             for b in model.coupled_bodies()]
    return _with_poses(motion, poses, [k for k, p in enumerate(coupled) if p.body is None])


def _with_poses(motion: Motion, poses: Sequence[Sequence[Law]], own: list[int]) -> Motion:
    """``motion`` with the coupled bodies' pose laws and the indices of the points not on a
    body (:attr:`Motion.poses`, :attr:`Motion.own`)."""
    motion.poses = [tuple(pose) for pose in poses]
    motion.own = own
    return motion


def _law(value: Law | float) -> Law:
    if isinstance(value, Law):
        return value
    return laws.constant(float(value))
