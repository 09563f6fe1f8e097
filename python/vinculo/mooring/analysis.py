"""The two analyses of a mooring file: its statics and a run with moving fairleads.

:func:`statics` builds the model of a MoorDyn file and solves its static equilibrium: each
line's end forces, tensions and laid length (:class:`MooringStatics`, written as
``statics.csv`` by ``vinculo mooring statics``). :func:`run` moves the coupled points by a
recorded motion from that equilibrium and records the end forces over time
(:class:`MooringRun`), with its CSV, NetCDF and plot outputs (``vinculo mooring run``).
"""

from __future__ import annotations

import csv
import math
import time
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from vinculo.errors import InvalidInputError
from vinculo.mooring.moordyn_file import MoorDynFile
from vinculo.mooring.motion import Motion

__all__ = ["STATICS_COLUMNS", "LineEnd", "MooringRun", "MooringStatics", "StepCheck",
           "check_step", "run", "statics"]

#: The columns of ``statics.csv``, in order: two rows per line, end A then end B.
STATICS_COLUMNS = ("line", "end", "point", "x", "y", "z", "fx", "fy", "fz", "tension",
                   "laid_length")


@dataclass(frozen=True)
class LineEnd:
    """One end of a line in static equilibrium.

    Arguments:
        line: the line's number in the file (1-based).
        end: ``"A"`` (MoorDyn's anchor end, AttachA) or ``"B"`` (the fairlead end, AttachB).
        point: the number of the point the end is attached to (1-based).
        position: the end's position (m).
        force: the force the line exerts on the end point (N).
        laid_length: the length of the line lying on the seabed (m; the same on both rows).
    """

    line: int
    end: str
    point: int
    position: tuple[float, float, float]
    force: tuple[float, float, float]
    laid_length: float

    @property
    def tension(self) -> float:
        """The magnitude of :attr:`force` (N)."""
        return math.sqrt(sum(c * c for c in self.force))


def _last(array: Any) -> np.ndarray:
    """The last row of a (times, 3) array, or a (3,) array as it is."""
    return np.asarray(array, dtype=float).reshape(-1, 3)[-1]


def _line_ends(built: Any, source: Any, positions: np.ndarray) -> list[LineEnd]:
    rows = []
    for k, (row, line) in enumerate(zip(built.file.lines, built.lines, strict=True)):
        force_a, force_b = line.end_forces(source)
        laid = float(line.laid_length(positions, built.seabed_height))
        a, b = built.line_ends(k)
        for end, point, particle, force in (("A", row.attach_a, a, force_a),
                                            ("B", row.attach_b, b, force_b)):
            rows.append(LineEnd(line=row.id, end=end, point=point,
                                position=tuple(float(c) for c in positions[particle]),
                                force=tuple(float(c) + 0.0 for c in _last(force)),
                                laid_length=laid))
    return rows


