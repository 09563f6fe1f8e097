"""Run MoorDyn itself on a mooring file: the peer code of the comparisons and benchmarks.

MoorDyn-C's Python package (``moordyn`` on PyPI, an optional dependency) reads the same MoorDyn
v2 input file. :func:`run_moordyn` computes MoorDyn's initial state (its own initial-condition
solve, or loads one that :func:`moordyn_initial_state` saved), then moves the coupled points by
a :class:`~vinculo.mooring.motion.Motion` and records the force of each line on each of its end
points and, if asked, the lines' node positions. :func:`largest_stable_step` finds MoorDyn's
largest stable time step on a case by bisection.

MoorDyn's initial-condition solve is a dynamic relaxation in its own time step (up to the
file's ``TmaxIC`` of simulated time): on a 1,000-segment line it costs minutes, more than the run
after it. A study that runs one file many times (the bisection on the step, the benchmark)
computes it once with :func:`moordyn_initial_state` and starts every run from the saved state
(MoorDyn's ``SaveState`` and ``LoadState``): the equilibrium does not depend on the step.

MoorDyn writes a main output file next to its input file, so each run works on a copy of the
file in a temporary folder; its console messages are silenced.

MoorDyn integrates explicitly (second-order Runge-Kutta by default) with the time step ``dtM``;
each call of its ``Step`` advances the coupling interval in steps of at most ``dtM``, moving the
coupled points with the position and velocity given at the start of the interval (every
:data:`COUPLING_STEP` by default, as a coupled simulation would call it).
"""

from __future__ import annotations

import contextlib
import math
import os
import shutil
import sys
import tempfile
import time
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from vinculo.errors import InvalidInputError, VinculoError
from vinculo.mooring.moordyn_file import MoorDynFile, read_moordyn, write_moordyn
from vinculo.mooring.motion import Motion

__all__ = [
    "COUPLING_STEP",
    "PeerError",
    "PeerRun",
    "largest_stable_step",
    "moordyn_available",
    "moordyn_initial_state",
    "run_moordyn",
    "settled_end_forces",
]


#: The default interval between calls of MoorDyn's Step (s).
COUPLING_STEP = 0.01


class PeerError(VinculoError, RuntimeError):
    """MoorDyn failed: it is not installed, it rejected the file, or its run blew up.

    Attributes:
        time: the time at which the run failed (s; None when it did not start).
    """

    time: float | None = None


def moordyn_available() -> bool:
    """Whether MoorDyn's Python package can be imported.

    Returns:
        True when ``import moordyn`` works.
    """
    try:
        import moordyn  # noqa: F401
    except ImportError:
        return False
    return True


def _moordyn():
    try:
        import moordyn
    except ImportError:
        raise PeerError("MoorDyn's Python package is not installed: pip install moordyn "
                        "(vinculo's requirements-dev.txt pins it)") from None
    return moordyn


@contextlib.contextmanager
def _silenced() -> Iterator[None]:
    """Send what MoorDyn's C++ code prints (to the process's stdout and stderr) to nowhere."""
    sys.stdout.flush()
    sys.stderr.flush()
    saved = [os.dup(1), os.dup(2)]
    null = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(null, 1)
        os.dup2(null, 2)
        yield
    finally:
        os.dup2(saved[0], 1)
        os.dup2(saved[1], 2)
        for fd in (*saved, null):
            os.close(fd)


