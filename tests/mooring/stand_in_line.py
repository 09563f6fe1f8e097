"""A stand-in for the line and statics modules of the mooring contract, for testing the file
builder, the analyses and the command line while ``vinculo.mooring.line`` and
``vinculo.mooring.statics`` are not in this tree.

It implements the contract's API with what the core already has: the nodes are placed on the
closed-form catenary of the line (so the "statics" is the catenary itself), consecutive nodes
are joined by exact distances, and each node carries its share of the line's mass and
buoyancy. The end forces of a static state are the catenary's; those of a run are the first and
last segments' tensions. It does not model EA, damping, bending, hydrodynamics or the seabed
(a line resting on the seabed can be solved, not run). With the real modules present, the tests
use those instead.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from vinculo.mooring.catenary import solve_catenary, weight_in_water


@dataclass(frozen=True)
class LineType:
    name: str
    diameter: float
    mass_per_length: float
    ea: float
    ba: float = 0.0
    ei: float = 0.0
    cd: float = 0.0
    ca: float = 0.0
    cdax: float = 0.0
    caax: float = 0.0


@dataclass(frozen=True)
class Water:
    depth: float
    density: float = 1025.0
    gravity: float = 9.80665


@dataclass(frozen=True)
class Seabed:
    kbot: float = 3.0e6
    cbot: float = 3.0e5
    friction: float = 0.0
    axial_friction: float | None = None
    friction_damping: float = 200.0
    static_dynamic_scale: float = 1.0


@dataclass
class Statics:
    positions: np.ndarray
    multipliers: Any = None
    residual: float = 0.0
    iterations: int = 0
    method: str = "catenary stand-in"


class Line:
    def __init__(self, nodes, segments, catenary, heading, seabed_z):
        self.nodes = nodes
        self.segments = segments
        self.catenary = catenary
        self.heading = heading
        self.seabed_z = seabed_z

    def tensions(self, solution):
        return np.column_stack([solution.distance_tension(c) for c in self.segments])

    def end_forces(self, solution):
        if isinstance(solution, Statics):
            c, e = self.catenary, self.heading
            on_a = c.horizontal_tension * e + np.array([0.0, 0.0, c.anchor_vertical_tension])
            on_b = -c.horizontal_tension * e - np.array([0.0, 0.0, c.fairlead_vertical_tension])
            return on_a, on_b
        q = np.asarray(solution.positions)
        t = self.tensions(solution)
        first = q[:, self.nodes[1]] - q[:, self.nodes[0]]
        last = q[:, self.nodes[-2]] - q[:, self.nodes[-1]]
        on_a = t[:, :1] * first / np.linalg.norm(first, axis=1, keepdims=True)
        on_b = t[:, -1:] * last / np.linalg.norm(last, axis=1, keepdims=True)
        return on_a, on_b

    def laid_length(self, positions, seabed_z):
        z = np.asarray(positions)[self.nodes, 2]
        q = np.asarray(positions)[self.nodes]
        down = np.isclose(z, seabed_z, atol=1e-9)
        both = down[:-1] & down[1:]
        return float(np.sum(np.linalg.norm(np.diff(q, axis=0), axis=1)[both]))


def add_line(system, end_a, end_b, line_type, unstretched_length, segments, water,
             seabed=None, name=""):
    handles = system.particles()
    q0 = np.asarray(system.initial_positions())
    a, b = q0[end_a], q0[end_b]
    if b[2] < a[2]:
        raise NotImplementedError("the stand-in needs end B above end A")
    w = weight_in_water(line_type.mass_per_length, line_type.diameter, water.density,
                        water.gravity)
    horizontal = b[:2] - a[:2]
    span = float(np.hypot(*horizontal))
    heading = np.array([*horizontal / span, 0.0])
    on_seabed = math.isclose(a[2], -water.depth)
    cat = solve_catenary(span, b[2] - a[2], unstretched_length, w, line_type.ea,
                         seabed_contact=on_seabed)
    s = np.linspace(0.0, unstretched_length, segments + 1)
    x, z = cat.profile(s)
    piece = unstretched_length / segments
    mass = line_type.mass_per_length * piece
    buoyancy = water.density * math.pi * line_type.diameter**2 / 4 * piece * water.gravity
    nodes = [end_a]
    for k in range(1, segments):
        position = a + x[k] * heading + np.array([0.0, 0.0, z[k]])
        particle = system.add_particle(mass, tuple(float(c) for c in position))
        system.add_force(particle, (0.0, 0.0, buoyancy))
        nodes.append(particle.index)
    nodes.append(end_b)
    links = [system.add_distance(handles[i] if i < len(handles) else system.particles()[i],
                                 system.particles()[j]) for i, j in itertools.pairwise(nodes)]
    return Line(nodes, links, cat, heading, -water.depth)


def solve_statics(system, *, tolerance=1e-9, max_iterations=200):
    return Statics(positions=np.asarray(system.initial_positions(), dtype=float))
