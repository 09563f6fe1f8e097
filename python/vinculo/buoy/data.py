"""Reading measured amplitude and phase curves of the buoy from CSV.

vinculo ships no measurements: the user supplies them. The file has one row per excitation
frequency with three comma-separated columns:

- ``frequency``, in Hz (> 0);
- ``amplitude``, in m (>= 0), of the horizontal displacement of the buoy's centre;
- ``phase``, in degrees, in the convention of :data:`vinculo.buoy.harmonic.PHASE_CONVENTION`
  (phase lead of the buoy over the tank).

Two optional columns, named in a header, give each value's standard uncertainty (used as weights
by :mod:`vinculo.buoy.calibration`): ``amplitude_sd`` (m) and ``phase_sd`` (degrees).

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

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from vinculo.buoy.csv_table import read_table
from vinculo.errors import InvalidInputError

__all__ = ["COLUMNS", "MOTIONS", "UNCERTAINTY_COLUMNS", "Measurements", "read_measurements"]

#: The required columns, in their order when the file has no header.
COLUMNS = ("frequency", "amplitude", "phase")
#: What the measured amplitude and phase describe: the buoy's displacement in the laboratory, or
#: relative to the tank.
MOTIONS = ("absolute", "relative")
#: Optional columns: standard uncertainties of the amplitude (m) and the phase (degrees).
UNCERTAINTY_COLUMNS = ("amplitude_sd", "phase_sd")


@dataclass(frozen=True)
class Measurements:
    """Measured steady-state amplitude and phase over frequency.

    Attributes:
        frequency: excitation frequencies, in Hz, shape (n,), in file order.
        amplitude: amplitude of the buoy centre's horizontal displacement, in m.
        phase_deg: its phase lead over the tank, in degrees.
        motion: ``"absolute"`` (laboratory frame) or ``"relative"`` (to the tank).
        path: the file they were read from.
        amplitude_sd: standard uncertainty of each amplitude, in m (NaN: not given).
        phase_sd: standard uncertainty of each phase, in degrees (NaN: not given).
    """

    frequency: np.ndarray
    amplitude: np.ndarray
    phase_deg: np.ndarray
    motion: str
    path: str
    amplitude_sd: np.ndarray | None = None
    phase_sd: np.ndarray | None = None

    def __post_init__(self) -> None:
        for name in UNCERTAINTY_COLUMNS:
            if getattr(self, name) is None:
                object.__setattr__(self, name, np.full(self.frequency.shape, np.nan))


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
    if motion not in MOTIONS:
        raise InvalidInputError(
            f"motion must be one of {', '.join(map(repr, MOTIONS))}, got {motion!r}",
            name="motion",
            value=motion,
        )
    table = read_table(path, COLUMNS, what="measurement file", optional=UNCERTAINTY_COLUMNS)
    frequency, amplitude, phase, amplitude_sd, phase_sd = table.values.T
    for row in range(len(frequency)):
        if frequency[row] <= 0.0:
            raise table.error(row, f"frequency {frequency[row]:g} Hz must be positive")
        if amplitude[row] < 0.0:
            raise table.error(
                row,
                f"amplitude {amplitude[row]:g} m must not be negative (give the phase to say the "
                f"direction)",
            )
        for label, sd in (("amplitude_sd", amplitude_sd[row]), ("phase_sd", phase_sd[row])):
            if not (math.isnan(sd) or sd > 0.0):
                raise table.error(row, f"{label} {sd:g} must be positive (or left empty)")
    return Measurements(
        frequency=frequency.copy(),
        amplitude=amplitude.copy(),
        phase_deg=phase.copy(),
        motion=motion,
        path=str(path),
        amplitude_sd=amplitude_sd.copy(),
        phase_sd=phase_sd.copy(),
    )
