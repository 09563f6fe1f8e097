"""Mooring lines of lumped masses joined by elastic segments (MoorDyn's discretisation).

A line of ``N`` segments between two particles of a :class:`vinculo.System` gets ``N - 1``
interior nodes, each carrying the mass of one segment (``mass_per_length L / N``), and ``N``
elastic segments: compliant distances whose multipliers are the segments' tensions
(``docs/theory/moorings.md``; ``EA = inf`` is an exact distance). The two end particles carry the
loads of the half segment next to them (weight, buoyancy, drag, seabed contact), as MoorDyn's end
nodes belong to the points they attach to; their inertia stays the particles' own. Axial damping
``BA`` (or, negative, MoorDyn's damping ratio ``-zeta`` of each segment's axial mode:
``BA = zeta (L / N) sqrt(EA w)``, MoorDyn's documentation) is a dashpot in parallel with each
segment, carried by the segment itself (``System.set_axial_damping``), bending stiffness
``EI`` acts on consecutive node triples, Morison loads and seabed contact act on every node
with MoorDyn's conventions.

The interior nodes start on the closed-form elastic catenary of the line when it has one (a line
hanging in a vertical plane, :func:`vinculo.mooring.catenary.solve_catenary`), else on a
parabola of the line's length: a start close to the equilibrium that
:func:`vinculo.mooring.statics.solve_statics` then finds.

Example:
    >>> import vinculo
    >>> from vinculo.mooring.line import LineType, Water, add_line
    >>> s = vinculo.System(gravity=(0.0, 0.0, -9.80665))
    >>> a = s.add_particle(1.0, (0.0, 0.0, -50.0), fixed=True)
    >>> b = s.add_particle(1.0, (80.0, 0.0, 0.0), fixed=True)
    >>> chain = LineType("chain", diameter=0.1, mass_per_length=50.0, ea=5e8)
    >>> line = add_line(s, a.index, b.index, chain, 110.0, 20, Water(depth=200.0))
    >>> len(line.nodes), len(line.segments)
    (21, 20)
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from vinculo._core import Law
from vinculo.errors import InvalidInputError


@dataclass(frozen=True)
class LineType:
    """The properties of a line (a MoorDyn "LINE TYPES" row), SI units.

    Arguments:
        name: the type's name.
        diameter: the volume-equivalent diameter d (m, > 0).
        mass_per_length: the mass per unit length in air w (kg/m, > 0).
        ea: the axial stiffness EA (N, > 0); ``math.inf``: inextensible.
        ba: the axial damping BA (N s, >= 0); negative: minus the damping ratio of each
            segment's axial mode (MoorDyn's BA/-zeta).
        ei: the bending stiffness EI (N m^2, >= 0).
        cd: the normal drag coefficient.
        ca: the normal added-mass coefficient.
        cdax: the axial drag coefficient.
        caax: the axial added-mass coefficient.
        ea_curve: the tension-strain curve of a nonlinear line
            (:class:`vinculo.mooring.stiffness_curve.StiffnessCurve`, MoorDyn's EA table), in
            place of Hooke's law; ``ea`` is then its stiffest piece's slope. None: Hooke's law.
    """

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
    ea_curve: Any = None


@dataclass(frozen=True)
class Water:
    """The still water the lines are in: surface at z = 0, z up, flat seabed at z = -depth.

    Arguments:
        depth: the water depth (m, > 0).
        density: the water density (kg/m^3, > 0).
        gravity: the acceleration of gravity (m/s^2, > 0).
    """

    depth: float
    density: float = 1025.0
    gravity: float = 9.80665


@dataclass(frozen=True)
class Seabed:
    """MoorDyn's seabed contact: a spring and a dashpot per unit area, regularised Coulomb
    friction.

    Arguments:
        kbot: the contact stiffness per unit area (Pa/m), MoorDyn's kBot.
        cbot: the contact damping per unit area (Pa s/m), MoorDyn's cBot.
        friction: the transverse kinetic friction coefficient.
        axial_friction: the axial kinetic friction coefficient (None: the transverse one on the
            whole sliding velocity, MoorDyn-C's law).
        friction_damping: the slope of the friction at small speeds (N s/m), MoorDyn's FricDamp.
        static_dynamic_scale: static over kinetic friction, MoorDyn's StatDynFricScale.
        surface: the seabed's heights on a grid (:class:`vinculo.mooring.seafloor.Seafloor`,
            MoorDyn's 3D seafloor); None: the plane z = -depth of the water.
    """

    kbot: float = 3.0e6
    cbot: float = 3.0e5
    friction: float = 0.0
    axial_friction: float | None = None
    friction_damping: float = 200.0
    static_dynamic_scale: float = 1.0
    surface: Any = None

    def height(self, water: Water, x: Any, y: Any) -> np.ndarray:
        """The seabed's height under the points (x, y) (m): the surface's, or ``-depth``.

        Arguments:
            water: the water (its depth places a flat seabed).
            x: x coordinates (m).
            y: y coordinates (m).

        Returns:
            The heights, of the points' shape.
        """
        if self.surface is not None:
            return self.surface.height(x, y)
        return np.full(np.broadcast_shapes(np.shape(x), np.shape(y)), -water.depth)


@dataclass
class Line:
    """The particles and elements of a line, and its results.

    Arguments:
        nodes: the particle indices from end A to end B (N + 1).
        segments: the constraint handles of the N elastic segments, from end A.
        line_type: the line's type.
        unstretched_length: its unstretched length at t = 0 (m).
        water: the water it is in.
        name: a name for messages.
        end_loads: the weights of the half segments at ends A and B (N), which the line puts
            on its end particles.
        system: the system the line is in (for its end elements' loads).
        end_elements: the force elements on the end nodes A and B (hydrodynamics and seabed
            contact), whose loads the line also puts on its end particles.
        damping: the dashpot coefficient BA / l of each segment (N s/m; 0: none).
        length_law: the line's unstretched length as a law of time (a winch), or None when it
            is :attr:`unstretched_length` at all times.
        bending: the stiffness EI / l^3 (N/m) of the bending element at each inner node (0:
            no bending stiffness).
    """

    nodes: list[int]
    segments: list[Any]
    line_type: LineType
    unstretched_length: float
    water: Water
    name: str = ""
    end_loads: tuple[np.ndarray, np.ndarray] = field(
        default_factory=lambda: (np.zeros(3), np.zeros(3)))
    damping: float = 0.0
    length_law: Any = None
    bending: float = 0.0
    system: Any = None
    end_elements: tuple[list[Any], list[Any]] = field(default_factory=lambda: ([], []))

    def tensions(self, solution: Any) -> np.ndarray:
        """The segments' tensions: the elastic part, plus the axial damping's
        ``(BA / l) u . (v_i - v_j)`` where the source has velocities (a run). The elastic part of
        a run is Hooke's law at the stored positions; of an equilibrium (or an inextensible
        line), the segments' multipliers.

        Arguments:
            solution: a :class:`vinculo.Solution` of the line's system, or a static equilibrium
                (:class:`vinculo.mooring.statics.Statics`).

        Returns:
            ``(times, segments)`` tensions (N); one row for an equilibrium.
        """
        velocities = getattr(solution, "velocities", None)
        times = getattr(solution, "times", None)
        if times is not None and math.isfinite(self.line_type.ea):
            # Hooke's law at the stored positions. A time rule evaluates the multiplier where
            # it applies the tension (the step's midpoint for the trapezoidal rule), half a
            # step away from the stored time; the stretch at the stored time gives the
            # tension there, to the rule's order (docs/theory/moorings.md).
            tension = self._elastic_tensions(np.asarray(solution.positions, dtype=float),
                                             np.asarray(times, dtype=float))
        else:
            multipliers = np.atleast_2d(np.asarray(solution.multipliers, dtype=float))
            tension = multipliers[:, [c.index for c in self.segments]]
        if self.damping > 0.0 and velocities is not None:
            q = np.asarray(solution.positions, dtype=float)[:, self.nodes]
            v = np.asarray(velocities, dtype=float)[:, self.nodes]
            d = q[:, 1:] - q[:, :-1]
            u = d / np.linalg.norm(d, axis=2, keepdims=True)
            tension = tension + self.damping * np.sum(u * (v[:, 1:] - v[:, :-1]), axis=2)
        return tension

    def _elastic_tensions(self, positions: np.ndarray, times: np.ndarray) -> np.ndarray:
        """``max(0, EA (|d| - l(t)) / l(t))`` of every segment at every stored time: the
        segments go slack rather than push (MoorDyn's; :meth:`vinculo.System.set_slack`)."""
        q = positions.reshape(-1, positions.shape[-2], 3)[:, self.nodes]
        stretched = np.linalg.norm(q[:, 1:] - q[:, :-1], axis=2)
        if self.length_law is None:
            lengths = np.full(len(times), self.unstretched_length)
        else:
            lengths = np.array([float(self.length_law(float(t))) for t in times])
        segment = (lengths / len(self.segments))[:, None]
        strain = (stretched - segment) / segment
        if self.line_type.ea_curve is not None:
            return np.where(strain > 0.0, self.line_type.ea_curve.tension(strain), 0.0)
        return np.maximum(0.0, self.line_type.ea * strain)

    def end_forces(self, solution: Any) -> tuple[np.ndarray, np.ndarray]:
        """The forces of the line on its end particles A and B, as MoorDyn reports a point's
        force from its lines' end nodes: the end segments' tensions along them, the weight of
        the half segments at the ends, the loads of the water and the seabed on the end nodes
        (buoyancy, drag, Froude-Krylov, seabed contact and friction, at the stored states), and,
        for a line with bending stiffness, the force of the bending element next to each end
        on it (the shear that carries part of the line's weight: the second difference's force
        ``-EI / l^3 (q_0 - 2 q_1 + q_2)``, ``forces/bending.rs``). Not included: the end
        node's inertia, ``-(m + m_a) a``, which MoorDyn adds for a coupled point.

        Arguments:
            solution: a :class:`vinculo.Solution` or a static equilibrium.

        Returns:
            ``(times, 3)`` forces (N) on end A and on end B.
        """
        q = np.asarray(solution.positions, dtype=float)
        q = q.reshape(-1, q.shape[-2], 3)
        t = self.tensions(solution)
        first = q[:, self.nodes[1]] - q[:, self.nodes[0]]
        last = q[:, self.nodes[-2]] - q[:, self.nodes[-1]]
        on_a = t[:, :1] * first / np.linalg.norm(first, axis=1, keepdims=True)
        on_b = t[:, -1:] * last / np.linalg.norm(last, axis=1, keepdims=True)
        if self.bending > 0.0 and len(self.nodes) >= 3:
            n = self.nodes
            on_a = on_a - self.bending * (q[:, n[0]] - 2.0 * q[:, n[1]] + q[:, n[2]])
            on_b = on_b - self.bending * (q[:, n[-1]] - 2.0 * q[:, n[-2]] + q[:, n[-3]])
        on_a, on_b = on_a + self.end_loads[0], on_b + self.end_loads[1]
        if self.system is not None and (self.end_elements[0] or self.end_elements[1]):
            times = getattr(solution, "times", None)
            if times is None:  # an equilibrium: at rest at its time
                times = np.array([float(getattr(solution, "t", 0.0))])
                velocities = np.zeros_like(q)
            else:
                times = np.asarray(times, dtype=float)
                velocities = np.asarray(solution.velocities, dtype=float).reshape(q.shape)
            q, velocities = np.ascontiguousarray(q), np.ascontiguousarray(velocities)
            for k, elements in enumerate(self.end_elements):
                if elements:
                    loads = self.system.element_forces(elements, q, velocities, times)
                    if k == 0:
                        on_a = on_a + loads.sum(axis=1)
                    else:
                        on_b = on_b + loads.sum(axis=1)
        return on_a, on_b

    def laid_length(self, positions: Any, seabed: float | Callable[[Any, Any], Any]) -> float:
        """The length of line lying on the seabed (unstretched).

        A node is on the seabed when it touches it, at or below the seabed under it (the nodes
        on it sink into the contact spring, which carries their weight; those past the
        touchdown point rise above it); the laid length sums the segments whose two nodes are
        on it, plus half a segment where the line lifts off between two nodes.

        Arguments:
            positions: ``(particles, 3)`` positions (m).
            seabed: the height of a flat seabed (m), or a function of x and y giving the
                heights of a 3D seafloor (:meth:`vinculo.mooring.model.MooringModel.seabed_height`).

        Returns:
            The laid length (m, unstretched).
        """
        q = np.asarray(positions, dtype=float)[self.nodes]
        floor = seabed(q[:, 0], q[:, 1]) if callable(seabed) else seabed
        down = q[:, 2] <= np.asarray(floor, dtype=float)
        segment = self.unstretched_length / len(self.segments)
        both = int(np.sum(down[:-1] & down[1:]))
        if both == 0:
            return 0.0
        # Lift-off between a node on the seabed and one above it: half a segment.
        lift = int(np.sum(down[:-1] != down[1:]))
        return segment * (both + 0.5 * lift)


def _damping(line_type: LineType, segment: float) -> float:
    """The dashpot coefficient BA / l (N s/m) of a segment of length ``segment``."""
    ba = line_type.ba
    if ba < 0.0:
        if not math.isfinite(line_type.ea):
            return 0.0
        if line_type.ea_curve is not None:
            raise InvalidInputError(
                f"line type {line_type.name!r}: BA = {ba:g}, a damping ratio, with a tabulated "
                f"EA: give BA in N s (the ratio needs one EA)", name="ba", value=ba)
        # MoorDyn: BA = zeta (L / N) sqrt(EA w).
        ba = -ba * segment * math.sqrt(line_type.ea * line_type.mass_per_length)
    return ba / segment


def _initial_shape(a: np.ndarray, b: np.ndarray, line_type: LineType, length: float,
                   segments: int, water: Water, seabed: Seabed | None) -> np.ndarray:
    """Positions of the N + 1 nodes: on the closed-form catenary when it exists, else on a
    parabola of arc length ``length`` sagging below the chord; the nodes on the seabed sunk by
    the contact's static penetration w / (kbot d) (their contact force then carries them)."""
    if seabed is not None and seabed.surface is not None:
        return _on_surface(a, b, line_type, length, segments, water, seabed)
    nodes = _guess(a, b, line_type, length, segments, water,
                   seabed is not None and min(a[2], b[2]) <= -water.depth + 1e-6)
    if seabed is not None and seabed.kbot > 0.0:
        sink = _sink(line_type, water, seabed)
        down = nodes[:, 2] <= -water.depth + 1e-9
        nodes[1:-1, 2] = np.where(down[1:-1], -water.depth - sink, nodes[1:-1, 2])
    return nodes


def _sink(line_type: LineType, water: Water, seabed: Seabed) -> float:
    """The static penetration w / (kbot d) of a line lying on the seabed (m)."""
    from vinculo.mooring.catenary import weight_in_water

    if seabed.kbot <= 0.0:
        return 0.0
    w = weight_in_water(line_type.mass_per_length, line_type.diameter, water.density,
                        water.gravity)
    return max(w, 0.0) / (seabed.kbot * line_type.diameter)


def _on_surface(a: np.ndarray, b: np.ndarray, line_type: LineType, length: float,
                segments: int, water: Water, seabed: Seabed) -> np.ndarray:
    """The nodes of :func:`_initial_shape` over a 3D seafloor: the catenary (or parabola) of a
    flat seabed at the lower end's height, kept above the seafloor (the nodes it would bury
    lie on it, sunk by the static penetration)."""
    low = min(a[2], b[2])
    under = seabed.height(water, np.array([a[0], b[0]]), np.array([a[1], b[1]]))
    touching = bool(np.any(np.array([a[2], b[2]]) <= under + 1e-6))
    flat = Water(depth=-low, density=water.density, gravity=water.gravity)
    nodes = _guess(a, b, line_type, length, segments, flat, touching)
    floor = seabed.height(water, nodes[:, 0], nodes[:, 1])
    down = nodes[:, 2] <= floor + 1e-9
    nodes[1:-1, 2] = np.where(down[1:-1], floor[1:-1] - _sink(line_type, water, seabed),
                              nodes[1:-1, 2])
    return nodes


def _guess(a: np.ndarray, b: np.ndarray, line_type: LineType, length: float,
           segments: int, water: Water, on_seabed: bool) -> np.ndarray:
    """The catenary or the parabola of :func:`_initial_shape`."""
    from vinculo.mooring.catenary import solve_catenary, weight_in_water

    s = np.linspace(0.0, length, segments + 1)
    low, high = (a, b) if a[2] <= b[2] else (b, a)
    horizontal = high[:2] - low[:2]
    span = float(np.hypot(*horizontal))
    w = weight_in_water(line_type.mass_per_length, line_type.diameter, water.density,
                        water.gravity)
    try:
        if span <= 0.0 or w <= 0.0:
            raise InvalidInputError("no catenary")
        cat = solve_catenary(span, float(high[2] - low[2]), length, w, line_type.ea,
                             seabed_contact=on_seabed)
        x, z = cat.profile(s)
        heading = np.array([*horizontal / span, 0.0])
        nodes = low + np.outer(x, heading) + np.outer(z, [0.0, 0.0, 1.0])
        return nodes if low is a else nodes[::-1]
    except (InvalidInputError, ValueError, ArithmeticError):
        pass
    # A parabola -4 f u (1 - u) e_z below the chord whose arc length is the line's, its nodes
    # at equal arc lengths: each segment's chord a little shorter than its length, so that
    # the shape holds no tension (a run from the file's shape starts slack, not snapping);
    # clipped at the seabed. The sag f by bisection on the arc length (increasing in f). A
    # vertical chord sags sideways (along x) instead: sagging along itself, the line would fold
    # back on the chord, every node on one vertical, from where no iteration straightens it
    # (a slack line from a point down to a clump: the statics stopped without converging).
    return _parabola(a, b, length, segments, water)


def _parabola(a: np.ndarray, b: np.ndarray, length: float, segments: int,
              water: Water) -> np.ndarray:
    """The nodes of :func:`_guess`'s parabola (its comment)."""
    u = np.linspace(0.0, 1.0, 2049)
    chord = b - a
    vertical = float(np.hypot(chord[0], chord[1])) <= 1e-9 * float(np.linalg.norm(chord))
    sag_direction = np.array([1.0, 0.0, 0.0] if vertical else [0.0, 0.0, -1.0])

    def curve(sag: float) -> tuple[np.ndarray, np.ndarray]:
        points = a + np.outer(u, chord) + np.outer(4.0 * sag * u * (1.0 - u), sag_direction)
        arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(points, axis=0),
                                                              axis=1))])
        return points, arc

    low, high = 0.0, max(length, 1e-12)
    if curve(0.0)[1][-1] < length:
        for _ in range(100):
            mid = 0.5 * (low + high)
            if curve(mid)[1][-1] < length:
                low = mid
            else:
                high = mid
    points, arc = curve(low)
    targets = np.linspace(0.0, arc[-1], segments + 1)
    nodes = np.column_stack([np.interp(targets, arc, points[:, k]) for k in range(3)])
    nodes[0], nodes[-1] = a, b
    nodes[:, 2] = np.maximum(nodes[:, 2], -water.depth)
    return nodes