@dataclass
class MooringStatics:
    """The static equilibrium of a mooring.

    Arguments:
        model: the model (:class:`vinculo.mooring.model.MooringModel`), in equilibrium.
        ends: two :class:`LineEnd` per line, end A then end B, in file order.
        cpu_time: the CPU time of the equilibrium solve (s).
    """

    model: Any
    ends: list[LineEnd]
    cpu_time: float = 0.0

    def table(self) -> str:
        """A text table of the end tensions and laid lengths, one row per line end.

        Returns:
            The table, with a header line.
        """
        lines = [f"{'line':>4} {'end':>3} {'point':>5} {'tension (N)':>14} "
                 f"{'fx (N)':>13} {'fy (N)':>13} {'fz (N)':>13} {'laid (m)':>10}"]
        for e in self.ends:
            lines.append(f"{e.line:>4} {e.end:>3} {e.point:>5} {e.tension:>14.6g} "
                         f"{e.force[0]:>13.6g} {e.force[1]:>13.6g} {e.force[2]:>13.6g} "
                         f"{e.laid_length:>10.4g}")
        return "\n".join(lines)

    def coupled_points(self) -> list[int]:
        """The ids of the coupled (Vessel/Coupled) points, in file order.

        Returns:
            The point ids.
        """
        return [p.id for p in self.model.file.coupled_points()]

    def _particles(self, points: Any) -> tuple[list[int], list[int]]:
        """The ids of ``points`` (None: the coupled ones) and their particle indices."""
        ids = self.coupled_points() if points is None else [int(p) for p in points]
        count = len(self.model.points)
        if not ids:
            raise InvalidInputError("the file has no coupled (Vessel/Coupled) points: give the "
                                    "points to take the stiffness at", name="points", value=ids)
        for k in ids:
            if not 1 <= k <= count:
                raise InvalidInputError(f"point {k} is not one of the file's points 1 to "
                                        f"{count}", name="points", value=k)
        if len(set(ids)) != len(ids):
            raise InvalidInputError("each point once", name="points", value=ids)
        return ids, [self.model.points[k - 1].index for k in ids]

    def point_forces(self, points: Any = None) -> np.ndarray:
        """The force of the mooring on each point in the equilibrium (N): that of its lines and
        of the other elements acting on it, not the point's own weight and buoyancy.

        Arguments:
            points: the point ids (None: the coupled points, :meth:`coupled_points`).

        Returns:
            ``(n, 3)`` forces, in the order of ``points``.
        """
        from vinculo.mooring.statics import point_force

        _, particles = self._particles(points)
        system, statics = self.model.system, self.model.statics
        return np.array([point_force(system, statics, p) for p in particles])

    def stiffness(self, points: Any = None) -> np.ndarray:
        """The joint linearised stiffness of the mooring at points (N/m), from the analytic
        Jacobian of the equilibrium (``docs/theory/moorings.md``, stiffness).

        Block ``(i, j)``, rows and columns ``3i:3i+3`` and ``3j:3j+3``, is ``-dF_i/dx_j``:
        ``F_i`` the mooring's force on point i (:meth:`point_forces`) as point j moves, the
        other points held and every free node and point in equilibrium. A restoring mooring
        has a positive definite matrix (a spring's sign: K = -dF/dx).

        Arguments:
            points: the point ids (None: the coupled points).

        Returns:
            ``(3n, 3n)`` stiffness (N/m).

        Raises:
            InvalidInputError: for no points, an unknown one or one listed twice.
            ConvergenceError: when the stiffness is infinite (an inextensible taut line).
        """
        from vinculo.errors import ConvergenceError
        from vinculo.mooring.statics import points_stiffness

        ids, particles = self._particles(points)
        try:
            return points_stiffness(self.model.system, self.model.statics, particles)
        except ConvergenceError as exc:
            listed = ", ".join(map(str, ids))
            raise ConvergenceError(
                f"no finite stiffness at points {listed}: the equilibrium's matrix is singular "
                f"there (a point without a line, or a taut line that cannot stretch): {exc}"
            ) from exc

    def vessel_stiffness(self, reference: Any = (0.0, 0.0, 0.0),
                         points: Any = None) -> np.ndarray:
        """The 6x6 linearised stiffness of the mooring on a rigid vessel that carries the
        points (the coupled points by default), about the point ``reference``.

        With the vessel's small translation u and rotation theta about ``reference``, point i
        moves by ``u + theta x r_i`` (``r_i`` from the reference to the point), and the
        mooring's force and moment on the vessel are ``F = sum F_i`` and
        ``M = sum r_i x F_i``, ``r_i`` turning with the vessel. With the joint stiffness
        ``K_ij`` (:meth:`stiffness`) and ``[a]`` the matrix of ``a x``::

            K_uu = sum_ij K_ij                  K_ut = -sum_ij K_ij [r_j]
            K_tu = sum_ij [r_i] K_ij            K_tt = -sum_ij [r_i] K_ij [r_j] - sum_i [F_i] [r_i]

        the last term the change of the moment of the point forces as their points turn (a line
        hanging below the reference restores a heel with it). Rows and columns: x, y, z
        (translations, m; forces, N), then rotations about x, y, z (rad; moments, N m).

        Arguments:
            reference: the point the rotations and moments are about (m).
            points: the point ids (None: the coupled points).

        Returns:
            ``(6, 6)`` stiffness: N/m, N/rad, N m/m and N m/rad blocks.

        Raises:
            InvalidInputError: for a reference that is not three finite numbers, or bad points.
            ConvergenceError: when the stiffness is infinite (an inextensible taut line).
        """
        origin = np.asarray(reference, dtype=float)
        if origin.shape != (3,) or not np.all(np.isfinite(origin)):
            raise InvalidInputError("give the reference point as three finite coordinates (m)",
                                    name="reference", value=reference)
        ids, particles = self._particles(points)
        k = self.stiffness(ids)
        forces = self.point_forces(ids)
        positions = np.asarray(self.model.statics.positions, dtype=float)[particles]
        arms = positions - origin
        out = np.zeros((6, 6))
        for i, (ri, fi) in enumerate(zip(arms, forces, strict=True)):
            out[3:, 3:] -= _cross_matrix(fi) @ _cross_matrix(ri)
            for j, rj in enumerate(arms):
                kij = k[3 * i:3 * i + 3, 3 * j:3 * j + 3]
                out[:3, :3] += kij
                out[:3, 3:] -= kij @ _cross_matrix(rj)
                out[3:, :3] += _cross_matrix(ri) @ kij
                out[3:, 3:] -= _cross_matrix(ri) @ kij @ _cross_matrix(rj)
        return out

    def coupled_bodies(self) -> list[int]:
        """The ids of the file's Coupled bodies, in file order.

        Returns:
            The body ids.
        """
        return [b.id for b in self.model.file.coupled_bodies()]

    def body_stiffness(self, body: int) -> np.ndarray:
        """The 6x6 linearised stiffness of the mooring on a body of the file, about its
        reference point (X0, Y0, Z0): :meth:`vessel_stiffness` of the points attached to it.

        Arguments:
            body: the body's id.

        Returns:
            ``(6, 6)`` stiffness: N/m, N/rad, N m/m and N m/rad blocks.

        Raises:
            InvalidInputError: for a body that is not in the file or carries no point.
            ConvergenceError: when the stiffness is infinite.
        """
        bodies = {b.id: b for b in self.model.file.bodies}
        if body not in bodies:
            raise InvalidInputError(f"body {body} is not one of the file's bodies "
                                    f"({', '.join(map(str, bodies)) or 'none'})", name="body",
                                    value=body)
        points = [p.id for p in self.model.file.points if p.body == body]
        if not points:
            raise InvalidInputError(f"body {body} carries no point, so no line pulls it",
                                    name="body", value=body)
        return self.vessel_stiffness(bodies[body].position, points)

    def stiffness_table(self, reference: Any = (0.0, 0.0, 0.0),
                        stiffness: np.ndarray | None = None) -> str:
        """A text table of :meth:`vessel_stiffness` about ``reference``: rows and columns x, y,
        z, rx, ry, rz.

        Arguments:
            reference: the vessel's reference point (m).
            stiffness: the matrix (None: :meth:`vessel_stiffness` about ``reference``).

        Returns:
            The table, with a header line.
        """
        k = self.vessel_stiffness(reference) if stiffness is None else stiffness
        lines = [f"{'':>4}" + "".join(f"{name:>14}" for name in VESSEL_DOFS)]
        for name, row in zip(VESSEL_DOFS, k, strict=True):
            lines.append(f"{name:>4}" + "".join(f"{x:>14.6g}" for x in row))
        return "\n".join(lines)

    def stiffness_to_csv(self, path: str | Path, stiffness: np.ndarray | None = None,
                         reference: Any = (0.0, 0.0, 0.0)) -> Path:
        """Write the vessel stiffness: a header ``row,x,y,z,rx,ry,rz``, then one row per degree
        of freedom, named in the first column (N/m, N/rad, N m/m, N m/rad).

        Arguments:
            path: the file to write.
            stiffness: the matrix (None: :meth:`vessel_stiffness` about ``reference``).
            reference: the vessel's reference point (m), where ``stiffness`` is None.

        Returns:
            The path written.
        """
        k = self.vessel_stiffness(reference) if stiffness is None else stiffness
        return _write_matrix(path, list(VESSEL_DOFS), k)

    def point_stiffness_to_csv(self, path: str | Path,
                               stiffness: np.ndarray | None = None) -> Path:
        """Write the joint stiffness of the coupled points (:meth:`stiffness`): a header
        ``row,point<k>_x,point<k>_y,point<k>_z,...``, then one row per coordinate (N/m).

        Arguments:
            path: the file to write.
            stiffness: the matrix (None: :meth:`stiffness` of the coupled points).

        Returns:
            The path written.
        """
        k = self.stiffness() if stiffness is None else stiffness
        names = [f"point{p}_{c}" for p in self.coupled_points() for c in "xyz"]
        return _write_matrix(path, names, k)

    def slack_segments(self) -> dict[int, int]:
        """The segments without tension, shorter than their length (a line's spare length,
        which the statics lays slack as a run does: ``vinculo.mooring.statics``).

        Returns:
            The number of such segments of each line that has some, by line id.
        """
        positions = np.asarray(self.model.statics.positions, dtype=float)
        slack = {}
        for row, line in zip(self.model.file.lines, self.model.lines, strict=True):
            tension = line.tensions(self.model.statics)[0]
            chords = np.linalg.norm(np.diff(positions[line.nodes], axis=0), axis=1)
            count = int(np.sum((tension == 0.0) & (chords < line.unstretched_length
                                                   / len(line.segments))))
            if count:
                slack[row.id] = count
        return slack

    def to_csv(self, path: str | Path) -> Path:
        """Write ``statics.csv``: the columns :data:`STATICS_COLUMNS`, two rows per line.

        Arguments:
            path: the file to write.

        Returns:
            The path written.
        """
        return write_csv(path, STATICS_COLUMNS, (
            [e.line, e.end, e.point, *e.position, *e.force, e.tension, e.laid_length]
            for e in self.ends))


