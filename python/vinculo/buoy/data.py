"""Reading measured amplitude and phase curves of the buoy from CSV.

vinculo ships no measurements: the user supplies them. The file has one row per excitation
frequency with three comma-separated columns:

- ``frequency``, in Hz (> 0);
- ``amplitude``, in m (>= 0), of the horizontal displacement of the buoy's centre;
- ``phase``, in degrees, in the convention of :data:`vinculo.buoy.harmonic.PHASE_CONVENTION`
  (phase lead of the buoy over the tank).

An optional header row names the columns (``frequency``, ``amplitude``, ``phase`` in any order,
any letter case; a unit in parentheses or brackets, as in ``frequency (Hz)``, is allowed; other
columns are ignored). Without a header the three columns come in that order. Anything after ``#``
on a line is a comment; blank lines are skipped::

    # buoy, run 3
    frequency (Hz), amplitude (m), phase (deg)
    0.5, 0.0015, 1.2
    0.6, 0.0019, 3.0
"""

from __future__ import annotations

import csv
import math
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from vinculo.errors import InvalidInputError

__all__ = ["COLUMNS", "MOTIONS", "Measurements", "read_measurements"]

#: The required columns, in their order when the file has no header.
COLUMNS = ("frequency", "amplitude", "phase")
#: What the measured amplitude and phase describe: the buoy's displacement in the laboratory, or
#: relative to the tank.
MOTIONS = ("absolute", "relative")

_UNIT = re.compile(r"\s*[\(\[].*[\)\]]\s*$")


@dataclass(frozen=True)
class Measurements:
    """Measured steady-state amplitude and phase over frequency.

    Attributes:
        frequency: excitation frequencies, in Hz, shape (n,), in file order.
        amplitude: amplitude of the buoy centre's horizontal displacement, in m.
        phase_deg: its phase lead over the tank, in degrees.
        motion: ``"absolute"`` (laboratory frame) or ``"relative"`` (to the tank).
        path: the file they were read from.
    """

    frequency: np.ndarray
    amplitude: np.ndarray
    phase_deg: np.ndarray
    motion: str
    path: str


def _error(message: str, path: Path, line: int | None) -> InvalidInputError:
    """An error about the data file, naming it (and the line, when there is one)."""
    where = f"{path}, line {line}" if line is not None else str(path)
    return InvalidInputError(f"{where}: {message}", name="data", path=str(path), line=line)


def _column_name(field: str) -> str:
    """A header field without its unit and case: ``"Frequency (Hz)"`` -> ``"frequency"``."""
    return _UNIT.sub("", field).strip().lower()


def read_measurements(path: str | Path, motion: str = "absolute") -> Measurements:
    """Read measured amplitude and phase curves from a CSV file (format in the module docstring).

    Arguments:
        path: the CSV file.
        motion: whether the file describes the ``"absolute"`` displacement of the buoy (in the
            laboratory) or the ``"relative"`` one (to the tank).

    Returns:
        The measurements, rows in file order.

    Raises:
        InvalidInputError: (``name="data"``, with ``path`` and ``line``, 1-based) if the file is
            missing or unreadable, a header lacks a required column, a row has the wrong number of
            fields or a value that is not a finite number (the message quotes the line), a
            frequency is not positive or an amplitude is negative, or there is no data row.
    """
    path = Path(path)
    if motion not in MOTIONS:
        raise InvalidInputError(
            f"motion must be one of {', '.join(map(repr, MOTIONS))}, got {motion!r}",
            name="motion",
            value=motion,
        )
    try:
        text = path.read_text(encoding="utf-8-sig")
    except FileNotFoundError:
        raise _error("no such measurement file; check the path", path, None) from None
    except (OSError, UnicodeDecodeError) as error:
        reason = getattr(error, "strerror", None) or str(error)
        raise _error(f"cannot read the measurement file: {reason}", path, None) from None

    columns: dict[str, int] | None = None
    width = len(COLUMNS)
    rows: list[tuple[float, float, float]] = []
    for number, raw in enumerate(text.splitlines(), start=1):
        content = raw.split("#", 1)[0]
        if not content.strip():
            continue
        fields = [field.strip() for field in next(csv.reader([content]))]
        if columns is None and not rows and not all(_is_number(field) for field in fields):
            names = [_column_name(field) for field in fields]
            missing = [name for name in COLUMNS if name not in names]
            if missing and any(_is_number(field) for field in fields):
                bad = next(field for field in fields if not _is_number(field))
                raise _error(
                    f"{bad!r} is not a number, and the line is no header (it lacks the "
                    f"column(s) {', '.join(missing)}): {raw.strip()!r}",
                    path,
                    number,
                )
            if missing:
                raise _error(
                    f"the header {raw.strip()!r} lacks the column(s) {', '.join(missing)}; name "
                    f"the columns {', '.join(COLUMNS)} (any order), or drop the header and give "
                    f"the three columns in that order",
                    path,
                    number,
                )
            columns = {name: names.index(name) for name in COLUMNS}
            width = len(fields)
            continue
        if len(fields) != width:
            raise _error(
                f"expected {width} comma-separated fields, found {len(fields)}: {raw.strip()!r}",
                path,
                number,
            )
        indices = columns or {name: k for k, name in enumerate(COLUMNS)}
        values = []
        for name in COLUMNS:
            field = fields[indices[name]]
            try:
                value = float(field)
            except ValueError:
                raise _error(
                    f"{name} {field!r} is not a number: {raw.strip()!r}", path, number
                ) from None
            if not math.isfinite(value):
                raise _error(
                    f"{name} {field!r} is not a finite number: {raw.strip()!r}", path, number
                )
            values.append(value)
        frequency, amplitude, phase = values
        if frequency <= 0.0:
            raise _error(
                f"frequency {frequency:g} Hz must be positive: {raw.strip()!r}", path, number
            )
        if amplitude < 0.0:
            raise _error(
                f"amplitude {amplitude:g} m must not be negative (give the phase to say the "
                f"direction): {raw.strip()!r}",
                path,
                number,
            )
        rows.append((frequency, amplitude, phase))
    if not rows:
        raise _error(
            "no data rows (only blank lines, comments or a header); add rows of "
            "frequency, amplitude, phase",
            path,
            None,
        )
    table = np.array(rows, dtype=np.float64)
    return Measurements(
        frequency=table[:, 0],
        amplitude=table[:, 1],
        phase_deg=table[:, 2],
        motion=motion,
        path=str(path),
    )


def _is_number(field: str) -> bool:
    """Whether a field parses as a float (NaN and infinity included: they are numbers here)."""
    try:
        float(field)
    except ValueError:
        return False
    return True
