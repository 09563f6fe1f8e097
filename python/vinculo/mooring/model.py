"""Build a vinculo :class:`~vinculo.System` from a MoorDyn file model.

Each POINTS row becomes a particle:

- ``Fixed``: a fixed particle (an anchor) at the file's position;
- ``Coupled`` (MoorDyn's Vessel): a particle whose three coordinates follow the motion laws of
  a :class:`~vinculo.mooring.motion.Motion` (fixed-coordinate constraints; the file's position
  when no motion is given), so that the constraint multipliers carry the force that holds it;
- ``Free``: a free particle with the point's mass, and, for a point with a volume, its buoyancy,
  added mass (``Ca``) and drag (``CdA``) as a Morison element in still water (a point with no
  volume, its drag ``1/2 rho CdA |v| v`` alone).

Each LINES row becomes a line of lumped masses between its two points
(:func:`vinculo.mooring.line.add_line`, with the line type, the water and the seabed of the
file's OPTIONS), and the initial state is the static equilibrium
(:func:`vinculo.mooring.statics.solve_statics`).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from vinculo._core import ParticleId, System
from vinculo.errors import InvalidInputError
from vinculo.mooring.moordyn_file import (
    FileOptions,
    MoorDynFile,
    read_moordyn,
)
from vinculo.mooring.motion import Motion

__all__ = ["MooringModel", "build_model", "seabed", "water"]

# A particle needs a positive mass; a point of the file without one gets this (kg), to which
# the lines add the lumped mass of their end segments.
_POINT_MASS_FLOOR = 1e-6


def water(options: FileOptions) -> Any:
    """The water of a file's OPTIONS.

    Arguments:
        options: the options.

    Returns:
        A :class:`vinculo.mooring.line.Water`: depth, density and gravity.
    """
    from vinculo.mooring.line import Water

    return Water(depth=options.depth, density=options.density, gravity=options.gravity)


def file_water(options: FileOptions) -> Any | None:
    """The water of a file's current (``Currents 1``) and waves (``WaveKin 7``), None for still
    water (:func:`still_water`).

    Its free surface is the waves' elevation (the plane z = 0 without waves), with Wheeler's
    stretching, as MoorDyn's (``docs/theory/ocean.md``): a line's nodes above it carry no
    buoyancy and no drag.

    Arguments:
        options: the options.

    Returns:
        A ``vinculo._core.Water``, or None.
    """
    if options.current is None and options.waves is None:
        return None
    return _core_water(options)


def _core_water(options: FileOptions) -> Any:
    """The core's water of a file's current and waves (either may be None), under its free
    surface (:func:`file_water`)."""
    from vinculo import _core

    current, waves = options.current, options.waves
    empty = np.zeros(0)
    if current is not None:
        kind, velocities, heights = "table", current.velocities, current.heights
    else:
        kind, velocities, heights = "uniform", np.zeros((1, 3)), empty
    if waves is not None:
        amplitudes, omegas = np.abs(waves.amplitudes), waves.omegas
        directions, phases = waves.directions, waves.phases
    else:
        amplitudes = omegas = directions = phases = empty
    depth = options.depth if options.depth > 0.0 else math.inf
    return _core.Water(float(depth), float(options.gravity), amplitudes, omegas, directions,
                       phases, kind, np.ascontiguousarray(velocities, dtype=float),
                       np.ascontiguousarray(heights, dtype=float), 0.0, "wheeler",
                       True, float(options.wave_ramp))


def seabed(options: FileOptions) -> Any:
    """The seabed of a file's OPTIONS (MoorDyn's kBot, cBot and friction settings, and its 3D
    seafloor when the file names one).

    Arguments:
        options: the options.

    Returns:
        A :class:`vinculo.mooring.line.Seabed`.
    """
    from vinculo.mooring.line import Seabed

    return Seabed(kbot=options.kbot, cbot=options.cbot, friction=options.friction,
                  axial_friction=options.axial_friction,
                  friction_damping=options.friction_damping,
                  static_dynamic_scale=options.static_dynamic_scale,
                  surface=options.seafloor)


@dataclass
class MooringModel:
    """A mooring built from a MoorDyn file.

    Arguments:
        file: the file's content.
        system: the vinculo system: one particle per point, the lines' nodes and constraints.
        points: the particle of each point, in file order (``points[k - 1]`` for point k).
        lines: the lines (:class:`vinculo.mooring.line.Line`), in file order.
        motion: the coupled points' motion (None: they stay where the file puts them).
        statics: the static equilibrium the system starts from (None when not solved).
    """

    file: MoorDynFile
    system: System
    points: list[ParticleId]
    lines: list[Any]
    motion: Motion | None = None
    statics: Any = None
    coupling_constraints: list[list[Any]] = field(default_factory=list)

    @property
    def seabed_z(self) -> float:
        """The height of the flat seabed, ``-depth`` (m; the water depth's level under a 3D
        seafloor, whose heights :meth:`seabed_height` gives)."""
        return -self.file.options.depth

    def seabed_height(self, x: Any, y: Any) -> np.ndarray:
        """The seabed's height under the points (x, y) (m): the 3D seafloor's, or ``-depth``.

        Arguments:
            x: x coordinates (m).
            y: y coordinates (m).

        Returns:
            The heights, of the points' shape.
        """
        options = self.file.options
        return seabed(options).height(water(options), x, y)

    def line_ends(self, k: int) -> tuple[int, int]:
        """The particle indices of the two ends of line ``k`` (0-based).

        Arguments:
            k: the line's position in the file (0 for line 1).

        Returns:
            ``(end A, end B)`` particle indices.
        """
        row = self.file.lines[k]
        return self.points[row.attach_a - 1].index, self.points[row.attach_b - 1].index


def _check_motion(model: MoorDynFile, motion: Motion | None) -> None:
    coupled = model.coupled_points()
    if motion is not None and motion.num_points != len(coupled):
        raise InvalidInputError(
            f"{motion.source} moves {motion.num_points} points but "
            f"{model.path or 'the model'} has {len(coupled)} coupled (Vessel/Coupled) points; "
            f"give x, y, z of each, in the order of the POINTS section",
            name="motion", value=motion.num_points)


def build_model(source: str | Path | MoorDynFile, motion: Motion | None = None, *,
                solve: bool = True, couple: bool = True,
                **statics_options: Any) -> MooringModel:
    """Build the vinculo model of a MoorDyn file and put it in static equilibrium.

    Arguments:
        source: the MoorDyn input file, or its content.
        motion: the coupled points' motion (None: they stay at the file's positions); the
            statics uses their positions at t = 0.
        solve: solve the static equilibrium and start the system from it.
        couple: hold the coupled points on the motion (or where the file puts them); False:
            leave them free particles for the caller to attach (to a floating body), each
            carrying the mass of its lines' end half segments (the body then moves it), as a
            free point does.
        **statics_options: passed to :func:`vinculo.mooring.statics.solve_statics`
            (``tolerance``, ``max_iterations``).

    Returns:
        The model.

    Raises:
        MooringFileError: for a malformed or unsupported file.
        InvalidInputError: for a motion that does not match the coupled points.
        ConvergenceError: when the static equilibrium cannot be found.
    """
    from vinculo.mooring.line import add_line

    model = source if isinstance(source, MoorDynFile) else read_moordyn(source)
    _check_motion(model, motion)
    options = model.options
    system = System(gravity=(0.0, 0.0, -options.gravity))
    flowing = file_water(options)
    # The lines' and free points' loads in the file's current (else still water), under the
    # surface z = 0; its waves join for a run (:func:`vinculo.mooring.analysis.run`), the
    # equilibrium and its end forces are in the current alone, as MoorDyn's initial condition
    # leaves the waves out.
    current = (file_water(dataclasses.replace(options, waves=None))
               if options.waves is not None else flowing)
    system.set_water(current if current is not None else still_water(options))
    the_water, the_seabed = water(options), seabed(options)
    start = motion.positions(0.0) if motion is not None else None
    points: list[ParticleId] = []
    coupling: list[list[Any]] = []
    coupled_index = 0
    # The half segments at the lines' ends: a point that moves with the dynamics (a free point,
    # or a coupled one left free for a body) carries their mass, their weight with it
    # (MoorDyn's point takes its lines' end nodes' masses into its own, and a body its points').
    ends = _end_masses(model)

    def dynamic(attachment: str) -> bool:
        return attachment == "free" or (attachment == "coupled" and not couple)

    for point in model.points:
        carried = ends.get(point.id, 0.0) if dynamic(point.attachment) else 0.0
        mass = max(point.mass + carried, _POINT_MASS_FLOOR)
        if point.attachment == "fixed":
            points.append(system.add_particle(mass, point.position, fixed=True))
            continue
        if point.attachment == "coupled" and not couple:
            points.append(system.add_particle(mass, point.position))
            continue
        if point.attachment == "coupled":
            laws = motion.laws[coupled_index] if motion is not None else point.position
            position = start[coupled_index] if start is not None else point.position
            velocity = (motion.velocities(0.0)[coupled_index] if motion is not None
                        else (0.0, 0.0, 0.0))
            particle = system.add_particle(mass, tuple(float(c) for c in position),
                                           velocity=tuple(float(c) for c in velocity))
            coupling.append([system.add_fixed_coordinate(particle, axis, value)
                             for axis, value in enumerate(laws)])
            points.append(particle)
            coupled_index += 1
            continue
        particle = system.add_particle(mass, point.position)
        if flowing is not None and (point.volume > 0.0 or point.cda > 0.0):
            # In the file's current and waves: buoyancy, added mass and drag in its water.
            system.add_morison(particle, volume=point.volume, area=point.cda,
                               drag_coefficient=1.0 if point.cda > 0.0 else 0.0,
                               added_mass_coefficient=point.ca, density=options.density,
                               in_water=True)
        elif point.volume > 0.0:
            system.add_morison(particle, volume=point.volume, area=point.cda,
                               drag_coefficient=1.0 if point.cda > 0.0 else 0.0,
                               added_mass_coefficient=point.ca, density=options.density)
        elif point.cda > 0.0:  # drag alone: 1/2 rho CdA |v| v against the motion
            system.add_quadratic_drag(particle, 0.5 * options.density * point.cda)
        points.append(particle)
    lines = []
    for row in model.lines:
        free = tuple(dynamic(model.point(k).attachment) for k in (row.attach_a, row.attach_b))
        lines.append(add_line(
            system, points[row.attach_a - 1].index, points[row.attach_b - 1].index,
            model.line_types[row.line_type], row.unstretched_length, row.segments,
            the_water, the_seabed, name=f"line {row.id}", ends_carry_mass=free))
    built = MooringModel(file=model, system=system, points=points, lines=lines, motion=motion,
                         coupling_constraints=coupling)
    if solve:
        from vinculo.mooring.statics import solve_statics

        built.statics = solve_statics(system, **statics_options)
    return built


def _end_masses(model: MoorDynFile) -> dict[int, float]:
    """The mass of the half segments at the ends of the lines on each point (kg), by point id."""
    masses: dict[int, float] = {}
    for row in model.lines:
        kind = model.line_types[row.line_type]
        half = 0.5 * kind.mass_per_length * row.unstretched_length / row.segments
        for point in (row.attach_a, row.attach_b):
            masses[point] = masses.get(point, 0.0) + half
    return masses


def still_water(options: FileOptions) -> Any:
    """Still water below its surface, the plane z = 0, as MoorDyn's: the part of a line above
    it carries its weight without buoyancy or drag (a node's wet fraction is the mean of its
    segments' submerged fractions, as MoorDyn's, ``docs/theory/ocean.md``).

    Arguments:
        options: the file's options (gravity, depth).

    Returns:
        A ``vinculo._core.Water``.
    """
    return _core_water(dataclasses.replace(options, current=None, waves=None))