def statics(path: str | Path | MoorDynFile, motion: Motion | None = None,
            **options: Any) -> MooringStatics:
    """The static equilibrium of the mooring of a MoorDyn file.

    Arguments:
        path: the MoorDyn v2 input file (or its content).
        motion: the coupled points' motion; their positions at t = 0 are used (None: the
            file's positions).
        **options: passed to :func:`vinculo.mooring.statics.solve_statics`.

    Returns:
        The equilibrium: each line's end forces, tensions and laid length.

    Raises:
        MooringFileError: for a malformed or unsupported file.
        ConvergenceError: when the equilibrium cannot be found.
    """
    from vinculo.mooring.model import build_model

    started = time.process_time()
    built = build_model(path, motion, **options)
    cpu = time.process_time() - started
    positions = np.asarray(built.statics.positions, dtype=float)
    return MooringStatics(model=built, ends=_line_ends(built, built.statics, positions),
                          cpu_time=cpu)


#: The degrees of freedom of a vessel's stiffness, in the order of its rows and columns:
#: translations along x, y, z, then rotations about them.
VESSEL_DOFS = ("x", "y", "z", "rx", "ry", "rz")


def write_csv(path: str | Path, header: Sequence[str], rows: Iterable[Sequence[Any]]) -> Path:
    """Write a CSV table: the ``header``, then the ``rows``, numbers as the shortest text that
    reads back to the same float (``repr``), other entries (names, ids) as they are.

    Arguments:
        path: the file to write.
        header: the column names.
        rows: the rows.

    Returns:
        The path written.
    """
    path = Path(path)

    def text(x: Any) -> Any:
        return repr(float(x)) if isinstance(x, float | np.floating) else x

    with path.open("w", newline="", encoding="utf-8") as handle:
        writer = csv.writer(handle)
        writer.writerow(header)
        for row in rows:
            writer.writerow([text(x) for x in row])
    return path


