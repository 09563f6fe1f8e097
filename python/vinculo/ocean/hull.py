"""Hulls of floating and submerged bodies: stacks of axisymmetric sections about the body's
axis (docs/theory/ocean.md, "Floating bodies").

A hull is given in its own frame, z along the body's axis: :func:`sphere`, :func:`cylinder`,
:func:`frustum` (a cone when a radius is zero), stacked with ``+`` (a spar with a heave plate:
``cylinder(0.5, -20, 5) + cylinder(3, -20.2, -20)``). ``System.add_floating_body(body, hull)``
puts it on a rigid body.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from vinculo.errors import InvalidInputError

__all__ = ["Hull", "cylinder", "frustum", "sphere"]


def _finite(name: str, value: float) -> float:
    value = float(value)
    if not math.isfinite(value):
        raise InvalidInputError(f"{name} = {value!r}: give a finite number", name=name,
                                value=value)
    return value


@dataclass(frozen=True)
class Hull:
    """A stack of sections (use :func:`sphere`, :func:`cylinder`, :func:`frustum` and ``+``).

    Arguments:
        parts: the sections, ``("frustum", bottom, top, r_bottom, r_top)`` or
            ``("sphere", centre, radius)`` (m, in the hull's frame).
    """

    parts: tuple[tuple[object, ...], ...]

    def sections(self) -> list[tuple[object, ...]]:
        """The sections, for the core.

        Returns:
            The list of section tuples.
        """
        return list(self.parts)

    def __add__(self, other: Hull) -> Hull:
        return Hull(self.parts + other.parts)

    @property
    def volume(self) -> float:
        """The volume (m^3; overlapping sections count twice)."""
        total = 0.0
        for kind, *numbers in self.parts:
            v = [float(x) for x in numbers]  # type: ignore[arg-type]
            if kind == "sphere":
                total += 4.0 / 3.0 * math.pi * v[1] ** 3
            else:
                z0, z1, a, b = v
                total += math.pi * (z1 - z0) * (a * a + a * b + b * b) / 3.0
        return total


def sphere(radius: float, centre: float = 0.0) -> Hull:
    """A sphere.

    Arguments:
        radius: its radius (m, > 0).
        centre: the height of its centre in the hull's frame (m).

    Returns:
        The hull.
    """
    return Hull((("sphere", _finite("centre", centre), _finite("radius", radius)),))


def cylinder(radius: float, bottom: float, top: float) -> Hull:
    """A vertical cylinder (along the hull's axis).

    Arguments:
        radius: its radius (m, > 0).
        bottom: the height of its bottom in the hull's frame (m).
        top: the height of its top (m, above the bottom).

    Returns:
        The hull.
    """
    return frustum(bottom, top, radius, radius)


def frustum(bottom: float, top: float, r_bottom: float, r_top: float) -> Hull:
    """A frustum of a cone (a cone when one radius is zero).

    Arguments:
        bottom: the height of its bottom in the hull's frame (m).
        top: the height of its top (m, above the bottom).
        r_bottom: its radius at the bottom (m, >= 0).
        r_top: its radius at the top (m, >= 0).

    Returns:
        The hull.
    """
    return Hull((("frustum", _finite("bottom", bottom), _finite("top", top),
                  _finite("r_bottom", r_bottom), _finite("r_top", r_top)),))
