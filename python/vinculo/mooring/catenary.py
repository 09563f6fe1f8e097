"""The elastic catenary in closed form, with a frictionless flat seabed.

A uniform line of unstretched length ``L``, weight in water per unit unstretched length ``w``
and axial stiffness ``EA`` hangs in a vertical plane from its lower end A (the anchor) to its
upper end B (the fairlead), ``X`` apart horizontally and ``Z >= 0`` vertically. With the
horizontal tension ``H`` (the same all along the line, as no horizontal load acts on it) and the
vertical tension ``V_B`` at the fairlead, the profile is (Irvine, *Cable Structures*, 1981,
section 1.3; the same equations as MoorDyn's and MAP++'s catenary routines, and Jonkman,
NREL/TP-500-41958, 2007, with the seabed friction coefficient set to zero):

- Fully suspended (``V_A = V_B - w L >= 0``, or the lower end above a seabed it does not reach):

  ``X = H/w [asinh(V_B/H) - asinh(V_A/H)] + H L / EA``

  ``Z = H/w [sqrt(1 + (V_B/H)^2) - sqrt(1 + (V_A/H)^2)] + (V_B L - w L^2 / 2) / EA``

- Touching the seabed (``V_B < w L``): the unstretched length ``L_B = L - V_B / w`` lies on the
  seabed, pulled by ``H`` alone (no friction), so

  ``X = L_B + H/w asinh(V_B/H) + H L / EA``

  ``Z = H/w [sqrt(1 + (V_B/H)^2) - 1] + V_B^2 / (2 EA w)``

The two forms agree at ``V_B = w L``. The derivation is on the documentation page "Elastic
catenary" (docs/theory/catenary.md). :func:`solve_catenary` finds ``H`` and ``V_B`` from the
spans by two nested bracketed root searches (each residual is monotonic in its unknown), so it
needs no initial guess and does not fail on nearly slack or nearly taut lines.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from vinculo.errors import InvalidInputError

__all__ = ["CatenarySolution", "SlopeCatenarySolution", "solve_catenary", "solve_catenary_on_slope",
           "weight_in_water"]


def weight_in_water(mass_per_length: float, diameter: float, density: float = 1025.0,
                    gravity: float = 9.80665) -> float:
    """The weight in water per unit length of a line, MoorDyn's way: its weight in air less the
    buoyancy of a cylinder of its volume-equivalent diameter.

    Arguments:
        mass_per_length: mass per unit length in air (kg/m).
        diameter: volume-equivalent diameter (m).
        density: water density (kg/m^3).
        gravity: gravitational acceleration (m/s^2).

    Returns:
        ``(m - rho pi d^2 / 4) g`` in N/m (negative for a line that floats).
    """
    return (mass_per_length - density * math.pi * diameter**2 / 4.0) * gravity


@dataclass(frozen=True)
class CatenarySolution:
    """The equilibrium of an elastic catenary from its anchor A to its fairlead B.

    Arguments:
        horizontal_span: ``X``, the horizontal distance from A to B (m).
        vertical_span: ``Z``, the height of B above A (m).
        length: ``L``, the unstretched length (m).
        weight: ``w``, weight in water per unit unstretched length (N/m).
        ea: ``EA``, the axial stiffness (N; ``math.inf``: inextensible).
        horizontal_tension: ``H``, the horizontal tension component, the same all along the
            line (N).
        fairlead_vertical_tension: ``V_B``, the vertical tension component at B (N, up).
        laid_length: ``L_B``, the unstretched length lying on the seabed (m; 0 when suspended).
        seabed_contact: whether the seabed was allowed to carry part of the line.
    """

    horizontal_span: float
    vertical_span: float
    length: float
    weight: float
    ea: float
    horizontal_tension: float
    fairlead_vertical_tension: float
    laid_length: float
    seabed_contact: bool = True

    @property
    def anchor_vertical_tension(self) -> float:
        """``V_A``: the vertical tension component at A (N, up; 0 when part of the line lies on
        the seabed)."""
        if self.laid_length > 0.0:
            return 0.0
        return self.fairlead_vertical_tension - self.weight * self.length

    @property
    def fairlead_tension(self) -> float:
        """The tension at B: ``sqrt(H^2 + V_B^2)`` (N)."""
        return math.hypot(self.horizontal_tension, self.fairlead_vertical_tension)

    @property
    def anchor_tension(self) -> float:
        """The tension at A: ``sqrt(H^2 + V_A^2)`` (N; ``H`` when the line touches the
        seabed, since the seabed carries no friction)."""
        return math.hypot(self.horizontal_tension, self.anchor_vertical_tension)

    @property
    def laid_length_stretched(self) -> float:
        """The length of line on the seabed as it lies there, stretched by ``H`` (m)."""
        return self.laid_length * (1.0 + self.horizontal_tension / self.ea)

    def tension(self, s: np.ndarray | float) -> np.ndarray:
        """The tension at unstretched arc length ``s`` from A.

        Arguments:
            s: arc lengths from 0 to ``L`` (m).

        Returns:
            ``sqrt(H^2 + V(s)^2)`` (N), with ``V(s) = max(0, V_A + w s)`` measured past the
            touchdown point.
        """
        v = self._vertical(np.asarray(s, dtype=float))
        return np.hypot(self.horizontal_tension, v)

    def _vertical(self, s: np.ndarray) -> np.ndarray:
        if self.laid_length > 0.0:
            return self.weight * np.maximum(s - self.laid_length, 0.0)
        return self.anchor_vertical_tension + self.weight * s

    def profile(self, s: np.ndarray | float) -> tuple[np.ndarray, np.ndarray]:
        """The line's shape: the position of the material point at unstretched arc length
        ``s`` from A, relative to A.

        Arguments:
            s: arc lengths from 0 to ``L`` (m).

        Returns:
            ``(x, z)``: horizontal distance from A towards B and height above A (m).
        """
        s = np.asarray(s, dtype=float)
        h, w, ea = self.horizontal_tension, self.weight, self.ea
        if self.laid_length > 0.0:
            lb = self.laid_length
            sus = np.maximum(s - lb, 0.0)  # suspended arc past the touchdown point
            on_bed = np.minimum(s, lb)
            v = w * sus
            x = on_bed * (1.0 + h / ea) + _span_x(h, w, v, 0.0, sus) + h * sus / ea
            z = _span_z(h, w, v, 0.0, sus) + w * sus**2 / (2.0 * ea)
            return x, z
        va = self.anchor_vertical_tension
        v = va + w * s
        x = _span_x(h, w, v, va, s) + h * s / ea
        z = _span_z(h, w, v, va, s) + (va * s + w * s**2 / 2.0) / ea
        return x, z


def _asinh_difference(a: np.ndarray, b: float, d: np.ndarray) -> np.ndarray:
    """``asinh(a) - asinh(b)`` given ``d = a - b`` exactly, without cancellation when ``a`` and
    ``b`` are close: for ``a b > 0`` it is ``asinh(d (a + b) / (a sqrt(1+b^2) + b sqrt(1+a^2)))``
    (the addition theorem of asinh)."""
    a = np.asarray(a, dtype=float)
    d = np.asarray(d, dtype=float)
    same_sign = a * b > 0.0
    root_a, root_b = np.sqrt(1.0 + a * a), math.sqrt(1.0 + b * b)
    denominator = np.where(same_sign, a * root_b + b * root_a, 1.0)
    close = np.arcsinh(d * (a + b) / denominator)
    return np.where(same_sign, close, np.arcsinh(a) - math.asinh(b))


def _span_x(h: float, w: float, v: np.ndarray | float, va: float,
            s: np.ndarray | float) -> np.ndarray:
    """``H/w [asinh(V/H) - asinh(V_A/H)]`` with ``V = V_A + w s``: the inextensible part of the
    horizontal span; its limit ``H s / T`` for a weightless line."""
    if w == 0.0:
        return h * np.asarray(s, dtype=float) / math.hypot(h, va)
    d = w * np.asarray(s, dtype=float) / h
    return h / w * _asinh_difference(np.asarray(v, dtype=float) / h, va / h, d)


def _span_z(h: float, w: float, v: np.ndarray | float, va: float,
            s: np.ndarray | float) -> np.ndarray:
    """``H/w [sqrt(1 + (V/H)^2) - sqrt(1 + (V_A/H)^2)]`` with ``V = V_A + w s``, written
    without cancellation: ``s (a + b) / (sqrt(1+a^2) + sqrt(1+b^2))`` with ``a = V/H``,
    ``b = V_A/H`` (and ``a - b = w s / H``)."""
    v = np.asarray(v, dtype=float)
    a, b = v / h, va / h
    root_a, root_b = np.sqrt(1.0 + a * a), math.sqrt(1.0 + b * b)
    return np.asarray(s, dtype=float) * (a + b) / (root_a + root_b)


def _spans(h: float, v_b: float, length: float, w: float, ea: float, contact: bool
           ) -> tuple[float, float, float]:
    """(X, Z, laid length) of the line with tensions ``h`` and ``v_b`` at the fairlead."""
    if contact and v_b < w * length:
        lb = length - v_b / w
        suspended = v_b / w
        x = lb + float(_span_x(h, w, v_b, 0.0, suspended)) + h * length / ea
        z = float(_span_z(h, w, v_b, 0.0, suspended)) + v_b**2 / (2.0 * w * ea)
        return x, z, lb
    va = v_b - w * length
    x = float(_span_x(h, w, v_b, va, length)) + h * length / ea
    z = float(_span_z(h, w, v_b, va, length)) + (v_b * length - w * length**2 / 2.0) / ea
    return x, z, 0.0


def _bracket_up(f, low: float, high: float) -> float:
    """Double ``high`` until ``f(high) > 0`` (``f`` increasing)."""
    for _ in range(200):
        if f(high) > 0.0:
            return high
        _low, high = high, 2.0 * high
    raise InvalidInputError("the catenary's tensions could not be bracketed",
                            name="catenary", value=high)


def solve_catenary(horizontal_span: float, vertical_span: float, length: float, weight: float,
                   ea: float = math.inf, *, seabed_contact: bool = True,
                   rtol: float = 1e-13) -> CatenarySolution:
    """Solve the elastic catenary from its anchor to its fairlead.

    Arguments:
        horizontal_span: ``X > 0``, the horizontal distance from the anchor A to the
            fairlead B (m).
        vertical_span: ``Z >= 0``, the height of B above A (m).
        length: ``L > 0``, the unstretched length (m).
        weight: ``w >= 0``, the weight in water per unit unstretched length (N/m; see
            :func:`weight_in_water`); 0 gives a straight elastic bar.
        ea: ``EA > 0``, the axial stiffness (N); ``math.inf`` for an inextensible line.
        seabed_contact: whether A lies on a flat frictionless seabed that carries the part of
            the line that would hang below A (a mooring line); False for a line hanging freely
            between two points above the seabed.
        rtol: relative tolerance of the root searches.

    Returns:
        The tensions and the laid length.

    Raises:
        InvalidInputError: for a span, length, weight or stiffness out of its domain; for a
            line so long that it would lie slack on the seabed (no horizontal tension); for a
            weightless line shorter than the distance it spans only if ``ea`` is infinite.
    """
    for name, value, ok in (
        ("horizontal_span", horizontal_span, horizontal_span > 0.0),
        ("vertical_span", vertical_span, vertical_span >= 0.0),
        ("length", length, length > 0.0),
        ("weight", weight, weight >= 0.0),
        ("ea", ea, ea > 0.0),
    ):
        if not (ok and (math.isfinite(value) or name == "ea")):
            raise InvalidInputError(
                f"solve_catenary: {name} = {value!r} is out of its domain (spans in m with "
                f"the fairlead above the anchor, length > 0, weight in water >= 0 in N/m, "
                f"EA > 0 in N)", name=name, value=value)
    from scipy.optimize import brentq

    x_target, z_target = float(horizontal_span), float(vertical_span)
    chord = math.hypot(x_target, z_target)
    if weight == 0.0:
        # A weightless line is a straight elastic bar: T = EA (chord / L - 1).
        if chord <= length:
            raise InvalidInputError(
                f"solve_catenary: a weightless line of length {length:g} m spanning "
                f"{chord:g} m is slack (no tension); give a line shorter than its span",
                name="length", value=length)
        tension = ea * (chord / length - 1.0)
        if not math.isfinite(tension):
            raise InvalidInputError(
                f"solve_catenary: an inextensible weightless line cannot span {chord:g} m "
                f"with length {length:g} m", name="ea", value=ea)
        return CatenarySolution(x_target, z_target, length, 0.0, ea,
                                tension * x_target / chord, tension * z_target / chord, 0.0,
                                seabed_contact)
    w = float(weight)
    if math.isinf(ea) and chord >= length:
        raise InvalidInputError(
            f"solve_catenary: an inextensible line of length {length:g} m cannot span "
            f"{chord:g} m; give a longer line or a finite EA", name="length", value=length)

    def vertical_for(h: float) -> float:
        # Z(V) is increasing in V; for a suspended line Z = 0 at V = w L / 2.
        low = 0.0 if seabed_contact else 0.5 * w * length

        def dz(v: float) -> float:
            return _spans(h, v, length, w, ea, seabed_contact)[1] - z_target

        if dz(low) >= 0.0:
            return low
        high = _bracket_up(dz, low, max(2.0 * low, w * length, h, 1.0))
        return brentq(dz, low, high, rtol=rtol, xtol=1e-300, maxiter=500)

    def dx(h: float) -> float:
        return _spans(h, vertical_for(h), length, w, ea, seabed_contact)[0] - x_target

    h_low = w * length * 1e-12
    if dx(h_low) > 0.0:
        raise InvalidInputError(
            f"solve_catenary: the line ({length:g} m) is longer than it needs to reach the "
            f"fairlead ({x_target:g} m away, {z_target:g} m up) along the seabed: it lies "
            f"slack, with no horizontal tension; shorten it or move the fairlead away",
            name="length", value=length)
    h_high = _bracket_up(dx, h_low, w * length)
    h = brentq(dx, h_low, h_high, rtol=rtol, xtol=1e-300, maxiter=500)
    v_b = vertical_for(h)
    laid = _spans(h, v_b, length, w, ea, seabed_contact)[2]
    return CatenarySolution(x_target, z_target, length, w, ea, h, v_b, laid, seabed_contact)


@dataclass(frozen=True)
class SlopeCatenarySolution:
    """The equilibrium of an elastic catenary whose anchor lies on a plane seabed sloping up
    towards the fairlead, MoorDyn's vertical frictionless contact (:func:`solve_catenary_on_slope`).

    Arguments:
        length: ``L``, the unstretched length (m).
        weight: ``w``, weight in water per unit unstretched length (N/m).
        ea: ``EA``, the axial stiffness (N).
        slope: ``tan(beta)``, the seabed's rise per horizontal metre towards the fairlead.
        horizontal_tension: ``H``, the same all along the line (N).
        suspended_length: ``L_S``, the unstretched length off the seabed (m).
    """

    length: float
    weight: float
    ea: float
    slope: float
    horizontal_tension: float
    suspended_length: float

    @property
    def laid_length(self) -> float:
        """``L_B = L - L_S``, the unstretched length on the seabed (m)."""
        return self.length - self.suspended_length

    @property
    def anchor_vertical_tension(self) -> float:
        """``V_A = H tan(beta)``: the laid line follows the slope (N, up)."""
        return self.horizontal_tension * self.slope

    @property
    def anchor_tension(self) -> float:
        """``T_A = H / cos(beta)``, the tension all along the laid line (N)."""
        return math.hypot(self.horizontal_tension, self.anchor_vertical_tension)

    @property
    def fairlead_vertical_tension(self) -> float:
        """``V_B = H tan(beta) + w L_S`` (N, up)."""
        return self.anchor_vertical_tension + self.weight * self.suspended_length

    @property
    def fairlead_tension(self) -> float:
        """``sqrt(H^2 + V_B^2)`` (N)."""
        return math.hypot(self.horizontal_tension, self.fairlead_vertical_tension)

    @property
    def laid_length_stretched(self) -> float:
        """The laid line's length along the slope, stretched by ``T_A`` (m)."""
        return self.laid_length * (1.0 + self.anchor_tension / self.ea)