def _write_matrix(path: str | Path, names: list[str], matrix: np.ndarray) -> Path:
    """Write a square matrix as CSV: a header ``row,<names>``, then each row named."""
    return write_csv(path, ["row", *names],
                     ([name, *map(float, row)] for name, row in zip(names, matrix, strict=True)))


def _cross_matrix(a: np.ndarray) -> np.ndarray:
    """The matrix of ``a x``: ``_cross_matrix(a) @ b == np.cross(a, b)``."""
    return np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])


@dataclass
class MooringRun:
    """A run of a mooring with its coupled points moved by a motion.

    Arguments:
        model: the model (:class:`vinculo.mooring.model.MooringModel`).
        solution: the :class:`vinculo.Solution` of the run.
        times: the stored times (s).
        end_forces: ``(times, lines, 2, 3)``: the force of each line on its end A and end B (N).
        segment_tensions: ``(times, lines, 2)``: the tension of each line's first and last
            segment (N).
        cpu_time: the CPU time of the time integration (s).
        dt: the step size (s).
        files: the files written (CSV, NetCDF, plots), by kind.
    """

    model: Any
    solution: Any
    times: np.ndarray
    end_forces: np.ndarray
    segment_tensions: np.ndarray
    cpu_time: float
    dt: float
    files: dict[str, Path] = field(default_factory=dict)

    @property
    def end_tensions(self) -> np.ndarray:
        """``(times, lines, 2)``: the end tensions (N)."""
        return np.linalg.norm(self.end_forces, axis=-1)

    def tension_columns(self) -> list[str]:
        """The column names of :meth:`to_csv` after ``time``.

        Returns:
            ``line<k>_<end>_<fx|fy|fz|tension>`` for each line and end.
        """
        return [f"line{row.id}_{end}_{q}" for row in self.model.file.lines for end in "AB"
                for q in ("fx", "fy", "fz", "tension")]

    def channels(self) -> dict[str, np.ndarray]:
        """The file's output channels (its OUTPUTS section) over the stored times, by name
        (:mod:`vinculo.mooring.channels`).

        Returns:
            ``{name: (times,) values}``, in the file's order.
        """
        from vinculo.mooring.channels import channel_values, parse_channel

        return {name: channel_values(self, parse_channel(name))
                for name in self.model.file.outputs}

    def channels_csv(self, path: str | Path) -> Path:
        """Write the output channels over time (MoorDyn's main output, as CSV).

        Arguments:
            path: the CSV file: ``time``, then one column per channel, named as in the file.

        Returns:
            The path written.
        """
        values = self.channels()
        columns = list(values.values())
        return write_csv(path, ["time", *values], (
            [float(t), *(float(c[i]) for c in columns)] for i, t in enumerate(self.times)))

    def to_csv(self, path: str | Path) -> Path:
        """Write the end forces and tensions over time.

        Arguments:
            path: the CSV file: ``time``, then :meth:`tension_columns`.

        Returns:
            The path written.
        """
        tensions = self.end_tensions

        def row(i: int) -> list[float]:
            values = [float(self.times[i])]
            for k in range(self.end_forces.shape[1]):
                for e in range(2):
                    values += [*map(float, self.end_forces[i, k, e]), float(tensions[i, k, e])]
            return values

        return write_csv(path, ["time", *self.tension_columns()],
                         (row(i) for i in range(len(self.times))))


