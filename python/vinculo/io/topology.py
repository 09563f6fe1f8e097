"""What each constraint of a system is and which particles it joins, read from its name.

The compiled core names every constraint equation after its kind and particles (for example
``'distance #3 (particles 2-3)'``, ``'plane #4 (particle 1)'``); result files use these names to
tell distances between two particles (drawn as lines, carrying a tension) from the others.
"""

from __future__ import annotations

import re

import numpy as np

from vinculo._core import System

__all__ = ["KINDS", "constraint_kinds", "distance_pairs"]

#: The constraint kinds, by the start of their names in ``System.constraint_names()``.
KINDS = {
    "distance to a moving point": "point distance",
    "distance": "distance",
    "plane": "plane",
    "fixed coordinate": "fixed coordinate",
}

_PAIR = re.compile(r"^distance #\d+ \(particles (\d+)-(\d+)\)$")


def constraint_kinds(system: System) -> list[str]:
    """The kind of each constraint equation of ``system``.

    Arguments:
        system: the system.

    Returns:
        One of ``'distance'``, ``'point distance'``, ``'plane'``, ``'fixed coordinate'`` (or
        ``'other'``) per constraint equation.
    """
    kinds = []
    for name in system.constraint_names():
        kind = next((k for prefix, k in KINDS.items() if name.startswith(prefix)), "other")
        kinds.append(kind)
    return kinds


def distance_pairs(system: System) -> tuple[np.ndarray, np.ndarray]:
    """The distance constraints between two particles and the particles they join.

    Arguments:
        system: the system.

    Returns:
        ``(constraints, pairs)``: the (k,) indices of the particle-particle distance constraints
        and the (k, 2) indices of their two particles.
    """
    constraints, pairs = [], []
    for index, name in enumerate(system.constraint_names()):
        match = _PAIR.match(name)
        if match:
            constraints.append(index)
            pairs.append((int(match.group(1)), int(match.group(2))))
    return (
        np.array(constraints, dtype=np.int64),
        np.array(pairs, dtype=np.int64).reshape(-1, 2),
    )
