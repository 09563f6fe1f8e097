"""A seabed of varying height: MoorDyn's 3D seafloor (the ``SeafloorFile`` option).

The seabed's height z_b(x, y) (m, negative below the still water level) is given on a grid of
x and y ticks and is bilinear in each cell; beyond the grid it keeps the height of the grid's
edge. The line nodes' seabed contact is MoorDyn's: vertical, with the penetration
z_b(x, y) - z (``docs/theory/seabed-and-line-loads.md``).

MoorDyn-C's file format (its ``SeafloorFile`` option): the first line holds the numbers of
ticks ``nx ny``, the second the ``nx`` x ticks, the third the ``ny`` y ticks, then one line
``x y z`` for each grid point (any order), z the seabed's height there::

    3 2
    -100.0 0.0 100.0
    -50.0 50.0
    -100.0 -50.0 -60.0
    ...

MoorDyn-F's bathymetry file (given as its ``WtrDpth``): a title line, ``nGridX nx``,
``nGridY ny``, a line of the ``nx`` x ticks, then ``ny`` lines each of a y tick and the
``nx`` water depths along it (positive down: z = -depth)::

    ----- MoorDyn Bathymetry Input File ----
    nGridX 2
    nGridY 2
           -1500 900
    -1200   1000 700
     1200   1000 700

:func:`read_seafloor` reads either (every grid point once; a line whose x or y is not a tick, a
missing or repeated point, or a value that is not a number is an error naming the file, the
line and the field); :meth:`Seafloor.write` writes MoorDyn-C's.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from vinculo.errors import InvalidInputError, MooringFileError
from vinculo.mooring._table_file import numbers, read_lines, write_lines

__all__ = ["Seafloor", "read_seafloor"]


@dataclass(frozen=True, eq=False)
class Seafloor:
    """Heights of the seabed on a grid (MoorDyn's 3D seafloor).

    Arguments:
        x: the ``nx`` x ticks (m), strictly increasing.
        y: the ``ny`` y ticks (m), strictly increasing.
        z: the ``(nx, ny)`` heights of the seabed at the grid points (m).
        path: the file it was read from (None when built in code).
        layout: the file's layout, ``"C"`` (MoorDyn-C's SeafloorFile) or ``"F"`` (MoorDyn-F's
            bathymetry file).

    Raises:
        InvalidInputError: for ticks that are not finite and strictly increasing, heights of
            another shape, or a height that is not finite.
    """

    x: np.ndarray
    y: np.ndarray
    z: np.ndarray
    path: Path | None = None
    layout: str = "C"
    _core: Any = field(default=None, init=False, repr=False)

    def __post_init__(self) -> None:
        from vinculo import _core

        x = np.ascontiguousarray(self.x, dtype=float).reshape(-1)
        y = np.ascontiguousarray(self.y, dtype=float).reshape(-1)
        z = np.ascontiguousarray(self.z, dtype=float)
        if z.shape != (x.size, y.size):
            raise InvalidInputError(
                f"seafloor heights of shape {z.shape}: give ({x.size}, {y.size}) heights, one "
                f"for each pair of x and y ticks", name="z", value=z.shape)
        object.__setattr__(self, "x", x)
        object.__setattr__(self, "y", y)
        object.__setattr__(self, "z", z)
        object.__setattr__(self, "_core", _core.SeabedGrid(x, y, z))

    def __eq__(self, other: object) -> bool:
        """The same ticks and heights (wherever they were read from)."""
        if not isinstance(other, Seafloor):
            return NotImplemented
        return (np.array_equal(self.x, other.x) and np.array_equal(self.y, other.y)
                and np.array_equal(self.z, other.z))

    __hash__ = None  # type: ignore[assignment]

    @classmethod
    def from_function(cls, x: Any, y: Any, height: Callable[[np.ndarray, np.ndarray], Any]
                      ) -> Seafloor:
        """The grid of ticks ``x`` and ``y`` with the heights ``height(X, Y)`` at its points.

        Arguments:
            x: the x ticks (m).
            y: the y ticks (m).
            height: a function of the grid points' coordinates (arrays of shape (nx, ny)).

        Returns:
            The seafloor.
        """
        gx, gy = np.meshgrid(np.asarray(x, dtype=float), np.asarray(y, dtype=float),
                             indexing="ij")
        return cls(x=gx[:, 0], y=gy[0, :], z=np.broadcast_to(height(gx, gy), gx.shape))

    @property
    def core(self) -> Any:
        """The core's grid (``vinculo._core.SeabedGrid``), shared by the nodes' contacts."""
        return self._core

    def height(self, x: Any, y: Any) -> np.ndarray:
        """The seabed's height z_b at the points (x, y) (m; arrays of one shape).

        Arguments:
            x: x coordinates (m).
            y: y coordinates (m).

        Returns:
            The heights, of the points' shape.
        """
        xa, ya = np.broadcast_arrays(np.asarray(x, dtype=float), np.asarray(y, dtype=float))
        values = self._core.heights_at(xa.reshape(-1).tolist(), ya.reshape(-1).tolist())
        return np.asarray(values, dtype=float).reshape(xa.shape)

    def slope(self, x: float, y: float) -> tuple[float, float]:
        """The slopes dz_b/dx and dz_b/dy at (x, y) (those of the cell on the far side of a
        grid line; zero beyond the grid)."""
        _, sx, sy = self._core.height_and_slope(float(x), float(y))
        return float(sx), float(sy)

    @property
    def mean_depth(self) -> float:
        """Minus the mean of the grid's heights (m): MoorDyn's average water depth."""
        return -float(np.mean(self.z))

    def write(self, path: str | Path) -> Path:
        """Write the grid in MoorDyn's format (module documentation).

        Arguments:
            path: the file to write (replaced if it exists).

        Returns:
            The path written.
        """
        rows = [f"{self.x.size} {self.y.size}",
                " ".join(repr(float(v)) for v in self.x),
                " ".join(repr(float(v)) for v in self.y)]
        rows += [f"{float(a)!r} {float(b)!r} {float(self.z[i, j])!r}"
                 for i, a in enumerate(self.x) for j, b in enumerate(self.y)]
        return write_lines(path, rows)


def _tick(ticks: np.ndarray, value: float) -> int | None:
    """The index of the tick ``value`` is (within 1e-9 of the grid's extent), None if none."""
    k = int(np.argmin(np.abs(ticks - value)))
    span = float(ticks[-1] - ticks[0]) if ticks.size > 1 else 1.0
    return k if abs(ticks[k] - value) <= 1e-9 * max(span, 1.0) else None


def read_seafloor(path: str | Path) -> Seafloor:
    """Read a seafloor file in MoorDyn's format (module documentation).

    Arguments:
        path: the file.

    Returns:
        The seafloor.

    Raises:
        MooringFileError: when the file cannot be read or is malformed: the message names the
            file, the line and the field.
    """
    path = Path(path)
    name = str(path)
    lines = read_lines(path, "seafloor file")
    rows = [(k + 1, ln.split()) for k, ln in enumerate(lines) if ln.strip()]
    heading = next((k for k, (_, fields) in enumerate(rows[:3])
                    if fields[0].lower() == "ngridx"), None)
    if heading is not None:
        return _read_bathymetry(path, rows[heading:])
    if len(rows) < 4:
        raise MooringFileError(
            f"{name}: a seafloor file holds 'nx ny', the x ticks, the y ticks and a line "
            f"'x y z' for each grid point; it has {len(rows)} lines", file=name, line=None,
            field="nx ny", value=len(rows))
    number, head = rows[0]
    counts = numbers(name, number, head[:2], ["nx ny"]) if len(head) >= 2 else []
    if len(counts) != 2 or any(c < 1 or c != int(c) for c in counts):
        raise MooringFileError(
            f"{name}, line {number}: nx ny: {' '.join(head)!r}: give the numbers of x and y "
            f"ticks (integers >= 1)", file=name, line=number, field="nx ny",
            value=" ".join(head))
    nx, ny = int(counts[0]), int(counts[1])
    ticks = []
    for (number, fields), axis, n in ((rows[1], "x", nx), (rows[2], "y", ny)):
        if len(fields) != n:
            raise MooringFileError(
                f"{name}, line {number}: {axis} ticks: {len(fields)} values where line 1 says "
                f"{n}", file=name, line=number, field=f"{axis} ticks", value=len(fields))
        values = np.array(numbers(name, number, fields, [f"{axis} tick"]))
        if np.any(np.diff(values) <= 0.0):
            k = int(np.argmax(np.diff(values) <= 0.0))
            raise MooringFileError(
                f"{name}, line {number}: {axis} tick {k + 2}: {fields[k + 1]!r} is not above "
                f"the tick before it ({fields[k]}); give increasing ticks", file=name,
                line=number, field=f"{axis} tick", value=fields[k + 1])
        ticks.append(values)
    x, y = ticks
    z = np.full((nx, ny), np.nan)
    seen: dict[tuple[int, int], int] = {}
    for number, fields in rows[3:]:
        if len(fields) != 3:
            raise MooringFileError(
                f"{name}, line {number}: x y z: {len(fields)} values; give the point's x, y "
                f"and the seabed's height z", file=name, line=number, field="x y z",
                value=" ".join(fields))
        a, b, height = numbers(name, number, fields, ["x y z"])
        i, j = _tick(x, a), _tick(y, b)
        for axis, index, value in (("x", i, a), ("y", j, b)):
            if index is None:
                raise MooringFileError(
                    f"{name}, line {number}: {axis}: {value!r} is not one of the {axis} ticks "
                    f"of line {2 if axis == 'x' else 3}", file=name, line=number, field=axis,
                    value=value)
        assert i is not None and j is not None
        if (i, j) in seen:
            raise MooringFileError(
                f"{name}, line {number}: x y: the point ({a:g}, {b:g}) is given a second time "
                f"(first on line {seen[(i, j)]})", file=name, line=number, field="x y",
                value=(a, b))
        seen[(i, j)] = number
        z[i, j] = height
    if len(seen) < nx * ny:
        i, j = (int(k[0]) for k in np.nonzero(np.isnan(z)))
        raise MooringFileError(
            f"{name}: x y: the grid has {nx} x {ny} points and the file gives {len(seen)}; "
            f"the first one missing is ({x[i]:g}, {y[j]:g})", file=name, line=None,
            field="x y", value=(float(x[i]), float(y[j])))
    try:
        return Seafloor(x=x, y=y, z=z, path=path)
    except InvalidInputError as exc:  # pragma: no cover - the checks above come first
        raise MooringFileError(f"{name}: {exc}", file=name, line=None, field=None,
                               value=None) from None


def _read_bathymetry(path: Path, rows: list[tuple[int, list[str]]]) -> Seafloor:
    """MoorDyn-F's bathymetry file from its ``nGridX`` line on (module documentation)."""
    name = str(path)
    counts = []
    for k, key in enumerate(("nGridX", "nGridY")):
        if len(rows) <= k or rows[k][1][0].lower() != key.lower() or len(rows[k][1]) < 2:
            number = rows[k][0] if len(rows) > k else None
            raise MooringFileError(
                f"{name}{f', line {number}' if number else ''}: {key}: give '{key} n', the "
                f"number of grid lines", file=name, line=number, field=key, value=None)
        number, fields = rows[k]
        value = numbers(name, number, fields[1:2], [key])[0]
        if value < 1 or value != int(value):
            raise MooringFileError(f"{name}, line {number}: {key}: {fields[1]!r}: give an "
                                   f"integer >= 1", file=name, line=number, field=key,
                                   value=fields[1])
        counts.append(int(value))
    nx, ny = counts
    if len(rows) != 3 + ny:
        raise MooringFileError(
            f"{name}: the x ticks and {ny} rows of a y tick and {nx} depths: the file has "
            f"{len(rows) - 2} lines after nGridY", file=name, line=None, field="nGridY",
            value=len(rows) - 2)
    number, fields = rows[2]
    if len(fields) != nx:
        raise MooringFileError(f"{name}, line {number}: x ticks: {len(fields)} values where "
                               f"nGridX says {nx}", file=name, line=number, field="x ticks",
                               value=len(fields))
    x = np.array(numbers(name, number, fields, ["x tick"]))
    y, depths = [], []
    for number, fields in rows[3:]:
        if len(fields) != nx + 1:
            raise MooringFileError(
                f"{name}, line {number}: y depths: {len(fields)} values; give the y tick and "
                f"the {nx} depths along it", file=name, line=number, field="y depths",
                value=len(fields))
        values = numbers(name, number, fields, ["y depths"])
        y.append(values[0])
        depths.append(values[1:])
    for axis, ticks, number in (("x", x, rows[2][0]), ("y", np.array(y), rows[3][0])):
        if np.any(np.diff(ticks) <= 0.0):
            raise MooringFileError(
                f"{name}, line {number}: {axis} ticks: give increasing ticks", file=name,
                line=number, field=f"{axis} ticks", value=ticks.tolist())
    # Depths are positive down: the seabed's height is -depth; z[i, j] at (x[i], y[j]).
    return Seafloor(x=x, y=np.array(y), z=-np.array(depths).T, path=path, layout="F")
