"""The sea a model is in: depth, current, waves (docs/theory/ocean.md).

z points up, the still-water level is z = 0 and the seabed z = -depth. A :class:`Sea` gives
the core's water (:meth:`Sea.water`, for :meth:`vinculo.System.set_water`), whose flow the
line elements use, and evaluates that flow at many points at once (:meth:`Sea.flow`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Literal

import numpy as np
import numpy.typing as npt

from vinculo import _core
from vinculo.errors import InvalidInputError
from vinculo.ocean.spectra import WaveComponents, components, jonswap

__all__ = ["Current", "Sea"]

_NO_WAVES = WaveComponents(np.zeros(0), np.zeros(0), np.zeros(0), np.zeros(0))


def _vector(name: str, value: Sequence[float]) -> np.ndarray:
    v = np.asarray(value, dtype=float)
    if v.shape != (3,) or not np.all(np.isfinite(v)):
        raise InvalidInputError(f"{name} = {value!r}: give 3 finite numbers (m/s)", name=name,
                                value=value)
    return v


@dataclass(frozen=True)
class Current:
    """A steady current profile (use the constructors).

    Arguments:
        kind: ``"uniform"``, ``"power"`` or ``"table"``.
        velocity: (n, 3) velocities (m/s): the one velocity, the velocity at the surface, or
            one per height of the table.
        heights: the table's heights z (m, increasing; z = 0 the still-water level).
        exponent: the power law's exponent.
    """

    kind: Literal["uniform", "power", "table"] = "uniform"
    velocity: np.ndarray = field(default_factory=lambda: np.zeros((1, 3)))
    heights: np.ndarray = field(default_factory=lambda: np.zeros(0))
    exponent: float = 1.0

    @classmethod
    def uniform(cls, velocity: Sequence[float]) -> Current:
        """The same velocity at every depth.

        Arguments:
            velocity: (m/s, 3 numbers).

        Returns:
            The current.
        """
        return cls("uniform", _vector("current velocity", velocity)[None, :])

    @classmethod
    def power_law(cls, surface: Sequence[float], exponent: float = 1.0 / 7.0) -> Current:
        """``U(z) = U_s ((z + h) / h)^exponent``, zero at the seabed (1/7: the tidal profile of
        DNV-RP-C205 4.1.3); above z = 0, its surface value.

        Arguments:
            surface: the velocity at the still-water level U_s (m/s, 3 numbers).
            exponent: the exponent (> 0).

        Returns:
            The current.
        """
        return cls("power", _vector("current velocity at the surface", surface)[None, :],
                   exponent=float(exponent))

    @classmethod
    def table(cls, heights: Sequence[float], velocities: npt.ArrayLike) -> Current:
        """Linear between the given heights, constant beyond the first and the last.

        Arguments:
            heights: z (m, increasing; negative below the still-water level).
            velocities: (n, 3) velocities (m/s), one per height.

        Returns:
            The current.
        """
        u = np.asarray(velocities, dtype=float)
        if u.ndim != 2 or u.shape[1] != 3:
            raise InvalidInputError(f"current table velocities of shape {u.shape}: give (n, 3)",
                                    name="velocities", value=u.shape)
        return cls("table", u, np.asarray(heights, dtype=float))


@dataclass(frozen=True)
class Sea:
    """Water of a depth, with a current and linear waves below a free surface.

    Arguments:
        depth: water depth (m, > 0; ``math.inf``: deep water).
        waves: the wave components (:mod:`vinculo.ocean.spectra`); none: still water.
        current: the current profile (default none).
        stretching: ``"wheeler"`` or ``"vertical"``: the flow between the still-water level and
            a crest (docs/theory/ocean.md).
        density: water density (kg/m^3).
        g: gravity (m/s^2), for the dispersion relation.
        ramp: the waves grow from nothing over this time (s) by ``(1 - cos(pi t / ramp)) / 2``,
            so that a run from still-water equilibrium meets no sudden load (0: none).
    """

    depth: float
    waves: WaveComponents = _NO_WAVES
    current: Current = field(default_factory=Current)
    stretching: Literal["wheeler", "vertical"] = "wheeler"
    density: float = 1025.0
    g: float = 9.80665
    ramp: float = 0.0

    @classmethod
    def regular(cls, height: float, period: float, depth: float, *, direction: float = 0.0,
                phase: float = 0.0, **options: object) -> Sea:
        """Regular linear (Airy) waves: elevation ``H/2 cos(k x - 2 pi t / T + phase)`` along
        ``direction``.

        Arguments:
            height: wave height H, crest to trough (m, >= 0).
            period: wave period T (s, > 0).
            depth: water depth (m).
            direction: direction of travel (rad from x towards y).
            phase: phase (rad).
            **options: ``current``, ``stretching``, ``density``, ``g``, ``ramp``.

        Returns:
            The sea.
        """
        if not (math.isfinite(period) and period > 0.0):
            raise InvalidInputError(f"period = {period!r}: give a wave period > 0 s",
                                    name="period", value=period)
        w = WaveComponents(np.array([0.5 * float(height)]), np.array([2.0 * math.pi / period]),
                           np.array([float(direction)]), np.array([float(phase)]))
        return cls(depth, w, **options)  # type: ignore[arg-type]

    @classmethod
    def irregular(cls, hs: float, tp: float, depth: float, *, gamma: float = 3.3,
                  count: int = 200, seed: int | None = 0, direction: float = 0.0,
                  spreading_exponent: float | None = None, directions: int = 9,
                  omega_range: tuple[float, float] | None = None,
                  **options: object) -> Sea:
        """Irregular long-crested (or short-crested, with spreading) waves of a JONSWAP
        spectrum (``gamma = 1``: Pierson-Moskowitz), by :func:`vinculo.ocean.spectra.components`.

        Arguments:
            hs: significant wave height (m).
            tp: peak period (s).
            depth: water depth (m).
            gamma: peak enhancement factor.
            count: the number of frequencies.
            seed: the random seed of the frequencies and phases.
            direction: the main direction of travel (rad from x towards y).
            spreading_exponent: n of the cos^n spreading; None: long-crested.
            directions: direction bins with spreading.
            omega_range: the frequency band (rad/s); default 0.5 to 4 times the peak
                frequency (more than 99.7 % of the variance for gamma from 1 to 7).
            **options: ``current``, ``stretching``, ``density``, ``g``, ``ramp``.

        Returns:
            The sea.
        """
        wp = 2.0 * math.pi / float(tp)
        band = omega_range if omega_range is not None else (0.5 * wp, 4.0 * wp)
        waves = components(lambda w: jonswap(w, hs, tp, gamma), omega_range=band, count=count,
                           seed=seed, direction=direction,
                           spreading_exponent=spreading_exponent,
                           directions=directions if spreading_exponent is not None else 1)
        return cls(depth, waves, **options)  # type: ignore[arg-type]

    def water(self) -> _core.Water:
        """The core's water for :meth:`vinculo.System.set_water`.

        Returns:
            The water.

        Raises:
            InvalidInputError: a value outside its domain, named.
        """
        w = self.waves
        if self.stretching not in ("wheeler", "vertical"):
            raise InvalidInputError(f"stretching = {self.stretching!r}: give \"wheeler\" or "
                                    "\"vertical\"", name="stretching", value=self.stretching)
        return _core.Water(float(self.depth), float(self.g),
                           np.ascontiguousarray(w.amplitudes, dtype=float),
                           np.ascontiguousarray(w.omegas, dtype=float),
                           np.ascontiguousarray(w.directions, dtype=float),
                           np.ascontiguousarray(w.phases, dtype=float), self.current.kind,
                           np.ascontiguousarray(self.current.velocity, dtype=float),
                           np.ascontiguousarray(self.current.heights, dtype=float),
                           float(self.current.exponent), self.stretching, True,
                           float(self.ramp))

    @property
    def wave_numbers(self) -> np.ndarray:
        """The components' wave numbers (rad/m), roots of ``omega^2 = g k tanh(k h)``."""
        return np.asarray(self.water().wave_numbers)

    def flow(self, points: npt.ArrayLike, t: float) -> dict[str, np.ndarray]:
        """The flow at many points at one time.

        Arguments:
            points: (n, 3) positions (m).
            t: time (s).

        Returns:
            ``velocity``, ``acceleration`` (n, 3; the local acceleration du/dt),
            ``pressure`` (n,: the waves' dynamic pressure, Pa) and ``elevation`` (n,: the
            surface above each point, m).
        """
        x = np.ascontiguousarray(np.atleast_2d(np.asarray(points, dtype=float)))
        out = self.water().flow(x, float(t))
        out["pressure"] = self.density * out["pressure"]
        return out

    def elevation(self, times: npt.ArrayLike, xy: Sequence[float] = (0.0, 0.0)) -> np.ndarray:
        """The surface elevation at one horizontal position over time.

        Arguments:
            times: times (s).
            xy: the position (x, y; m).

        Returns:
            The elevation at each time (m).
        """
        t = np.ascontiguousarray(np.atleast_1d(np.asarray(times, dtype=float)))
        at = np.ascontiguousarray(np.asarray(xy, dtype=float).reshape(1, 2))
        return np.asarray(self.water().elevation(at, t))[:, 0]