@dataclass
class PeerRun:
    """What a MoorDyn run recorded.

    Arguments:
        times: the output times (s), from 0.
        end_forces: ``(times, lines, 2, 3)``: the force of each line on its end A (index 0)
            and end B (index 1), in N, the sum of the line's tension and of the loads on its
            end node (MoorDyn lumps half a segment at each end node).
        segment_tensions: ``(times, lines, 2)``: the tension of each line's first and last
            segment (N), the line's own tension at its ends without the loads MoorDyn lumps on
            the end nodes (their weight, drag and added mass).
        node_positions: for each line, ``(times, nodes, 3)`` positions (m); empty when not
            stored.
        time_step: MoorDyn's time step dtM (s).
        coupling_step: the interval between calls of MoorDyn's Step (s).
        cpu_time: the CPU time of the time stepping (s), without the initial condition.
        initial_cpu_time: the CPU time of MoorDyn's initial-condition solve (s).
        steps: the number of MoorDyn time steps taken.
        error: why the run stopped early (None when it reached the end).
    """

    times: np.ndarray
    end_forces: np.ndarray
    segment_tensions: np.ndarray
    node_positions: list[np.ndarray] = field(default_factory=list)
    time_step: float = math.nan
    coupling_step: float = math.nan
    cpu_time: float = 0.0
    initial_cpu_time: float = 0.0
    steps: int = 0
    error: str | None = None

    @property
    def end_tensions(self) -> np.ndarray:
        """``(times, lines, 2)``: the magnitude of each end force (N)."""
        return np.linalg.norm(self.end_forces, axis=-1)


#: How much larger than the step MoorDyn is asked to take its file's dtM is written: MoorDyn's
#: Step takes steps of dtM until less than dtM of the call is left, then one step of the rest,
#: so a call of k steps computed in floating point could end with a step of 1e-19 s, or one of
#: a millionth of dtM where the call is a hair longer than k dtM. With dtM a billionth larger,
#: a call of k steps takes k steps, the last shorter by k billionths of a step.
_STEP_MARGIN = 1e-9


def _dividing_step(time_step: float, dt_output: float) -> tuple[float, int]:
    """The largest step at most ``time_step`` that divides ``dt_output``, and how many of it
    make ``dt_output``: every output time is then the end of a MoorDyn step, and a call of
    whole steps takes exactly those steps (:data:`_STEP_MARGIN`)."""
    steps = max(1, math.ceil(dt_output / time_step - 1e-9))
    return dt_output / steps, steps


def _model_and_file(source: str | Path | MoorDynFile, folder: Path,
                    time_step: float | None) -> tuple[MoorDynFile, Path]:
    """The model, and a copy of its file in ``folder`` (with ``dtM`` replaced if asked)."""
    import dataclasses

    model = source if isinstance(source, MoorDynFile) else read_moordyn(source)
    if time_step is not None:
        model = dataclasses.replace(
            model, options=dataclasses.replace(model.options, time_step=float(time_step)))
    if isinstance(source, MoorDynFile) or time_step is not None or (
            model.options.seafloor is not None or model.options.current is not None
            or model.options.waves is not None
            or any(t.ea_curve is not None for t in model.line_types.values())):
        # Written again: a seafloor file and stiffness curves are then named by their absolute
        # paths, which MoorDyn finds from any working directory, and a current profile written
        # beside it.
        path = write_moordyn(model, folder / "mooring.txt")
    else:
        path = Path(shutil.copy(source, folder / "mooring.txt"))
    return model, path


def _end_forces(md, lines: list, sizes: list[int]) -> tuple[np.ndarray, np.ndarray]:
    forces = np.empty((len(lines), 2, 3))
    tensions = np.empty((len(lines), 2))
    for k, (line, n) in enumerate(zip(lines, sizes, strict=True)):
        forces[k, 0] = md.GetLineNodeForce(line, 0)
        forces[k, 1] = md.GetLineNodeForce(line, n)
        tensions[k, 0] = np.linalg.norm(md.GetLineNodeTen(line, 0))
        tensions[k, 1] = np.linalg.norm(md.GetLineNodeTen(line, n))
    return forces, tensions


def _coupled_motion(model: MoorDynFile, motion: Motion | None) -> Motion:
    """The motion of the model's coupled points (theirs at the file's positions, still, when
    None), checked against them; with coupled bodies, the bodies' poses too, which MoorDyn
    takes as six coupled degrees of freedom each."""
    from vinculo.mooring.motion import still_motion

    coupled, bodies = model.coupled_points(), model.coupled_bodies()
    if motion is None:
        motion = still_motion(model)
    if motion.num_points != len(coupled):
        raise InvalidInputError(
            f"the motion moves {motion.num_points} points but the file has "
            f"{len(coupled)} coupled points", name="motion", value=motion.num_points)
    if len(motion.poses) != len(bodies):
        raise InvalidInputError(
            f"the file has {len(bodies)} coupled bodies and {motion.source} gives the poses of "
            f"{len(motion.poses)}: read the motion file with vinculo.mooring.read_motion(model, "
            f"path), which keeps them for MoorDyn's six degrees of freedom a body",
            name="motion", value=len(motion.poses))
    return motion


