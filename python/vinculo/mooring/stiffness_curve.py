"""A line whose tension is a function of its strain: MoorDyn's nonlinear EA, a file name in the
EA column of a line type.

The file (beside the input file, or at the path given) holds three header lines, then one line
per point of the curve, ``strain tension`` (-, N), both increasing from (0, 0)::

    ----Polyester----
    Strain    Tension
    (-)       (N)
    0.0       0.0
    0.01      2.0e5
    0.03      9.0e5

Between the points the tension is linear in the strain; beyond the last point it continues
along the last piece (MoorDyn holds the last tension there, which no implicit step can solve),
below the first along the first; a segment shorter than its length is slack (no tension), as
MoorDyn's (``docs/theory/moorings.md``, "Nonlinear stiffness"). :func:`read_stiffness_curve`
reads such a file (a row that is not two numbers, or values that do not increase, is an error
naming the file, the line and the field).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from vinculo.errors import InvalidInputError, MooringFileError
from vinculo.mooring._table_file import numbers, read_lines, write_lines

__all__ = ["StiffnessCurve", "read_stiffness_curve"]


@dataclass(frozen=True, eq=False)
class StiffnessCurve:
    """Tensions of a line at its strains (both increasing), linear between them.

    Arguments:
        strains: the strains (-).
        tensions: the tensions (N), one per strain.
        path: the file it was read from (None when built in code).

    Raises:
        InvalidInputError: for fewer than two points, values that are not finite, strains or
            tensions that do not increase, or a first point other than (0, 0).
    """

    strains: np.ndarray
    tensions: np.ndarray
    path: Path | None = None

    def __post_init__(self) -> None:
        e = np.ascontiguousarray(self.strains, dtype=float).reshape(-1)
        t = np.ascontiguousarray(self.tensions, dtype=float).reshape(-1)
        if e.size < 2 or e.size != t.size:
            raise InvalidInputError(
                f"a stiffness curve of {e.size} strains and {t.size} tensions: give at least "
                f"two points, a tension per strain", name="strains", value=e.size)
        if not (np.all(np.isfinite(e)) and np.all(np.isfinite(t))):
            raise InvalidInputError("a stiffness curve's strains and tensions must be finite",
                                    name="strains", value=None)
        for name, values in (("strains", e), ("tensions", t)):
            if np.any(np.diff(values) <= 0.0):
                raise InvalidInputError(f"a stiffness curve's {name} must increase",
                                        name=name, value=values.tolist())
        if e[0] != 0.0 or t[0] != 0.0:
            raise InvalidInputError(
                f"a stiffness curve starts at strain 0 and tension 0 (a segment at its length "
                f"has no tension), not ({e[0]:g}, {t[0]:g})", name="strains", value=e[0])
        object.__setattr__(self, "strains", e)
        object.__setattr__(self, "tensions", t)

    def __eq__(self, other: object) -> bool:
        """The same points (wherever they were read from)."""
        if not isinstance(other, StiffnessCurve):
            return NotImplemented
        return (np.array_equal(self.strains, other.strains)
                and np.array_equal(self.tensions, other.tensions))

    __hash__ = None  # type: ignore[assignment]

    def tension(self, strain: Any) -> np.ndarray:
        """The tension at ``strain`` (N): linear between the points, continued along the first
        and last pieces beyond them; no slack here (a segment is slack below zero strain)."""
        e = np.asarray(strain, dtype=float)
        k = np.clip(np.searchsorted(self.strains, e, side="right") - 1, 0,
                    self.strains.size - 2)
        e0, e1 = self.strains[k], self.strains[k + 1]
        t0, t1 = self.tensions[k], self.tensions[k + 1]
        return t0 + (t1 - t0) / (e1 - e0) * (e - e0)

    def strain(self, tension: Any) -> np.ndarray:
        """The strain at ``tension`` (the curve read the other way)."""
        t = np.asarray(tension, dtype=float)
        k = np.clip(np.searchsorted(self.tensions, t, side="right") - 1, 0,
                    self.tensions.size - 2)
        t0, t1 = self.tensions[k], self.tensions[k + 1]
        e0, e1 = self.strains[k], self.strains[k + 1]
        return e0 + (e1 - e0) / (t1 - t0) * (t - t0)

    @property
    def stiffest(self) -> float:
        """The largest slope dT/de of the curve (N): the EA that stands for it where one
        number must (an initial shape, the static solve's scales)."""
        return float(np.max(np.diff(self.tensions) / np.diff(self.strains)))

    def write(self, path: str | Path) -> Path:
        """Write the curve in MoorDyn's format (module documentation).

        Arguments:
            path: the file to write (replaced if it exists).

        Returns:
            The path written.
        """
        rows = ["---- tension-strain curve (written by vinculo) ----", "Strain    Tension",
                "(-)       (N)"]
        rows += [f"{float(e)!r} {float(t)!r}"
                 for e, t in zip(self.strains, self.tensions, strict=True)]
        # No newline after the last point: MoorDyn 2.7 reads an empty last line as a point.
        return write_lines(path, rows, final_newline=False)


def read_stiffness_curve(path: str | Path) -> StiffnessCurve:
    """Read a strain-tension file (module documentation).

    Arguments:
        path: the file.

    Returns:
        The curve.

    Raises:
        MooringFileError: when the file cannot be read or is malformed: the message names the
            file, the line and the field.
    """
    path = Path(path)
    name = str(path)
    lines = read_lines(path, "stiffness curve")
    points: list[tuple[float, float, int]] = []
    for number, text in enumerate(lines[3:], start=4):
        fields = text.split()
        if not fields:
            continue
        if len(fields) != 2:
            raise MooringFileError(
                f"{name}, line {number}: strain tension: {len(fields)} values; give a strain "
                f"and the tension there", file=name, line=number, field="strain tension",
                value=text.strip())
        values = numbers(name, number, fields, ("strain", "tension"))
        if points:
            for k, field in enumerate(("strain", "tension")):
                if values[k] <= points[-1][k]:
                    raise MooringFileError(
                        f"{name}, line {number}: {field}: {fields[k]} is not above the one "
                        f"before it (line {points[-1][2]}); give increasing strains and "
                        f"tensions", file=name, line=number, field=field, value=values[k])
        points.append((values[0], values[1], number))
    if len(points) < 2:
        raise MooringFileError(f"{name}: {len(points)} points after the three header lines; "
                               f"give at least two", file=name, line=None,
                               field="strain tension", value=len(points))
    if points[0][:2] != (0.0, 0.0):
        raise MooringFileError(
            f"{name}, line {points[0][2]}: strain tension: the curve starts at strain 0 and "
            f"tension 0 (a segment at its length has no tension; shorter, it is slack), not "
            f"({points[0][0]:g}, {points[0][1]:g})", file=name, line=points[0][2],
            field="strain tension", value=points[0][:2])
    return StiffnessCurve(np.array([p[0] for p in points]), np.array([p[1] for p in points]),
                          path=path)