def run(path: str | Path | MoorDynFile, motion: Motion | str | Path | None, t_end: float, *,
        dt: float = 0.02, output_every: float | None = None, output: str | Path | None = None,
        plots: bool = True, progress: bool | Callable[[float, float], None] = False,
        start: str = "statics", **options: Any) -> MooringRun:
    """Run a mooring from its static equilibrium with the coupled points moved by a motion.

    Arguments:
        path: the MoorDyn v2 input file (or its content).
        motion: the coupled points' motion, or a motion CSV file (see
            :mod:`vinculo.mooring.motion`: with coupled bodies, their six degrees of freedom
            first, :func:`vinculo.mooring.motion.read_motion`); None: they stay where they
            are.
        t_end: the end time (s).
        dt: the step size (s).
        output_every: the interval of the stored states (s): a whole number of steps (MoorDyn's
            output interval dtOut; None: every step). A long run at small steps stores less
            (a state of a 100-segment line is 5.6 kB) and runs faster: storing every 5 ms step
            instead of every 0.1 s cost the benchmark's chain on the seabed a fifth more CPU.
        output: a folder for ``tensions.csv``, ``run.nc`` and the plots (None: write nothing).
        plots: also draw ``shapes.png`` and ``tensions.png`` into ``output``.
        progress: True draws a progress bar on standard error (see :func:`vinculo.simulate`).
        start: ``"statics"`` (the default): from the static equilibrium; ``"file"``: from the
            file's point positions and the lines' initial shapes (the catenary between their
            ends, or a parabola where there is none) at rest, as MoorDyn without its initial
            condition (TmaxIC 0): a model released from a shape, or one without a unique
            equilibrium (a slack neutrally buoyant line).
        **options: run options passed to :func:`vinculo.simulate`. ``t_eval`` defaults to
            the multiples of ``output_every`` (else ``dt``) and ``t_end`` (unless
            ``save_every`` or ``adaptive`` is given): the run's stored states are at those
            times, whatever short steps the contact events of nodes landing on the seabed take
            between them.
            ``jacobian_reuse`` defaults to True here (modified Newton): a line's iteration
            matrix changes slowly, so one factorisation serves many steps, to the same
            tolerance: end tensions within 5e-6 of the peak tension of full Newton's on the
            benchmark's hanging chain and cable, at a third to two thirds of the CPU time; on
            the chain on the seabed, whose steps go to each contact event, within that case's
            time-step error.

    Returns:
        The run.

    Raises:
        MooringFileError: for a malformed or unsupported file.
        InvalidInputError: for a motion that does not match the coupled points or does not
            cover the run, or a bad step or end time.
        ConvergenceError: when a step or the initial equilibrium fails.
    """
    from vinculo.mooring.model import _check_motion, build_model
    from vinculo.mooring.moordyn_file import read_moordyn
    from vinculo.simulate import simulate

    if not isinstance(path, MoorDynFile):
        path = read_moordyn(path)
    if isinstance(motion, (str, Path)):
        from vinculo.mooring.motion import read_motion

        motion = read_motion(path, motion)
    if not (math.isfinite(t_end) and t_end > 0.0):
        raise InvalidInputError(f"t_end = {t_end!r}: give an end time > 0 s", name="t_end",
                                value=t_end)
    if start not in ("statics", "file"):
        raise InvalidInputError(f"start = {start!r}: give \"statics\" or \"file\"",
                                name="start", value=start)
    if motion is not None:
        first, last = motion.domain()
        if first > 0.0 or last < t_end:
            raise InvalidInputError(
                f"{motion.source} covers t = {first:g} to {last:g} s; the run needs 0 to "
                f"{t_end:g} s: give a shorter --t-end or a longer record", name="t_end",
                value=t_end)
    every = 1 if output_every is None else _output_steps(output_every, dt)
    _check_motion(path, motion)
    built = build_model(path, motion, solve=start == "statics")
    if built.file.options.waves is not None:
        # The file's waves, from the equilibrium in its current alone.
        from vinculo.mooring.model import file_water

        built.system.set_water(file_water(built.file.options))
    if motion is not None and np.any(motion.velocities(0.0) != 0.0):
        # The coupled points start moving: the velocities of the lines' nodes are made
        # consistent with theirs (the least mass-weighted change).
        built.system.project_initial_state()
    options.setdefault("jacobian_reuse", True)
    if "save_every" not in options and not options.get("adaptive", False):
        # The states at the multiples of dt (and t_end), whatever the steps between: the short
        # steps of contact events would otherwise all be stored.
        options.setdefault("t_eval", _output_grid(t_end, dt, every))
    started = time.process_time()
    solution = simulate(built.system, t_end, dt, progress=progress, **options)
    cpu = time.process_time() - started
    forces, segment = _dynamic_end_loads(built.lines, solution)
    result = MooringRun(model=built, solution=solution, times=np.asarray(solution.times),
                        end_forces=forces, segment_tensions=segment, cpu_time=cpu, dt=dt)
    if output is not None:
        folder = Path(output)
        folder.mkdir(parents=True, exist_ok=True)
        result.files["tensions"] = result.to_csv(folder / "tensions.csv")
        if built.file.outputs:
            result.files["channels"] = result.channels_csv(folder / "channels.csv")
        result.files["netcdf"] = Path(solution.save_netcdf(
            folder / "run.nc", attributes=_attributes(built, dt)) or folder / "run.nc")
        if plots:
            from vinculo.mooring.plots import plot_shapes, plot_tensions

            result.files["shapes"] = plot_shapes(result, folder / "shapes.png")
            result.files["tensions_plot"] = plot_tensions(result, folder / "tensions.png")
    return result