def run_moordyn(source: str | Path | MoorDynFile, motion: Motion | None, t_end: float, *,
                dt_output: float = 0.1, coupling_step: float | None = None,
                time_step: float | None = None, store_shapes: bool = False,
                initial_state: str | Path | None = None) -> PeerRun:
    """Run MoorDyn on a mooring file with the coupled points moved by ``motion``.

    Arguments:
        source: the MoorDyn input file, or a model to write to one.
        motion: the coupled points' motion (None: they stay at the file's positions).
        t_end: the end time (s).
        dt_output: the interval between stored outputs (s).
        coupling_step: the interval between calls of MoorDyn's Step (s; default
            :data:`COUPLING_STEP`, or dtM when larger, at most ``dt_output``): MoorDyn moves the
            coupled points at a constant velocity over each call (here the chord velocity, so
            that they reach the motion's position at the call's end), so the velocity jumps
            from one call to the next and the axial dashpots feel the jumps: on the hanging
            chain (20 segments, 0.2 ms steps), calls every 0.01 s change the fairlead
            segment's tension by 0.8 % of its peak against calls at every step, calls every
            0.1 s by 3.5 % (9 % at the anchor). Calls at every step (the coupling step equal
            to ``time_step``) follow the motion as closely as MoorDyn allows: at the chord
            velocity through each step, half a step's change of velocity from the motion's at
            the step's start, which makes MoorDyn's tensions first order in its step under a
            moving fairlead (the work-precision benchmark, :mod:`vinculo.mooring.work_precision`).
        time_step: MoorDyn's time step dtM (s; default: the file's, run as the file says, as
            MoorDyn itself would: a call that is not a whole number of its steps ends with a
            shorter one, as in a coupled simulation with that file); given, the run takes the
            largest step at most this that divides ``dt_output`` (``PeerRun.time_step``), so
            that every output time ends a step, and calls MoorDyn with whole numbers of steps
            (a call at every step when ``coupling_step`` is the step asked), which it then takes
            exactly.
        store_shapes: also store every line's node positions at each output time.
        initial_state: a state file of :func:`moordyn_initial_state` for the same file and
            motion to start from (None: MoorDyn's own initial-condition solve).

    Returns:
        What the run recorded; a run that blew up (NaN) stops there with ``error`` set.

    Raises:
        PeerError: when MoorDyn is not installed or rejects the file.
        MooringFileError: when the file itself is malformed (read by vinculo first).
        InvalidInputError: for a motion with the wrong number of points or times out of range.
    """
    md = _moordyn()
    if not (math.isfinite(t_end) and t_end > 0.0 and dt_output > 0.0):
        raise InvalidInputError(f"run_moordyn: t_end = {t_end!r} and dt_output = {dt_output!r} "
                                f"must be positive", name="t_end", value=t_end)
    steps_per_output = None
    if time_step is not None:
        if not (math.isfinite(time_step) and time_step > 0.0):
            raise InvalidInputError(f"run_moordyn: time_step = {time_step!r}: give a step > 0 s",
                                    name="time_step", value=time_step)
        time_step, steps_per_output = _dividing_step(float(time_step), dt_output)
    with tempfile.TemporaryDirectory(prefix="vinculo-moordyn-") as folder:
        model, path = _model_and_file(
            source, Path(folder),
            None if time_step is None else time_step * (1.0 + _STEP_MARGIN))
        if steps_per_output is None:
            dtm = model.options.time_step if model.options.time_step is not None else 1e-3
            coupling = float(coupling_step or min(dt_output, max(COUPLING_STEP, dtm)))
            per_output = max(1, round(dt_output / coupling))
            coupling = dt_output / per_output
            steps_per_call = math.ceil(coupling / dtm - 1e-9)
        else:
            dtm = time_step
            wanted = float(coupling_step or min(dt_output, max(COUPLING_STEP, dtm)))
            steps_per_call = max(k for k in range(1, steps_per_output + 1)
                                 if steps_per_output % k == 0
                                 and k * dtm <= wanted * (1.0 + 1e-9))
            per_output = steps_per_output // steps_per_call
            coupling = dt_output / per_output
        coupled = model.coupled_points()
        motion = _coupled_motion(model, motion)
        start, end = motion.domain()
        if start > 0.0 or end < t_end:
            raise InvalidInputError(
                f"{motion.source} covers t = {start:g} to {end:g} s; the run needs 0 to "
                f"{t_end:g} s", name="t_end", value=t_end)
        with _silenced():
            system = _create(md, path)
            try:
                lines = [md.GetLine(system, k + 1) for k in range(len(model.lines))]
                sizes = [md.GetLineN(line) for line in lines]
                x = motion.coupled_dofs(0.0).tolist()
                v = motion.coupled_dof_rates(0.0).tolist()
                started = time.process_time()
                _initialise(md, system, x, v, initial_state)
                initial_cpu = time.process_time() - started
                outputs = math.floor(t_end / dt_output + 1e-9) + 1
                times = np.arange(outputs) * dt_output
                forces = np.full((outputs, len(lines), 2, 3), np.nan)
                segment = np.full((outputs, len(lines), 2), np.nan)
                shapes = [np.full((outputs, n + 1, 3), np.nan) for n in sizes] if store_shapes \
                    else []

                def record(i: int) -> None:
                    forces[i], segment[i] = _end_forces(md, lines, sizes)
                    for k, (line, n) in enumerate(zip(lines, sizes, strict=True)):
                        if store_shapes:
                            shapes[k][i] = [md.GetLineNodePos(line, j) for j in range(n + 1)]

                if initial_state is not None:
                    # A loaded state has no forces until a step: those saved with it.
                    forces[0], segment[0] = _saved_forces(initial_state, forces[0].shape)
                else:
                    if coupled:
                        md.Step(system, x, v, 0.0, 0.0)  # the forces at t = 0
                    record(0)
                error = None
                cpu = 0.0
                t = 0.0
                for i in range(1, outputs):
                    for _ in range(per_output):
                        # The chord velocity over the call: MoorDyn moves the points at the
                        # velocity given, so they reach the motion's position at the call's
                        # end and the path is continuous (the motion's own velocity at the
                        # call's start would leave them a v' dt^2 / 2 jump at each call).
                        x = motion.coupled_dofs(t)
                        v = ((motion.coupled_dofs(t + coupling) - x) / coupling).tolist()
                        x = x.tolist()
                        tick = time.process_time()
                        try:
                            md.Step(system, x, v, t, coupling)
                        except RuntimeError as exc:
                            cpu += time.process_time() - tick
                            error = f"MoorDyn failed at t = {t:g} s: {exc}"
                            break
                        cpu += time.process_time() - tick
                        t += coupling
                    if error is not None:
                        times, forces, segment = times[:i], forces[:i], segment[:i]
                        shapes = [s[:i] for s in shapes]
                        break
                    record(i)
                    if not np.all(np.isfinite(forces[i])):
                        error = f"MoorDyn's forces are not finite at t = {times[i]:g} s"
                        times, forces = times[: i + 1], forces[: i + 1]
                        segment = segment[: i + 1]
                        shapes = [s[: i + 1] for s in shapes]
                        break
            finally:
                md.Close(system)
    steps = (times.size - 1) * per_output * steps_per_call
    return PeerRun(times=times, end_forces=forces, segment_tensions=segment,
                   node_positions=shapes, time_step=dtm,
                   coupling_step=coupling, cpu_time=cpu, initial_cpu_time=initial_cpu,
                   steps=steps, error=error)