def _slope_spans(h: float, suspended: float, length: float, w: float, ea: float,
                 slope: float) -> tuple[float, float]:
    """(X, Z) of a line on a slope with horizontal tension ``h`` and ``suspended`` unstretched
    length off the seabed."""
    laid = length - suspended
    cos_b = 1.0 / math.sqrt(1.0 + slope * slope)
    tension = h / cos_b
    along = laid * (1.0 + tension / ea)
    v0 = h * slope
    v1 = v0 + w * suspended
    x = along * cos_b + float(_span_x(h, w, v1, v0, suspended)) + h * suspended / ea
    z = (along * slope * cos_b + float(_span_z(h, w, v1, v0, suspended))
         + (v0 * suspended + w * suspended**2 / 2.0) / ea)
    return x, z


def solve_catenary_on_slope(horizontal_span: float, vertical_span: float, length: float,
                            weight: float, ea: float = math.inf, *, slope: float,
                            rtol: float = 1e-13) -> SlopeCatenarySolution:
    """The elastic catenary from an anchor on a plane seabed that rises towards the fairlead
    by ``slope`` (tan beta; negative: falls), MoorDyn's vertical frictionless contact.

    With a vertical contact force and no friction no horizontal load acts on the line, so its
    horizontal tension ``H`` is the same all along it; the part on the seabed lies straight up
    the slope, so its vertical tension is ``H tan(beta)`` and the seabed carries its weight;
    the suspended part leaves the seabed tangentially, a catenary from ``V_0 = H tan(beta)``
    to ``V_B = V_0 + w L_S`` (docs/theory/catenary.md, "A sloping seabed"):

    ``X = L_B (1 + T_A/EA) cos(beta) + H/w [asinh(V_B/H) - asinh(V_0/H)] + H L_S / EA``

    ``Z = L_B (1 + T_A/EA) sin(beta) + H/w [sqrt(1 + (V_B/H)^2) - sqrt(1 + (V_0/H)^2)]
    + (V_0 L_S + w L_S^2 / 2) / EA``

    with ``T_A = H / cos(beta)`` and ``L_B = L - L_S``. For each ``H`` the height ``Z`` grows
    with ``L_S``, which a bracketed search finds; ``H`` then by a second one on ``X``.

    Arguments:
        horizontal_span: ``X > 0`` from the anchor to the fairlead (m).
        vertical_span: ``Z``, the fairlead's height above the anchor (m).
        length: ``L > 0``, the unstretched length (m).
        weight: ``w > 0``, the weight in water per unit length (N/m).
        ea: ``EA > 0`` (N; ``math.inf``: inextensible).
        slope: tan(beta), the seabed's rise per horizontal metre towards the fairlead.
        rtol: relative tolerance of the root searches.

    Returns:
        The tensions and the laid length.

    Raises:
        InvalidInputError: for arguments out of their domain, or a line that does not lie on
            the seabed at this configuration (it hangs from the anchor: :func:`solve_catenary`
            with ``seabed_contact=False``) or lies slack.
    """
    for name, value, ok in (("horizontal_span", horizontal_span, horizontal_span > 0.0),
                            ("length", length, length > 0.0), ("weight", weight, weight > 0.0),
                            ("ea", ea, ea > 0.0), ("slope", slope, math.isfinite(slope)),
                            ("vertical_span", vertical_span, math.isfinite(vertical_span))):
        if not (ok and (math.isfinite(value) or name == "ea")):
            raise InvalidInputError(
                f"solve_catenary_on_slope: {name} = {value!r} is out of its domain",
                name=name, value=value)
    from scipy.optimize import brentq

    w = float(weight)

    def suspended_for(h: float) -> float:
        def dz(s: float) -> float:
            return _slope_spans(h, s, length, w, ea, slope)[1] - vertical_span

        if dz(length) < 0.0:
            raise InvalidInputError(
                "solve_catenary_on_slope: the line hangs from its anchor above the seabed "
                "here (no part of it lies on the slope); use solve_catenary with "
                "seabed_contact=False", name="length", value=length)
        if dz(0.0) >= 0.0:
            return 0.0
        return brentq(dz, 0.0, length, rtol=rtol, xtol=1e-300, maxiter=500)

    def dx(h: float) -> float:
        return _slope_spans(h, suspended_for(h), length, w, ea, slope)[0] - horizontal_span

    h_low = w * length * 1e-9
    if dx(h_low) > 0.0:
        raise InvalidInputError(
            "solve_catenary_on_slope: the line is longer than it needs to reach the fairlead "
            "along the seabed: it lies slack; shorten it", name="length", value=length)
    h_high = _bracket_up(dx, h_low, w * length)
    h = brentq(dx, h_low, h_high, rtol=rtol, xtol=1e-300, maxiter=500)
    return SlopeCatenarySolution(length, w, ea, slope, h, suspended_for(h))
