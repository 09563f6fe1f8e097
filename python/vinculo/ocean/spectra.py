"""Wave spectra and their wave components (docs/theory/ocean.md).

- :func:`pierson_moskowitz` and :func:`jonswap`: the one-sided spectra of DNV-RP-C205 (2010)
  3.5.5, in angular frequency, scaled so that ``4 sqrt(m0)`` is exactly the significant height
  asked for (DNV's factor ``A_gamma = 1 - 0.287 ln(gamma)`` is the approximation of that
  scaling; the integral is taken numerically instead);
- :func:`spreading`: the directional spreading ``D(theta) ~ cos^n(theta - theta_p)`` of
  DNV-RP-C205 3.5.8.6, over ``|theta - theta_p| < pi / 2``;
- :func:`components`: amplitudes ``a_i = sqrt(2 S(omega_i) d_omega)`` at one random frequency
  in each of ``n`` equal bins (so that the record does not repeat with the period
  ``2 pi / d_omega`` of equal spacing), random phases, from one seed;
- :func:`from_elevation`: the components that reproduce a measured elevation record at one
  point over its duration (its discrete Fourier transform).
"""

from __future__ import annotations

import functools
import itertools
import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
from scipy import integrate, special

from vinculo.errors import InvalidInputError

__all__ = ["WaveComponents", "components", "from_elevation", "jonswap", "pierson_moskowitz",
           "spreading"]


def _positive(name: str, value: float) -> float:
    value = float(value)
    if not (math.isfinite(value) and value > 0.0):
        raise InvalidInputError(f"{name} = {value!r}: give a finite value > 0", name=name,
                                value=value)
    return value


def _pm_shape(omega: np.ndarray, wp: float) -> np.ndarray:
    with np.errstate(divide="ignore", over="ignore", invalid="ignore"):
        s = omega ** -5.0 * np.exp(-1.25 * (omega / wp) ** -4.0)
    return np.where(omega > 0.0, s, 0.0)


def _jonswap_shape(omega: np.ndarray, wp: float, gamma: float) -> np.ndarray:
    sigma = np.where(omega <= wp, 0.07, 0.09)
    peak = gamma ** np.exp(-0.5 * ((omega - wp) / (sigma * wp)) ** 2)
    return _pm_shape(omega, wp) * peak


def jonswap(omega: npt.ArrayLike, hs: float, tp: float, gamma: float = 3.3) -> np.ndarray:
    """The JONSWAP spectrum S(omega) (m^2 s/rad) of significant height ``hs`` and peak period
    ``tp``: the Pierson-Moskowitz shape ``omega^-5 exp(-5/4 (omega/omega_p)^-4)`` times the
    peak enhancement ``gamma^exp(-(omega - omega_p)^2 / (2 sigma^2 omega_p^2))`` (sigma 0.07
    below the peak, 0.09 above), scaled so that its zeroth moment is ``hs^2 / 16``.

    Arguments:
        omega: angular frequencies (rad/s).
        hs: significant wave height (m, > 0).
        tp: peak period (s, > 0).
        gamma: peak enhancement factor (1 to 7; 1 gives Pierson-Moskowitz).

    Returns:
        The spectral density at each frequency.

    Raises:
        InvalidInputError: a value outside its domain.
    """
    hs, tp = _positive("hs", hs), _positive("tp", tp)
    gamma = float(gamma)
    if not (1.0 <= gamma <= 7.0):
        raise InvalidInputError(f"gamma = {gamma!r}: give a peak enhancement factor from 1 to 7 "
                                "(DNV-RP-C205's range; 3.3 is the JONSWAP mean)", name="gamma",
                                value=gamma)
    wp = 2.0 * math.pi / tp
    return hs * hs / 16.0 / _shape_moment(wp, gamma) * _jonswap_shape(
        np.asarray(omega, dtype=float), wp, gamma)