def _create(md, path: Path):
    """MoorDyn's system of the input file ``path``."""
    try:
        return md.Create(str(path))
    except Exception as exc:  # MoorDyn raises a bare RuntimeError
        raise PeerError(f"MoorDyn rejected {path.name}: {exc}") from None


def _initialise(md, system, x: list[float], v: list[float],
                initial_state: str | Path | None) -> None:
    """MoorDyn's initial state: its own solve, or the saved ``initial_state``."""
    if initial_state is None:
        if md.Init(system, x, v) != 0:
            raise PeerError("MoorDyn's initial condition failed", time=0.0)
        return
    state = Path(initial_state)
    if not state.is_file():
        raise InvalidInputError(f"initial_state {state}: no such file (make it with "
                                f"moordyn_initial_state)", name="initial_state", value=str(state))
    if md.Init_NoIC(system, x, v) != 0:
        raise PeerError("MoorDyn did not initialise", time=0.0)
    md.LoadState(system, str(state))


def _forces_file(state: str | Path) -> Path:
    """The file beside a saved state that holds the end forces at t = 0."""
    return Path(f"{state}.forces.npz")


def _saved_forces(state: str | Path, shape: tuple[int, ...]) -> tuple[np.ndarray, np.ndarray]:
    with np.load(_forces_file(state)) as saved:
        forces, tensions = saved["end_forces"], saved["segment_tensions"]
    if forces.shape != shape:
        raise InvalidInputError(f"initial_state {state} holds {forces.shape[0]} lines, the "
                                f"file {shape[0]}: make it from the same file",
                                name="initial_state", value=str(state))
    return forces, tensions


