"""The resonance of a model, located by refining the frequency near the sweep's peak.

A sweep samples the amplitude curve on a grid; its largest sample, or a parabola through it and
its neighbours, is the grid's peak, not the model's: on the default 0.05 Hz grid the parabola's
vertex is 1.5 % low in amplitude, because the resonance curve is far from a parabola over
+-0.05 Hz. The model's peak is found by *successive parabolic refinement on freshly run
frequencies*:

1. the sweep's largest sample and its two neighbours bracket the peak; the vertex of the parabola
   through them is the first estimate ``v0``;
2. each round runs the model afresh at ``v - h``, ``v`` and ``v + h`` (``h`` a tenth of the
   previous spacing, starting from a tenth of the grid's), and the vertex of the parabola through
   these three runs is the next estimate;
3. the rounds stop when the estimate moves by less than ``resonance_tolerance`` (or after
   ``refine_rounds``).

Near the peak the curve is ``A0 (1 - (f - f0)^2 / w^2)`` to leading order, so a parabola through
points spaced ``h`` misplaces the vertex by O(h^2) (the curve's asymmetry) and each round gains a
factor of about 100 (on the default case: 6e-4 Hz off from the 0.05 Hz grid, 7e-5 Hz from the
first round's 0.005 Hz spacing, under 1e-5 Hz from the second's). The stated uncertainty of the
frequency is the last round's move, which bounds the error of the estimate before it and so,
generously, of the last one. The peak's is the larger of the last round's change of the peak
and the amplitude's own uncertainty, the relative change of the fitted amplitude between the
last two fit windows (``settling``) of the three runs. Both are printed with the digits these
uncertainties leave. Neighbouring runs differ by a fraction of a millihertz, so their
transients (which the steady-state check bounds) are nearly the same and move the vertex far
less than they move the amplitude.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

__all__ = ["Resonance", "bracket", "parabola_vertex", "round_frequencies", "significant"]


@dataclass
class Resonance:
    """The refined resonance of one model.

    Attributes:
        model: the model's name.
        frequency: the peak's frequency, in Hz (NaN when the model has no successful run).
        peak: the peak relative amplitude, in m.
        frequency_uncertainty: estimated uncertainty of ``frequency``, in Hz.
        peak_uncertainty: estimated uncertainty of ``peak``, in m.
        status: ``"refined"``; ``"edge"`` (the largest amplitude is at an end of the sweep, so the
            peak is not inside it and is not refined); ``"unrefined"`` (refinement runs failed or
            the rounds did not settle; the best estimate so far is given); ``"no runs"``.
        rounds: the refinement rounds run.
        estimates: the vertex frequency after each stage (the sweep's, then each round's).
        runs: frequencies run by the refinement.
    """

    model: str
    frequency: float
    peak: float
    frequency_uncertainty: float = math.nan
    peak_uncertainty: float = math.nan
    status: str = "no runs"
    rounds: int = 0
    estimates: list[float] = field(default_factory=list)
    runs: list[float] = field(default_factory=list)

    def describe(self) -> str:
        """``"0.9121 Hz, 47.08 mm"`` with the digits the uncertainties leave, and how it was found.

        Returns:
            The text (the amplitude in mm).
        """
        if self.status == "no runs":
            return "no successful run"
        f = significant(self.frequency, self.frequency_uncertainty)
        a = significant(self.peak * 1e3, self.peak_uncertainty * 1e3)
        how = {
            "refined": f"refined by {self.rounds} round(s) of 3 runs",
            "edge": "largest amplitude at an end of the sweep: the peak is outside it, not refined",
            "unrefined": "refinement did not settle: the best estimate",
        }[self.status]
        return f"{f} Hz, peak relative amplitude {a} mm ({how})"


def significant(value: float, uncertainty: float) -> str:
    """``value`` with as many decimals as ``uncertainty`` leaves, and the uncertainty.

    The last digit printed is the first significant digit of the uncertainty (rounded up so the
    printed uncertainty is not smaller), e.g. ``significant(0.912134, 3e-5)`` is
    ``"0.91213 +- 0.00003"``.

    Arguments:
        value: the number.
        uncertainty: its uncertainty (NaN or not positive: four decimals and no uncertainty).

    Returns:
        The text.
    """
    if not (math.isfinite(uncertainty) and uncertainty > 0.0):
        return f"{value:.4f}"
    decimals = max(0, -math.floor(math.log10(uncertainty)))
    step = 10.0**-decimals
    shown = math.ceil(uncertainty / step - 1e-9) * step
    return f"{value:.{decimals}f} +- {shown:.{decimals}f}"


def parabola_vertex(f: np.ndarray, y: np.ndarray) -> tuple[float, float, float]:
    """Vertex of the parabola through three points.

    Arguments:
        f: three distinct abscissae.
        y: the three values.

    Returns:
        ``(f_vertex, y_vertex, a)`` with ``a`` the coefficient of ``f^2`` (negative for a
        maximum); NaNs when the points are on a line.
    """
    a, b, c = np.polyfit(np.asarray(f, dtype=np.float64), np.asarray(y, dtype=np.float64), 2)
    if a == 0.0:
        return math.nan, math.nan, 0.0
    vertex = -b / (2.0 * a)
    return float(vertex), float(np.polyval((a, b, c), vertex)), float(a)


def bracket(f: np.ndarray, y: np.ndarray) -> tuple[int, bool]:
    """Index of the largest value and whether it has a neighbour on each side.

    Arguments:
        f: increasing frequencies.
        y: values at them.

    Returns:
        ``(k, inside)``.
    """
    k = int(np.argmax(y))
    return k, 0 < k < len(f) - 1


def round_frequencies(centre: float, spacing: float, low: float, high: float) -> list[float]:
    """The three frequencies of a refinement round, kept inside ``[low, high]``.

    Arguments:
        centre: the current estimate of the peak, in Hz.
        spacing: the round's spacing h, in Hz.
        low: the lower end of the bracket, in Hz.
        high: the upper end of the bracket, in Hz.

    Returns:
        ``[v - h, v, v + h]`` shifted, if needed, to lie within the bracket (rounded to 1e-9 Hz
        so that the files show the frequencies without float noise).
    """
    centre = min(max(centre, low + spacing), high - spacing)
    return [round(centre + k * spacing, 9) for k in (-1, 0, 1)]