@functools.lru_cache(maxsize=64)
def _shape_moment(wp: float, gamma: float) -> float:
    """The zeroth moment of the unscaled JONSWAP shape (below 0.3 omega_p and above 200 omega_p
    it holds less than 1e-30 and 1e-9 of it: the tail is about (200 omega_p)^-4 / 4 of a total
    above omega_p^-4 / 5)."""
    m0, _ = integrate.quad(lambda w: float(_jonswap_shape(np.array(w), wp, gamma)), 0.3 * wp,
                           200.0 * wp, points=[wp], limit=200, epsabs=0.0, epsrel=1e-12)
    return m0


def pierson_moskowitz(omega: npt.ArrayLike, hs: float, tp: float) -> np.ndarray:
    """The Pierson-Moskowitz spectrum ``5/16 hs^2 omega_p^4 omega^-5 exp(-5/4 (omega /
    omega_p)^-4)`` (JONSWAP with gamma = 1).

    Arguments:
        omega: angular frequencies (rad/s).
        hs: significant wave height (m, > 0).
        tp: peak period (s, > 0).

    Returns:
        The spectral density at each frequency (m^2 s/rad).
    """
    return jonswap(omega, hs, tp, gamma=1.0)


def spreading(theta: npt.ArrayLike, exponent: float, main: float = 0.0) -> np.ndarray:
    """The directional spreading function ``D(theta) = Gamma(1 + n/2) / (sqrt(pi)
    Gamma(1/2 + n/2)) cos^n(theta - main)`` for ``|theta - main| < pi/2``, zero elsewhere; it
    integrates to 1 over the directions.

    Arguments:
        theta: directions (rad).
        exponent: the spreading exponent n (> 0; larger is narrower).
        main: the main direction (rad).

    Returns:
        D at each direction (1/rad).
    """
    n = _positive("spreading exponent", exponent)
    d = (np.asarray(theta, dtype=float) - main + math.pi) % (2.0 * math.pi) - math.pi
    norm = special.gamma(1.0 + n / 2.0) / (math.sqrt(math.pi) * special.gamma(0.5 + n / 2.0))
    return np.where(np.abs(d) < 0.5 * math.pi, norm * np.cos(d).clip(0.0) ** n, 0.0)


@dataclass(frozen=True)
class WaveComponents:
    """Linear wave components: elevation ``sum a_i cos(k_i e_i . x - omega_i t + phase_i)``.

    Arguments:
        amplitudes: a_i (m).
        omegas: omega_i (rad/s).
        directions: the direction of travel of each (rad from x towards y).
        phases: phase_i (rad).
    """

    amplitudes: np.ndarray
    omegas: np.ndarray
    directions: np.ndarray
    phases: np.ndarray

    @property
    def variance(self) -> float:
        """The elevation's variance ``sum a_i^2 / 2`` (m^2): ``hs = 4 sqrt(variance)``."""
        return float(np.sum(self.amplitudes ** 2) / 2.0)

    def __len__(self) -> int:
        return int(self.amplitudes.size)