def moordyn_initial_state(source: str | Path | MoorDynFile, motion: Motion | None,
                          path: str | Path, *, time_step: float | None = None) -> Path:
    """Compute MoorDyn's initial state of a file once and save it, for :func:`run_moordyn`'s
    ``initial_state``.

    Arguments:
        source: the MoorDyn input file, or a model to write to one.
        motion: the coupled points' motion (its position and velocity at t = 0 are used;
            None: the file's positions, at rest).
        path: the state file to write.
        time_step: MoorDyn's time step dtM for the solve (s; default: the file's); its
            dynamic relaxation needs a stable one. Written as :func:`run_moordyn` writes a
            step that divides its output interval (:data:`_STEP_MARGIN`), so that a run at
            such a step from its own solve and one from this state are the same.

    Returns:
        ``path``. The end forces at t = 0 go beside it, into ``<path>.forces.npz`` (MoorDyn
        computes none for a loaded state until its first step).

    Raises:
        PeerError: when MoorDyn is not installed, rejects the file or its solve fails.
    """
    md = _moordyn()
    path = Path(path).resolve()
    with tempfile.TemporaryDirectory(prefix="vinculo-moordyn-") as folder:
        model, file = _model_and_file(
            source, Path(folder),
            None if time_step is None else time_step * (1.0 + _STEP_MARGIN))
        coupled = model.coupled_points()
        motion = _coupled_motion(model, motion)
        x = motion.coupled_dofs(0.0).tolist()
        v = motion.coupled_dof_rates(0.0).tolist()
        with _silenced():
            system = _create(md, file)
            try:
                _initialise(md, system, x, v, None)
                md.SaveState(system, str(path))
                lines = [md.GetLine(system, k + 1) for k in range(len(model.lines))]
                if coupled:
                    md.Step(system, x, v, 0.0, 0.0)  # the forces at t = 0
                forces, tensions = _end_forces(md, lines, [md.GetLineN(a) for a in lines])
            finally:
                md.Close(system)
    np.savez(_forces_file(path), end_forces=forces, segment_tensions=tensions)
    return path


