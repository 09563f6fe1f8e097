"""Linear waves summed from their components: MoorDyn-C's ``WaveKin 7`` and its
``wave_frequencies.txt``.

The file, beside the input file, holds one line per component, ``omega re im [beta]``: the
angular frequency (rad/s), the real and imaginary parts of its complex amplitude (m) and its
direction of travel (rad from x towards y; 0 when left out). MoorDyn's surface is

    eta(x, y, t) = sum |A| sin(omega t - k (x cos beta + y sin beta) + arg A),

with k from the dispersion relation at the water depth, the linear (Airy) flow below it and
Wheeler's stretching above the still-water level; that is vinculo's sea
(``docs/theory/ocean.md``, eta = a cos(k e.x - omega t + eps)) with a = |A| and
eps = pi/2 - arg A. A component of zero frequency (MoorDyn's spectra start with one) must have
no amplitude. MoorDyn ramps the waves up linearly over ``waveKin_rampT``; vinculo's ramp over
the same time is a half cosine (the same waves once it is over).
:func:`read_wave_frequencies` reads such a file (a row that is not three or four numbers, or a
negative frequency, is an error naming the file, the line and the field).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from vinculo.errors import InvalidInputError, MooringFileError
from vinculo.mooring._table_file import numbers, read_lines, write_lines

__all__ = ["WAVE_FILE", "WaveComponents", "read_wave_frequencies"]

#: The file MoorDyn reads the components of ``WaveKin 7`` from, beside the input file.
WAVE_FILE = "wave_frequencies.txt"


@dataclass(frozen=True, eq=False)
class WaveComponents:
    """Wave components: angular frequencies, complex amplitudes and directions.

    Arguments:
        omegas: the angular frequencies (rad/s, > 0).
        amplitudes: the complex amplitudes A (m; MoorDyn's re + i im).
        directions: the directions of travel (rad).
        path: the file they were read from (None when built in code).

    Raises:
        InvalidInputError: for arrays of different lengths, values that are not finite, or a
            frequency that is not positive.
    """

    omegas: np.ndarray
    amplitudes: np.ndarray
    directions: np.ndarray
    path: Path | None = None

    def __post_init__(self) -> None:
        w = np.ascontiguousarray(self.omegas, dtype=float).reshape(-1)
        a = np.ascontiguousarray(self.amplitudes, dtype=complex).reshape(-1)
        b = np.ascontiguousarray(self.directions, dtype=float).reshape(-1)
        if not (w.size == a.size == b.size):
            raise InvalidInputError(
                f"wave components of {w.size} frequencies, {a.size} amplitudes and {b.size} "
                f"directions: give one of each per component", name="omegas", value=w.size)
        if not (np.all(np.isfinite(w)) and np.all(np.isfinite(a)) and np.all(np.isfinite(b))):
            raise InvalidInputError("wave components must be finite", name="omegas",
                                    value=None)
        if np.any(w <= 0.0):
            raise InvalidInputError("wave components' frequencies must be > 0 rad/s",
                                    name="omegas", value=w.tolist())
        object.__setattr__(self, "omegas", w)
        object.__setattr__(self, "amplitudes", a)
        object.__setattr__(self, "directions", b)

    def __eq__(self, other: object) -> bool:
        """The same components (wherever they were read from)."""
        if not isinstance(other, WaveComponents):
            return NotImplemented
        return (np.array_equal(self.omegas, other.omegas)
                and np.array_equal(self.amplitudes, other.amplitudes)
                and np.array_equal(self.directions, other.directions))

    __hash__ = None  # type: ignore[assignment]

    @property
    def phases(self) -> np.ndarray:
        """vinculo's phases eps = pi/2 - arg A (module documentation)."""
        return 0.5 * math.pi - np.angle(self.amplitudes)

    def write(self, path: str | Path) -> Path:
        """Write the components in MoorDyn's format (module documentation).

        Arguments:
            path: the file to write (replaced if it exists).

        Returns:
            The path written.
        """
        # A first component of zero frequency and amplitude, as MoorDyn's spectra start (it
        # asks for two rows at least).
        rows = ["0.0 0.0 0.0 0.0"]
        rows += [f"{float(w)!r} {float(a.real)!r} {float(a.imag)!r} {float(b)!r}"
                 for w, a, b in zip(self.omegas, self.amplitudes, self.directions, strict=True)]
        return write_lines(path, rows)


def read_wave_frequencies(path: str | Path) -> WaveComponents:
    """Read a ``wave_frequencies.txt`` (module documentation).

    Arguments:
        path: the file.

    Returns:
        The components (a zero frequency of zero amplitude left out).

    Raises:
        MooringFileError: when the file cannot be read or is malformed: the message names the
            file, the line and the field.
    """
    path = Path(path)
    name = str(path)
    lines = read_lines(path, "wave components")
    omegas, amplitudes, directions = [], [], []
    for number, text in enumerate(lines, start=1):
        fields = text.split("#", 1)[0].split()
        if not fields:
            continue
        if len(fields) not in (3, 4):
            raise MooringFileError(
                f"{name}, line {number}: omega re im [beta]: {len(fields)} values; give the "
                f"frequency, the amplitude's real and imaginary parts and optionally the "
                f"direction", file=name, line=number, field="omega re im [beta]",
                value=text.strip())
        values = numbers(name, number, fields, ("omega", "re", "im", "beta"))
        omega, amplitude = values[0], complex(values[1], values[2])
        if omega < 0.0 or (omega == 0.0 and amplitude != 0.0):
            raise MooringFileError(
                f"{name}, line {number}: omega: {fields[0]}: a wave component needs a "
                f"frequency > 0 (a zero frequency only with a zero amplitude)", file=name,
                line=number, field="omega", value=omega)
        if omega == 0.0:
            continue
        omegas.append(omega)
        amplitudes.append(amplitude)
        directions.append(values[3] if len(values) == 4 else 0.0)
    if not omegas:
        raise MooringFileError(f"{name}: no wave component of a frequency > 0", file=name,
                               line=None, field="omega re im [beta]", value=None)
    return WaveComponents(np.array(omegas), np.array(amplitudes), np.array(directions),
                          path=path)