def components(spectrum: npt.ArrayLike | object, *, omega_range: tuple[float, float],
               count: int = 200, seed: int | None = 0, direction: float = 0.0,
               spreading_exponent: float | None = None, directions: int = 1,
               ) -> WaveComponents:
    """Wave components of a spectrum: ``count`` equal frequency bins over ``omega_range``,
    each with one frequency drawn uniformly inside it, amplitude ``sqrt(2 S(omega) d_omega)``
    (the bin's energy at that frequency) and a uniformly random phase; with spreading, each
    frequency's energy shared among ``directions`` equal direction bins by ``cos^n``.

    Arguments:
        spectrum: a function ``S(omega)`` (m^2 s/rad).
        omega_range: (lowest, highest) angular frequency (rad/s).
        count: the number of frequency bins (>= 1).
        seed: the random seed (the same seed gives the same sea); None: a fresh one.
        direction: the main direction of travel (rad from x towards y).
        spreading_exponent: n of :func:`spreading`; None: long-crested (one direction).
        directions: direction bins over the main direction +- pi/2 with spreading.

    Returns:
        The components.

    Raises:
        InvalidInputError: a bad range, count or spreading.
    """
    lo, hi = (float(x) for x in omega_range)
    if not (0.0 < lo < hi and math.isfinite(hi)):
        raise InvalidInputError(f"omega_range = {omega_range!r}: give 0 < lowest < highest "
                                "(rad/s)", name="omega_range", value=omega_range)
    if count < 1:
        raise InvalidInputError(f"count = {count!r}: give at least one component", name="count",
                                value=count)
    rng = np.random.default_rng(seed)
    width = (hi - lo) / count
    omegas = lo + width * (np.arange(count) + rng.uniform(size=count))
    energy = np.asarray(spectrum(omegas), dtype=float) * width
    if spreading_exponent is None:
        amplitudes = np.sqrt(2.0 * energy)
        return WaveComponents(amplitudes, omegas, np.full(count, float(direction)),
                              rng.uniform(0.0, 2.0 * math.pi, count))
    if directions < 1:
        raise InvalidInputError(f"directions = {directions!r}: give at least one",
                                name="directions", value=directions)
    edges = direction + np.linspace(-0.5 * math.pi, 0.5 * math.pi, directions + 1)
    centres = 0.5 * (edges[1:] + edges[:-1])

    def density(theta: float) -> float:
        return float(spreading(theta, spreading_exponent, direction))

    share = np.array([integrate.quad(density, a, b)[0]
                      for a, b in itertools.pairwise(edges)])
    share /= share.sum()
    e = np.outer(energy, share).ravel()
    return WaveComponents(np.sqrt(2.0 * e), np.repeat(omegas, directions),
                          np.tile(centres, count), rng.uniform(0.0, 2.0 * math.pi, e.size))


def from_elevation(times: npt.ArrayLike, elevation: npt.ArrayLike,
                   direction: float = 0.0) -> WaveComponents:
    """The wave components that reproduce a measured elevation record at x = y = 0:
    the record's discrete Fourier transform, one component per frequency ``2 pi j / T``
    (j = 1 .. N/2, T = N dt), travelling along ``direction``. Between the samples and beyond
    the record it is the record's periodic trigonometric interpolation; its mean is dropped.

    Arguments:
        times: equally spaced sample times (s).
        elevation: the elevation at those times (m).
        direction: the waves' direction of travel (rad from x towards y).

    Returns:
        The components (their phases place the record at x = y = 0 from ``times[0]`` on).

    Raises:
        InvalidInputError: unequal spacing, too few samples or non-finite values.
    """
    t = np.asarray(times, dtype=float)
    eta = np.asarray(elevation, dtype=float)
    if t.ndim != 1 or t.shape != eta.shape or t.size < 4:
        raise InvalidInputError(f"an elevation record of {t.size} times and {eta.size} values: "
                                "give at least 4 samples, one value per time", name="elevation",
                                value=eta.size)
    if not (np.all(np.isfinite(t)) and np.all(np.isfinite(eta))):
        raise InvalidInputError("the elevation record has non-finite values", name="elevation",
                                value=float("nan"))
    dt = np.diff(t)
    if np.any(dt <= 0.0) or np.ptp(dt) > 1e-6 * dt.mean():
        raise InvalidInputError(
            f"the elevation record's times are not equally spaced (steps from {dt.min():g} to "
            f"{dt.max():g} s): resample it onto a uniform grid", name="times", value=dt.max())
    n = t.size
    spectrum = np.fft.rfft(eta - eta.mean())
    j = np.arange(1, spectrum.size)
    amplitudes = 2.0 * np.abs(spectrum[1:]) / n
    if n % 2 == 0:
        amplitudes[-1] /= 2.0  # the Nyquist term appears once
    omegas = 2.0 * math.pi * j / (n * dt.mean())
    # eta(t) = sum A_j cos(omega_j (t - t0) + arg X_j) = sum A_j cos(-omega_j t + phase_j)
    # with phase_j = omega_j t0 - arg X_j, a component's elevation at x = 0.
    phases = omegas * t[0] - np.angle(spectrum[1:])
    return WaveComponents(amplitudes, omegas, np.full(j.size, float(direction)), phases)