def settled_end_forces(source: str | Path | MoorDynFile, t_end: float, settle: float, *,
                       dt_output: float = 0.5) -> np.ndarray:
    """MoorDyn's equilibrium by its dynamics: the mean of each line's end forces over
    ``[settle, t_end]`` of a run with the coupled points held where the file puts them.

    MoorDyn's own initial condition leaves a file's current and waves out and can stop short
    on a sloping seabed; its dynamics from there settle about the equilibrium (with the light
    oscillation that its damping leaves, which the mean averages out).

    Arguments:
        source: the MoorDyn input file, or a model to write to one.
        t_end: the end of the run (s).
        settle: the time from which its forces are averaged (s, below ``t_end``).
        dt_output: the interval of the forces averaged (s).

    Returns:
        ``(lines, 2, 3)``: the mean force of each line on its end A and end B (N).

    Raises:
        PeerError: when MoorDyn is not installed, rejects the file or blows up.
        InvalidInputError: for a ``settle`` not below ``t_end``.
    """
    if not 0.0 <= settle < t_end:
        raise InvalidInputError(f"settled_end_forces: settle = {settle!r} s: give a time in "
                                f"[0, t_end = {t_end!r})", name="settle", value=settle)
    run = run_moordyn(source, None, t_end, dt_output=dt_output)
    if run.error is not None:
        raise PeerError(f"MoorDyn did not settle: {run.error}")
    later = np.asarray(run.times) >= settle
    return np.asarray(run.end_forces)[later].mean(axis=0)


def largest_stable_step(source: str | Path | MoorDynFile, motion: Motion | None, t_end: float,
                        reference: PeerRun | None = None, *, low: float, high: float,
                        tolerance: float = 0.05, ratio: float = 1.1,
                        dt_output: float = 0.1, exact_motion: bool = False,
                        initial_state: str | Path | None = None) -> tuple[float, int]:
    """MoorDyn's largest stable time step on a case, by bisection on dtM.

    With a ``reference`` (a run at a small step with the same ``dt_output``), a step is stable
    when the run reaches ``t_end`` with end tensions within ``tolerance`` (relative to the
    largest reference tension) of the reference's. Without one, when the run reaches ``t_end``
    with finite forces whose tensions never exceed ten times their largest value at t = 0 (no
    blow-up).

    Arguments:
        source: the MoorDyn input file or model.
        motion: the coupled points' motion.
        t_end: the end time (s).
        reference: a run at a step known to be stable and accurate (None: the blow-up test).
        low: a step thought to be stable (s); halved until it is.
        high: a step thought to be above the stable range (s); doubled until it is.
        tolerance: the largest relative difference in end tension accepted.
        ratio: stop when ``high / low`` is below this.
        dt_output: the output interval (s), the same as the reference's.
        exact_motion: call MoorDyn's Step at every one of its steps, so that the coupled points
            follow the motion exactly (False: every :data:`COUPLING_STEP`).
        initial_state: a saved initial state to start every run from (see
            :func:`moordyn_initial_state`; None: each run computes its own).

    Returns:
        ``(step, runs)``: the largest stable step found (s) and the number of MoorDyn runs.

    Raises:
        PeerError: when no step down to a millionth of ``low`` is stable.
    """
    scale = float(np.nanmax(reference.end_tensions)) if reference is not None else math.nan
    runs = 0

    def stable(dt: float) -> bool:
        nonlocal runs
        runs += 1
        run = run_moordyn(source, motion, t_end, dt_output=dt_output, time_step=dt,
                          coupling_step=dt if exact_motion else None,
                          initial_state=initial_state)
        if run.error is not None or run.times.size < round(t_end / dt_output) + 1:
            return False
        tensions = run.end_tensions
        if not np.all(np.isfinite(tensions)):
            return False
        if reference is None:
            return bool(tensions.max() <= 10.0 * max(tensions[0].max(), 1e-300))
        if run.times.size != reference.times.size:
            return False
        return bool(np.abs(tensions - reference.end_tensions).max() <= tolerance * scale)

    floor = low * 1e-6
    while not stable(low):
        high, low = low, low / 2.0
        if low < floor:
            raise PeerError(f"MoorDyn found no stable step down to {floor:g} s")
    for _ in range(20):
        if not stable(high):
            break
        low, high = high, 2.0 * high
    while high / low > ratio:
        middle = math.sqrt(low * high)
        if stable(middle):
            low = middle
        else:
            high = middle
    return low, runs