@dataclass(frozen=True)
class StepCheck:
    """How much a run's end tensions change when its step is halved: an estimate of its
    time-step error (:func:`check_step`).

    Arguments:
        dt: the run's step (s); the check ran at ``dt / 2``.
        change: ``(lines, 2)``: the largest change of each line's end A and end B tension over
            the stored times (N).
        peak: the largest end tension of the run at ``dt / 2`` (N).
        time: the time of the largest change (s).
        line: the line id of the largest change.
        end: its end, ``"A"`` or ``"B"``.
    """

    dt: float
    change: np.ndarray
    peak: float
    time: float
    line: int
    end: str

    @property
    def relative(self) -> float:
        """The largest change relative to the peak end tension."""
        return float(self.change.max() / self.peak) if self.peak > 0.0 else math.inf

    def summary(self) -> str:
        """One sentence: the change, where and when, and what it says of the run's error."""
        return (f"time-step check: the end tensions change by up to {self.change.max():.4g} N "
                f"({self.relative:.2%} of the peak tension {self.peak:.4g} N; line {self.line} "
                f"end {self.end} at t = {self.time:g} s) when the step is halved to "
                f"{self.dt / 2:g} s; the run's own time-step error is about as large "
                f"(a smaller --dt makes it smaller)")


def check_step(result: MooringRun, **options: Any) -> StepCheck:
    """Run the same mooring again at half the step of ``result``, stored at its times, and
    compare the end tensions: the change estimates the time-step error of ``result``.

    With the run's error e(dt) = C dt^p, the change is e(dt) - e(dt / 2) = (1 - 2^-p) e(dt):
    3/4 of the error for the trapezoidal rule's second order, half of it where the run is
    first order locally (a segment going slack or taut), so the error would be 1.3 to 2 times
    the change; the largest differences over a run (a peak shifted in time) follow that rule
    loosely. Measured, the error against a run at dt / 16 over the largest change: 1.04 and 0.98
    on the benchmark's hanging chain at 0.1 and 0.05 s steps, 1.30 on its cable at 0.05 s, 1.35
    on its chain on the seabed at 0.02 s (20 segments, 20 s); on an S-mooring snapping taut (the
    buoy of ``tests/data/moordyn/s_mooring.txt`` jerked by 12 m of surge in 6 s, 60 s, against
    1 ms steps) 1.28 at 0.02 s steps (a change of 15.9 % of the peak tension, an error of
    20.3 %: the snaps' peaks come a little early or late) and 1.16 at 0.01 s (3.8 %, 4.4 %).

    Arguments:
        result: the run to check (:func:`run`): its file and motion are run again.
        **options: its other options of :func:`run` (``start``, run options; not ``dt``,
            ``output``).

    Returns:
        The check.
    """
    half = run(result.model.file, result.model.motion, float(result.times[-1]),
               dt=result.dt / 2.0, plots=False, t_eval=result.times, **options)
    before, after = result.end_tensions, half.end_tensions
    if before.shape != after.shape:
        raise InvalidInputError(
            f"check_step: the run at dt / 2 stored {after.shape[0]} states where the run "
            f"stored {before.shape[0]}", name="dt", value=result.dt)
    difference = np.abs(before - after)
    worst = np.unravel_index(int(np.argmax(difference)), difference.shape)
    return StepCheck(dt=result.dt, change=difference.max(axis=0),
                     peak=float(np.abs(after).max()), time=float(result.times[worst[0]]),
                     line=int(result.model.file.lines[worst[1]].id), end="AB"[worst[2]])