def add_line(system: Any, end_a: int, end_b: int, line_type: LineType,
             unstretched_length: float | Law, segments: int, water: Water,
             seabed: Seabed | None = None, name: str = "",
             ends_carry_mass: tuple[bool, bool] = (False, False)) -> Line:
    """Add a line of ``segments`` elastic segments between two particles of ``system``.

    Arguments:
        system: the :class:`vinculo.System`.
        end_a: the particle index of end A (a fixed, prescribed or free point).
        end_b: the particle index of end B.
        line_type: the line's properties.
        unstretched_length: its unstretched length (m), or a law of time (a winch: every
            segment keeps its share, 1 / segments, of the law's length).
        segments: the number of segments N (>= 1).
        water: the water (depth, density, gravity; the seabed at z = -depth unless the
            seabed has a surface of its own).
        seabed: the seabed contact (None: the line does not touch the seabed).
        name: a name for messages.
        ends_carry_mass: whether the particle of end A, end B already carries the mass of the
            half segment at that end (a free point, :func:`vinculo.mooring.model.build_model`:
            its weight then comes with it); otherwise the half segment's weight alone is put on
            the end particle as a force (a fixed or moved end, whose inertia does not matter).

    Returns:
        The :class:`Line`: its nodes, segment handles and results.

    Raises:
        InvalidInputError: for a non-positive length, diameter or mass per length, fewer than
            one segment, or the same particle at both ends.
    """
    length0 = float(unstretched_length(0.0)) if isinstance(unstretched_length, Law) \
        else float(unstretched_length)
    label = name or "line"
    checks = (("unstretched length", length0), ("diameter", line_type.diameter),
              ("mass per length", line_type.mass_per_length), ("EA", line_type.ea))
    for what, value in checks:
        if not value > 0.0:
            raise InvalidInputError(f"{label}: {what} = {value!r}: give a value > 0",
                                    name=what, value=value)
    if not (isinstance(segments, int) and segments >= 1):
        raise InvalidInputError(f"{label}: {segments!r} segments: give an integer >= 1",
                                name="segments", value=segments)
    if end_a == end_b:
        raise InvalidInputError(f"{label}: both ends are particle {end_a}: give two particles",
                                name="end_b", value=end_b)
    particles = system.particles()
    q0 = np.asarray(system.initial_positions(), dtype=float)
    a, b = q0[end_a], q0[end_b]
    shape = _initial_shape(a, b, line_type, length0, segments, water, seabed)
    segment = length0 / segments
    mass = line_type.mass_per_length * segment
    # The system's gravity (the water's is the same in a consistent model).
    gravity = np.asarray(system.gravity, dtype=float)
    nodes = [end_a]
    for k in range(1, segments):
        particle = system.add_particle(mass, tuple(float(c) for c in shape[k]))
        nodes.append(particle.index)
    nodes.append(end_b)
    particles = system.particles()
    handle = [particles[i] for i in nodes]
    length_law = unstretched_length if isinstance(unstretched_length, Law) else length0
    share = 1.0 / segments
    links = [system.add_elastic_distance(handle[k], handle[k + 1], length_law, line_type.ea,
                                         share)
             for k in range(segments)]
    if math.isfinite(line_type.ea):
        # MoorDyn's segments go slack instead of pushing (docs/theory/moorings.md).
        for link in links:
            system.set_slack(link)
    if line_type.ea_curve is not None:
        strains = [float(e) for e in line_type.ea_curve.strains]
        tensions = [float(t) for t in line_type.ea_curve.tensions]
        for link in links:
            system.set_strain_curve(link, strains, tensions)
    damping = _damping(line_type, segment)
    if damping > 0.0:
        # The segments' internal damping (MoorDyn's BA / l), carried by the segments themselves.
        for link in links:
            system.set_axial_damping(link, damping)
    if line_type.ei > 0.0:
        for k in range(1, segments):
            system.add_bending(handle[k - 1], handle[k], handle[k + 1], line_type.ei, segment)
    end_elements: tuple[list[Any], list[Any]] = ([], [])
    for k, node in enumerate(handle):
        end = k in (0, segments)
        piece = 0.5 * segment if end else segment
        tangent = (handle[max(k - 1, 0)], handle[min(k + 1, segments)])
        elements = end_elements[0 if k == 0 else 1] if end else []
        elements.append(system.add_line_hydrodynamics(
            node, diameter=line_type.diameter, length=piece, cd=line_type.cd,
            cdax=line_type.cdax, ca=line_type.ca, caax=line_type.caax, density=water.density,
            tangent=tangent))
        if seabed is not None:
            elements.append(system.add_seabed_contact(
                node, depth=water.depth, diameter=line_type.diameter, length=piece,
                kbot=seabed.kbot, cbot=seabed.cbot, tangent=tangent, friction=seabed.friction,
                axial_friction=seabed.axial_friction, friction_damping=seabed.friction_damping,
                static_dynamic_scale=seabed.static_dynamic_scale,
                grid=None if seabed.surface is None else seabed.surface.core))
        if end and not ends_carry_mass[0 if k == 0 else 1]:
            system.add_force(node, tuple(float(c) for c in 0.5 * mass * gravity))
    load = line_type.mass_per_length * 0.5 * segment * gravity
    return Line(nodes=nodes, segments=links, line_type=line_type, unstretched_length=length0,
                water=water, name=name, end_loads=(load, load.copy()), damping=damping,
                system=system, end_elements=end_elements,
                length_law=unstretched_length if isinstance(unstretched_length, Law) else None,
                bending=line_type.ei / segment**3 if line_type.ei > 0.0 and segments >= 2 else 0.0)
