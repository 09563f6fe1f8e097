"""A steady current that varies with depth: MoorDyn-C's ``Currents 1`` and its
``current_profile.txt``.

The file, in the input file's folder, holds three header lines, then one line per height
``z ux uy uz`` (m, m/s; z negative below the still-water level, increasing down the file)::

    --------------------- MoorDyn steady currents File ----------------------------------
    Tabulated file with the water currents components
    z (m), ux (m/s), uy (m/s), uz (m/s)
    -10.0 1.25 0 0
    -1.0 0.0 0 0
    0.0 0.0 0 0

The current is linear in z between the heights and keeps the nearest one's value beyond them
(MoorDyn's interpolation; :meth:`vinculo.ocean.Current.table`). The lines' drag acts on their
velocity relative to it (``docs/theory/seabed-and-line-loads.md``, line hydrodynamics).
:func:`read_current_profile` reads such a file (a row that is not four numbers, or heights that
do not increase, is an error naming the file, the line and the field).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from vinculo.errors import InvalidInputError, MooringFileError
from vinculo.mooring._table_file import numbers, read_lines, write_lines

__all__ = ["PROFILE_FILE", "CurrentProfile", "read_current_profile"]

#: The file MoorDyn reads the profile of ``Currents 1`` from, in the input file's folder.
PROFILE_FILE = "current_profile.txt"


@dataclass(frozen=True, eq=False)
class CurrentProfile:
    """A steady current's velocity at increasing heights.

    Arguments:
        heights: the heights z (m), strictly increasing.
        velocities: ``(n, 3)`` velocities (m/s), one per height.
        path: the file it was read from (None when built in code).

    Raises:
        InvalidInputError: for heights that are not finite and increasing, or velocities of
            another shape or not finite.
    """

    heights: np.ndarray
    velocities: np.ndarray
    path: Path | None = None

    def __post_init__(self) -> None:
        z = np.ascontiguousarray(self.heights, dtype=float).reshape(-1)
        u = np.ascontiguousarray(self.velocities, dtype=float)
        if z.size == 0 or u.shape != (z.size, 3):
            raise InvalidInputError(
                f"a current profile of {z.size} heights and velocities of shape {u.shape}: "
                f"give one (ux, uy, uz) per height", name="velocities", value=u.shape)
        if not (np.all(np.isfinite(z)) and np.all(np.isfinite(u))):
            raise InvalidInputError("a current profile's heights and velocities must be finite",
                                    name="heights", value=None)
        if np.any(np.diff(z) <= 0.0):
            raise InvalidInputError("a current profile's heights must increase",
                                    name="heights", value=z.tolist())
        object.__setattr__(self, "heights", z)
        object.__setattr__(self, "velocities", u)

    def __eq__(self, other: object) -> bool:
        """The same heights and velocities (wherever they were read from)."""
        if not isinstance(other, CurrentProfile):
            return NotImplemented
        return (np.array_equal(self.heights, other.heights)
                and np.array_equal(self.velocities, other.velocities))

    __hash__ = None  # type: ignore[assignment]

    def velocity(self, z: Any) -> np.ndarray:
        """The current's velocity at the heights ``z`` (m/s; shape ``z.shape + (3,)``)."""
        z = np.asarray(z, dtype=float)
        return np.stack([np.interp(z, self.heights, self.velocities[:, k]) for k in range(3)],
                        axis=-1)

    def write(self, path: str | Path) -> Path:
        """Write the profile in MoorDyn's format (module documentation).

        Arguments:
            path: the file to write (replaced if it exists).

        Returns:
            The path written.
        """
        rows = ["--------------------- MoorDyn steady currents File ---------------------",
                "Tabulated file with the water currents components (written by vinculo)",
                "z (m), ux (m/s), uy (m/s), uz (m/s)"]
        rows += [" ".join(repr(float(v)) for v in (z, *u))
                 for z, u in zip(self.heights, self.velocities, strict=True)]
        return write_lines(path, rows)


def read_current_profile(path: str | Path) -> CurrentProfile:
    """Read a ``current_profile.txt`` (module documentation).

    Arguments:
        path: the file.

    Returns:
        The profile.

    Raises:
        MooringFileError: when the file cannot be read or is malformed: the message names the
            file, the line and the field.
    """
    path = Path(path)
    name = str(path)
    lines = read_lines(path, "current profile")
    heights, velocities = [], []
    for number, text in enumerate(lines[3:], start=4):
        fields = text.split()
        if not fields:
            continue
        if len(fields) != 4:
            raise MooringFileError(
                f"{name}, line {number}: z ux uy uz: {len(fields)} values; give the height "
                f"and the three components of the current there", file=name, line=number,
                field="z ux uy uz", value=text.strip())
        values = numbers(name, number, fields, ("z", "ux", "uy", "uz"))
        if heights and values[0] <= heights[-1][0]:
            raise MooringFileError(
                f"{name}, line {number}: z: {fields[0]} is not above the height before it "
                f"({heights[-1][0]:g}, line {heights[-1][1]}); give increasing heights",
                file=name, line=number, field="z", value=values[0])
        heights.append((values[0], number))
        velocities.append(values[1:])
    if not heights:
        raise MooringFileError(f"{name}: no heights after the three header lines", file=name,
                               line=None, field="z ux uy uz", value=None)
    return CurrentProfile(np.array([h for h, _ in heights]), np.array(velocities), path=path)