def _whole_steps(every: float, dt: float) -> int | None:
    """The number of steps ``dt`` in the interval ``every`` (s), None unless it is a whole
    number (to 1e-9 of ``every``) of at least one."""
    steps = round(every / dt) if math.isfinite(every) and every > 0.0 else 0
    return steps if steps >= 1 and abs(steps * dt - every) <= 1e-9 * every else None


def _output_steps(every: float, dt: float) -> int:
    """The steps ``dt`` in the output interval ``every`` (s), checked to be a whole number."""
    steps = _whole_steps(every, dt)
    if steps is None:
        raise InvalidInputError(
            f"output_every = {every!r}: give a whole number of steps of {dt:g} s (the states "
            "between step ends would be interpolated, and a segment's tension from "
            "interpolated positions carries EA / l times their error)",
            name="output_every", value=every)
    return steps


def _output_grid(t_end: float, dt: float, steps: int = 1) -> np.ndarray:
    """The times 0, k dt, 2 k dt, ... (k = ``steps``) up to ``t_end``, and ``t_end`` itself (s):
    each a whole number of steps times ``dt``, the run's own step ends bit for bit."""
    times = np.arange(0, math.floor(t_end / dt + 1e-9) + 1, steps) * dt
    times = times[times < t_end - 1e-9 * dt]
    return np.append(times, t_end)


def _dynamic_end_loads(lines: list[Any], solution: Any) -> tuple[np.ndarray, np.ndarray]:
    """The end forces ``(times, lines, 2, 3)`` and end-segment tensions ``(times, lines, 2)`` of
    a run: each end segment's tension from Hooke's law at the stored positions plus its axial
    damping (``BA`` times the rate of strain, a dashpot beside each elastic segment), the tension
    a load cell at the end would measure and MoorDyn's segment tension (see
    :meth:`vinculo.mooring.line.Line.tensions`)."""
    forces, tensions = [], []
    for line in lines:
        ends = [np.asarray(f, dtype=float).reshape(-1, 3) for f in line.end_forces(solution)]
        forces.append(np.stack(ends, axis=1))
        tensions.append(np.asarray(line.tensions(solution), dtype=float)[:, [0, -1]])
    return np.stack(forces, axis=1), np.stack(tensions, axis=1)


def _attributes(built: Any, dt: float) -> dict[str, Any]:
    o = built.file.options
    return {
        "mooring_file": str(built.file.path) if built.file.path else "",
        "water_depth": o.depth,
        "water_density": o.density,
        "dt": dt,
        "lines": len(built.lines),
        "motion": built.motion.source if built.motion is not None else "still",
    }
