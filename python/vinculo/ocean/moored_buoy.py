"""A buoy moored in the sea: a rigid body with a hull in waves and currents, held by mooring
lines from a MoorDyn file, as one monolithic system (docs/guide/moored-buoy.md).

The case is a TOML file (:func:`read_case`; ``examples/moored_buoy/`` has a surface buoy on
three chains and the submerged buoy of the case study in an open basin):

- ``[buoy]``: mass, centre of gravity at rest (a guess the statics corrects), inertia (three
  principal moments or a 3x3 tensor), the hull in the body's frame with its origin at the
  centre of gravity (a list of ``{kind = "cylinder" | "sphere" | "frustum", ...}`` sections),
  ``ca``, ``cd``, ``drag_area``, ``layers``;
- ``[mooring]``: ``file``, a MoorDyn v2 file whose Coupled (Vessel) points are the fairleads:
  points of the buoy, where the file puts them with the buoy at its ``centre``; its depth,
  density and gravity are the sea's;
- ``[sea]``: ``waves`` (``{kind = "regular", height, period}``, ``{kind = "jonswap", hs, tp,
  gamma, seed, components, spreading, directions}``, ``{kind = "record", file}`` (a measured
  elevation at the buoy: CSV of time and elevation), or none), ``direction``, ``current``
  (``{kind = "uniform" | "power" | "table", velocity, z}``), ``stretching``, ``ramp`` (s);
- ``[run]``: ``t_end``, ``dt``; ``[rao]``: ``periods``, ``height``, ``cycles``.

:func:`build` makes the system (the buoy, its floating-body loads, the lines in the same water,
each fairlead held to its point of the buoy by three relative-coordinate constraints) and puts
it in static equilibrium; :func:`run` integrates it and returns motions, fairlead and anchor
tensions and the elevation at the buoy; :func:`rao` sweeps regular waves; :func:`write`
draws the plots and writes CSV and NetCDF files.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np
import tomllib

from vinculo.errors import InvalidInputError
from vinculo.ocean.hull import Hull, cylinder, frustum, sphere
from vinculo.ocean.sea import Current, Sea
from vinculo.ocean.spectra import from_elevation

__all__ = ["Built", "MooredBuoyCase", "MooredBuoyRun", "RaoTable", "build", "rao", "read_case",
           "run", "write"]

MOTIONS = ("surge", "sway", "heave", "roll", "pitch", "yaw")


@dataclass(frozen=True)
class MooredBuoyCase:
    """A moored-buoy case (see the module documentation for the file).

    Arguments:
        mass: the buoy's mass (kg).
        centre: its centre of gravity at rest, a guess (m).
        inertia: its inertia tensor about the centre of gravity (kg m^2).
        hull: its hull, origin at the centre of gravity.
        ca: added-mass coefficient.
        cd: drag coefficient.
        drag_area: the drag's frontal area (m^2).
        layers: the hull's layers.
        mooring: the MoorDyn file of the lines (None: a free-floating buoy).
        sea: the sea (its depth, density and gravity those of the mooring file).
        t_end: the run's length (s).
        dt: the time step (s).
        rao_periods: the regular-wave periods of the RAO sweep (s).
        rao_height: their wave height (m).
        rao_cycles: periods simulated per RAO run after the ramp (the last half measured).
        title: a title for plots.
    """

    mass: float
    centre: tuple[float, float, float]
    inertia: np.ndarray
    hull: Hull
    sea: Sea
    mooring: Path | None = None
    ca: float = 0.0
    cd: float = 0.0
    drag_area: float = 0.0
    layers: int = 40
    t_end: float = 120.0
    dt: float = 0.05
    rao_periods: tuple[float, ...] = ()
    rao_height: float = 0.2
    rao_cycles: int = 8
    title: str = "moored buoy"


def _number(table: dict[str, Any], key: str, where: str, default: float | None = None) -> float:
    if key not in table:
        if default is None:
            raise InvalidInputError(f"{where}: {key} is missing", name=key, value=None)
        return default
    value = table[key]
    if not isinstance(value, (int, float)) or not math.isfinite(value):
        raise InvalidInputError(f"{where}: {key} = {value!r}: give a number", name=key,
                                value=value)
    return float(value)


def _hull(sections: Any, where: str) -> Hull:
    if not isinstance(sections, list) or not sections:
        raise InvalidInputError(f"{where}: hull: give a list of sections", name="hull",
                                value=sections)
    parts: list[Hull] = []
    for k, s in enumerate(sections):
        at = f"{where}: hull section {k + 1}"
        kind = s.get("kind") if isinstance(s, dict) else None
        if kind == "sphere":
            parts.append(sphere(_number(s, "radius", at), _number(s, "centre", at, 0.0)))
        elif kind == "cylinder":
            parts.append(cylinder(_number(s, "radius", at), _number(s, "bottom", at),
                                  _number(s, "top", at)))
        elif kind == "frustum":
            parts.append(frustum(_number(s, "bottom", at), _number(s, "top", at),
                                 _number(s, "r_bottom", at), _number(s, "r_top", at)))
        else:
            raise InvalidInputError(f"{at}: kind = {kind!r}: give \"sphere\", \"cylinder\" or "
                                    "\"frustum\"", name="kind", value=kind)
    hull = parts[0]
    for p in parts[1:]:
        hull = hull + p
    return hull


def _sea(table: dict[str, Any], depth: float, density: float, g: float, where: str,
         folder: Path) -> Sea:
    waves = table.get("waves")
    direction = math.radians(_number(table, "direction", where, 0.0))
    options: dict[str, Any] = {"density": density, "g": g,
                               "ramp": _number(table, "ramp", where, 0.0),
                               "stretching": table.get("stretching", "wheeler")}
    current = table.get("current")
    if current is not None:
        kind = current.get("kind", "uniform")
        velocity = current.get("velocity")
        if kind == "uniform":
            options["current"] = Current.uniform(velocity)
        elif kind == "power":
            options["current"] = Current.power_law(velocity,
                                                   _number(current, "exponent", where, 1 / 7))
        elif kind == "table":
            options["current"] = Current.table(current.get("z", []), velocity)
        else:
            raise InvalidInputError(f"{where}: current kind = {kind!r}: give \"uniform\", "
                                    "\"power\" or \"table\"", name="current", value=kind)
    if waves is None:
        return Sea(depth, **options)
    kind = waves.get("kind")
    if kind == "regular":
        return Sea.regular(_number(waves, "height", where), _number(waves, "period", where),
                           depth, direction=direction, **options)
    if kind in ("jonswap", "pierson-moskowitz"):
        gamma = 1.0 if kind == "pierson-moskowitz" else _number(waves, "gamma", where, 3.3)
        spreading = waves.get("spreading")
        return Sea.irregular(_number(waves, "hs", where), _number(waves, "tp", where), depth,
                             gamma=gamma, seed=int(waves.get("seed", 0)),
                             count=int(waves.get("components", 100)), direction=direction,
                             spreading_exponent=None if spreading is None else float(spreading),
                             directions=int(waves.get("directions", 9)), **options)
    if kind == "record":
        # A measured elevation at the buoy's position: CSV of time (s) and elevation (m).
        record = folder / str(waves.get("file", ""))
        try:
            data = np.loadtxt(record, delimiter=",", skiprows=1, ndmin=2)
        except (OSError, ValueError) as e:
            raise InvalidInputError(f"{where}: waves record {record}: {e}: give a CSV file "
                                    "with a header line, then rows of time (s), elevation (m)",
                                    name="file", value=str(record)) from e
        if data.shape[1] < 2:
            raise InvalidInputError(f"{where}: waves record {record} has {data.shape[1]} "
                                    "column: give time (s), elevation (m)", name="file",
                                    value=str(record))
        return Sea(depth, from_elevation(data[:, 0], data[:, 1], direction), **options)
    raise InvalidInputError(f"{where}: waves kind = {kind!r}: give \"regular\", \"jonswap\", "
                            "\"pierson-moskowitz\" or \"record\"", name="waves", value=kind)


def read_case(path: str | Path) -> MooredBuoyCase:
    """Read a moored-buoy case file.

    Arguments:
        path: the TOML file.

    Returns:
        The case (the mooring file's path made absolute).

    Raises:
        InvalidInputError: a missing or malformed entry, named with the file.
    """
    from vinculo.mooring.moordyn_file import read_moordyn

    path = Path(path)
    try:
        data = tomllib.loads(path.read_text())
    except (OSError, tomllib.TOMLDecodeError) as e:
        raise InvalidInputError(f"{path}: {e}", name="case", value=str(path)) from e
    buoy = data.get("buoy")
    if not isinstance(buoy, dict):
        raise InvalidInputError(f"{path}: the [buoy] table is missing", name="buoy", value=None)
    where = f"{path} [buoy]"
    centre = buoy.get("centre")
    if not (isinstance(centre, list) and len(centre) == 3):
        raise InvalidInputError(f"{where}: centre = {centre!r}: give [x, y, z] (m)",
                                name="centre", value=centre)
    inertia = np.asarray(buoy.get("inertia"), dtype=float)
    if inertia.shape == (3,):
        inertia = np.diag(inertia)
    if inertia.shape != (3, 3):
        raise InvalidInputError(f"{where}: inertia: give 3 principal moments or a 3x3 tensor "
                                "(kg m^2)", name="inertia", value=inertia.shape)
    mooring = data.get("mooring", {}).get("file")
    mooring_path = (path.parent / mooring).resolve() if mooring else None
    if mooring_path is not None:
        options = read_moordyn(mooring_path).options
        depth, density, g = options.depth, options.density, options.gravity
    else:
        depth = _number(data.get("sea", {}), "depth", f"{path} [sea]")
        density, g = 1025.0, 9.80665
    run_table = data.get("run", {})
    rao_table = data.get("rao", {})
    return MooredBuoyCase(
        mass=_number(buoy, "mass", where), centre=tuple(float(c) for c in centre),
        inertia=inertia, hull=_hull(buoy.get("hull"), where),
        sea=_sea(data.get("sea", {}), depth, density, g, f"{path} [sea]", path.parent),
        mooring=mooring_path, ca=_number(buoy, "ca", where, 0.0),
        cd=_number(buoy, "cd", where, 0.0), drag_area=_number(buoy, "drag_area", where, 0.0),
        layers=int(buoy.get("layers", 40)),
        t_end=_number(run_table, "t_end", f"{path} [run]", 120.0),
        dt=_number(run_table, "dt", f"{path} [run]", 0.05),
        rao_periods=tuple(float(p) for p in rao_table.get("periods", ())),
        rao_height=_number(rao_table, "height", f"{path} [rao]", 0.2),
        rao_cycles=int(rao_table.get("cycles", 8)),
        title=str(data.get("title", path.stem)))


@dataclass
class Built:
    """A case's system in static equilibrium.

    Arguments:
        case: the case.
        system: the :class:`vinculo.System`.
        body: the buoy (``add_rigid_body``'s dict).
        lines: the mooring lines (:class:`vinculo.mooring.line.Line`).
        fairleads: per line, which end is on the buoy (0: end A, 1: end B, None: neither).
        statics: the static equilibrium (None for a free-floating buoy not solved).
    """

    case: MooredBuoyCase
    system: Any
    body: dict[str, Any]
    lines: list[Any] = field(default_factory=list)
    fairleads: list[int | None] = field(default_factory=list)
    statics: Any = None


def build(case: MooredBuoyCase, *, solve: bool = True) -> Built:
    """The case's system: the buoy, its floating-body loads, the mooring lines, the sea.

    Arguments:
        case: the case.
        solve: put it in static equilibrium (in still water, the current included). A
            free-floating buoy (no mooring file) has no stiffness in surge, sway and yaw, so
            no equilibrium to solve for: it starts where the case puts it. A buoy whose lines
            hold no yaw (one line on its axis) has a neutral yaw, which leaves the equilibrium
            equations singular: it is then solved with the yaw held by one more constraint,
            and the system (without it) starts from that equilibrium.

    Returns:
        The built system.

    Raises:
        InvalidInputError: a bad case or mooring file.
        ConvergenceError: when the static equilibrium is not found.
    """
    from vinculo.errors import ConvergenceError
    from vinculo.mooring.statics import solve_statics

    built = _assemble(case)
    if solve and built.lines:
        # The equilibrium in the current without waves; the run's water comes after.
        still = replace(case.sea, waves=Sea(case.sea.depth).waves).water()
        built.system.set_water(still)
        try:
            built.statics = solve_statics(built.system)
        except ConvergenceError:
            held = _assemble(case, hold_yaw=True)
            held.system.set_water(still)
            built.statics = solve_statics(held.system)
            built.statics.apply(built.system)
    built.system.set_water(case.sea.water())
    return built


def _assemble(case: MooredBuoyCase, hold_yaw: bool = False) -> Built:
    """The system of :func:`build`, not solved; ``hold_yaw`` keeps one horizontal axis of the
    body in its vertical plane, (v - c) . n = 0 with n the horizontal normal of that plane
    (which holds the yaw and leaves roll and pitch free)."""
    import vinculo
    from vinculo.mooring.model import build_model

    if case.mooring is not None:
        model = build_model(case.mooring, solve=False, couple=False)
        options = model.file.options
        if options.current is not None or options.waves is not None:
            # The case's sea is the water of the whole run: a second current or second waves
            # would be ignored.
            key = "Currents 1" if options.current is not None else "WaveKin 7"
            raise InvalidInputError(
                f"{case.mooring}: {key}: the lines' current and waves come from the case's "
                f"sea here; set Currents and WaveKin to 0 in the MoorDyn file",
                name=key.split()[0], value=key)
        system, lines = model.system, model.lines
        coupled = {p.id for p in model.file.points if p.attachment == "coupled"}
        fairlead_points = [model.points[p.id - 1] for p in model.file.points
                           if p.attachment == "coupled"]
    else:
        system = vinculo.System(gravity=(0.0, 0.0, -case.sea.g))
        lines, coupled, fairlead_points, model = [], set(), [], None
    body = system.add_rigid_body(case.mass, case.centre, case.inertia)
    system.add_floating_body(body, case.hull, origin=case.centre, density=case.sea.density,
                             ca=case.ca, cd=case.cd, drag_area=case.drag_area,
                             layers=case.layers)
    q0 = np.asarray(system.initial_positions())
    for particle in fairlead_points:
        point = system.point(body, tuple(float(c) for c in q0[particle.index]))
        for axis in range(3):
            system.add_relative_coordinate(point, particle, axis, 0.0)
    if hold_yaw:
        centre = q0[body["centre"].index]
        arms = [q0[v.index] - centre for v in body["vertices"][::2]]
        arm = min(arms, key=lambda a: abs(a[2]) / np.linalg.norm(a))  # the most horizontal
        normal = np.array([-arm[1], arm[0], 0.0]) / math.hypot(arm[0], arm[1])
        origin = system.point(None, (0.0, 0.0, 0.0))
        tip = system.point(None, tuple(float(c) for c in normal))
        vertex = body["vertices"][2 * [id(a) for a in arms].index(id(arm))]
        system.add_dot_product(body["centre"], vertex, origin, tip, 0.0)
    fairleads: list[int | None] = []
    if model is not None:
        for row in model.file.lines:
            fairleads.append(1 if row.attach_b in coupled else 0 if row.attach_a in coupled
                             else None)
    return Built(case=case, system=system, body=body, lines=list(lines), fairleads=fairleads)


@dataclass
class MooredBuoyRun:
    """A run of a moored-buoy case.

    Arguments:
        built: the system it ran.
        solution: the :class:`vinculo.Solution`.
        times: the stored times (s).
        motions: ``(times, 6)``: surge, sway, heave (m) of the centre of gravity from its
            equilibrium, and roll, pitch, yaw (rad, z-y-x angles of the body's rotation).
        tensions: ``(times, lines, 2)``: each line's fairlead and anchor tension (N; the
            segments at the buoy and at the other end).
        elevation: ``(times,)``: the surface elevation above the buoy's equilibrium position.
        cpu_time: the time integration's CPU time (s).
    """

    built: Built
    solution: Any
    times: np.ndarray
    motions: np.ndarray
    tensions: np.ndarray
    elevation: np.ndarray
    cpu_time: float


def _rotation(positions: np.ndarray, body: dict[str, Any]) -> np.ndarray:
    """(times, 3, 3) rotation matrices of the body from its octahedron's vertices."""
    v = positions[:, [p.index for p in body["vertices"]]]
    axes = np.asarray(body["axes"], dtype=float)
    e = np.stack([v[:, 2 * k] - v[:, 2 * k + 1] for k in range(3)], axis=2)
    e /= np.linalg.norm(e, axis=1, keepdims=True)
    # The pair k of vertices lies along column k of "axes" at the start: Q = sum e_k a_k^T.
    return np.einsum("tik,jk->tij", e, axes)


def _motions(positions: np.ndarray, body: dict[str, Any], rest: np.ndarray) -> np.ndarray:
    centre = positions[:, body["centre"].index]
    r = _rotation(positions, body)
    roll = np.arctan2(r[:, 2, 1], r[:, 2, 2])
    pitch = np.arcsin(np.clip(-r[:, 2, 0], -1.0, 1.0))
    yaw = np.arctan2(r[:, 1, 0], r[:, 0, 0])
    return np.column_stack([centre - rest, roll, pitch, yaw])


def run(built: Built, *, t_end: float | None = None, dt: float | None = None,
        progress: bool | Callable[[float, float], None] = False) -> MooredBuoyRun:
    """Integrate a built case from its equilibrium.

    Arguments:
        built: the system (:func:`build`).
        t_end: the end time (s; default the case's).
        dt: the step (s; default the case's).
        progress: True draws a progress bar on standard error.

    Returns:
        The run.

    Raises:
        ConvergenceError: when a step fails (the run's states so far are kept on the error).
    """
    import vinculo

    case = built.case
    t_end = case.t_end if t_end is None else float(t_end)
    dt = case.dt if dt is None else float(dt)
    # The multiples of dt, and t_end (not twice when it is one of them).
    grid = np.append(np.arange(0.0, t_end - 0.5 * dt, dt), t_end)
    start = time.process_time()
    solution = vinculo.simulate(built.system, t_end=t_end, dt=dt, t_eval=grid,
                                progress=progress, jacobian_reuse=True)
    cpu = time.process_time() - start
    positions = np.asarray(solution.positions)
    rest = positions[0, built.body["centre"].index]
    motions = _motions(positions, built.body, rest)
    tensions = np.zeros((len(solution.times), len(built.lines), 2))
    for k, (line, end) in enumerate(zip(built.lines, built.fairleads, strict=True)):
        t = line.tensions(solution)
        fair, anchor = (t[:, -1], t[:, 0]) if end != 0 else (t[:, 0], t[:, -1])
        tensions[:, k, 0], tensions[:, k, 1] = fair, anchor
    elevation = case.sea.elevation(solution.times, (float(rest[0]), float(rest[1])))
    return MooredBuoyRun(built=built, solution=solution, times=np.asarray(solution.times),
                         motions=motions, tensions=tensions, elevation=elevation, cpu_time=cpu)


@dataclass
class RaoTable:
    """Response amplitude operators from a regular-wave sweep.

    Arguments:
        periods: the wave periods (s).
        amplitude: ``(periods, 6)``: motion amplitude over wave amplitude (m/m for surge,
            sway, heave; rad/m for roll, pitch, yaw).
        phase: ``(periods, 6)``: the motion's phase lead over the elevation at the buoy (rad).
        tension: ``(periods, lines)``: the fairlead tension's amplitude over wave amplitude
            (N/m).
    """

    periods: np.ndarray
    amplitude: np.ndarray
    phase: np.ndarray
    tension: np.ndarray


def _harmonic(t: np.ndarray, x: np.ndarray, omega: float) -> complex:
    """The complex amplitude A of x ~ c + Re(A e^{i omega t}) by least squares."""
    basis = np.column_stack([np.ones_like(t), np.cos(omega * t), np.sin(omega * t)])
    coef, *_ = np.linalg.lstsq(basis, x, rcond=None)
    return complex(coef[1], -coef[2])


def rao(case: MooredBuoyCase, periods: Sequence[float] | None = None, height: float | None = None,
        cycles: int | None = None, ramp_cycles: int = 4) -> RaoTable:
    """Response amplitude operators: the case in regular waves of each period (small height,
    ``ramp_cycles`` periods of ramp, then ``cycles`` periods; the last half of them measured
    by a least-squares fit at the wave frequency), every run from the same equilibrium, with
    the case's step or a 40th of the period, whichever is shorter (the step must also resolve
    the buoy's own periods: the trapezoidal rule lengthens a period of 9 steps by 4 %).

    A slow ramp keeps the free oscillations it starts small (they decay only with the drag):
    the ramp's (1 - cos) shape leaves of them about (1 / (|omega - omega_n| T_ramp))^3 of the
    forced response.

    Arguments:
        case: the case (its sea's depth, current, stretching and direction are kept).
        periods: the wave periods (s; default the case's).
        height: the wave height (m; default the case's).
        cycles: periods per run after the ramp (default the case's).
        ramp_cycles: periods of the waves' ramp.

    Returns:
        The table.
    """
    periods = tuple(case.rao_periods if periods is None else periods)
    height = case.rao_height if height is None else float(height)
    cycles = case.rao_cycles if cycles is None else int(cycles)
    if not periods:
        raise InvalidInputError("no RAO periods: give [rao] periods in the case or periods=",
                                name="periods", value=periods)
    direction = float(case.sea.waves.directions[0]) if len(case.sea.waves) else 0.0
    amp = np.zeros((len(periods), 6))
    phase = np.zeros((len(periods), 6))
    tension = np.zeros((len(periods), 0))
    base = build(case)
    for i, period in enumerate(periods):
        sea = Sea.regular(height, period, case.sea.depth, direction=direction,
                          current=case.sea.current, stretching=case.sea.stretching,
                          density=case.sea.density, g=case.sea.g, ramp=ramp_cycles * period)
        built = build(replace(case, sea=sea), solve=False)
        # Every run starts from the one equilibrium (in still water with the current).
        if base.statics is not None:
            base.statics.apply(built.system)
        r = run(built, t_end=(ramp_cycles + cycles) * period, dt=min(case.dt, period / 40.0))
        keep = r.times >= (ramp_cycles + cycles / 2) * period
        omega = 2.0 * math.pi / period
        eta = _harmonic(r.times[keep], r.elevation[keep], omega)
        for k in range(6):
            a = _harmonic(r.times[keep], r.motions[keep, k], omega) / eta
            amp[i, k], phase[i, k] = abs(a), np.angle(a)
        if tension.shape[1] != r.tensions.shape[1]:
            tension = np.zeros((len(periods), r.tensions.shape[1]))
        for k in range(r.tensions.shape[1]):
            tension[i, k] = abs(_harmonic(r.times[keep], r.tensions[keep, k, 0], omega) / eta)
    return RaoTable(np.asarray(periods), amp, phase, tension)


def write(result: MooredBuoyRun, output: str | Path, *, rao_table: RaoTable | None = None,
          plots: bool = True) -> dict[str, Path]:
    """Write a run's motions and tensions (CSV and NetCDF), its spectra and plots.

    Arguments:
        result: the run.
        output: the folder.
        rao_table: an RAO sweep to write and plot beside it.
        plots: draw the figures.

    Returns:
        The files written, by kind.
    """
    import xarray as xr
    from scipy import signal

    out = Path(output)
    out.mkdir(parents=True, exist_ok=True)
    lines = [line.name or f"line {k + 1}" for k, line in enumerate(result.built.lines)]
    data = xr.Dataset(
        {name: ("time", result.motions[:, k]) for k, name in enumerate(MOTIONS)}
        | {"elevation": ("time", result.elevation),
           "fairlead_tension": (("time", "line"), result.tensions[:, :, 0]),
           "anchor_tension": (("time", "line"), result.tensions[:, :, 1])},
        coords={"time": result.times, "line": lines},
        attrs={"title": result.built.case.title, "cpu_time_s": result.cpu_time})
    for name in MOTIONS[:3]:
        data[name].attrs["units"] = "m"
    for name in MOTIONS[3:]:
        data[name].attrs["units"] = "rad"
    files = {"netcdf": out / "run.nc", "csv": out / "run.csv"}
    data.to_netcdf(files["netcdf"])
    columns = ["time", *MOTIONS, "elevation"]
    table = [result.times, *result.motions.T, result.elevation]
    for k, name in enumerate(lines):
        columns += [f"fairlead_tension {name}", f"anchor_tension {name}"]
        table += [result.tensions[:, k, 0], result.tensions[:, k, 1]]
    np.savetxt(files["csv"], np.column_stack(table), delimiter=",", header=",".join(columns),
               comments="")
    # Spectra after the waves' ramp.
    ramp = result.built.case.sea.ramp
    keep = result.times >= ramp
    spectra: dict[str, tuple[np.ndarray, np.ndarray]] = {}
    if keep.sum() > 64:
        fs = 1.0 / float(np.median(np.diff(result.times)))
        n = min(int(keep.sum()) // 2, 1024)
        for name, series in [("elevation", result.elevation), ("heave", result.motions[:, 2]),
                             ("surge", result.motions[:, 0]), ("pitch", result.motions[:, 4])] \
                + [(f"tension {s}", result.tensions[:, k, 0]) for k, s in enumerate(lines)]:
            f, p = signal.welch(series[keep], fs=fs, nperseg=n)
            spectra[name] = (f, p)
        frequency = next(iter(spectra.values()))[0]
        xr.Dataset({k.replace(" ", "_"): ("frequency", v[1]) for k, v in spectra.items()},
                   coords={"frequency": frequency},
                   attrs={"method": f"Welch, {n}-sample segments, after the {ramp:g} s ramp"}
                   ).to_netcdf(out / "spectra.nc")
        files["spectra"] = out / "spectra.nc"
    if rao_table is not None:
        files["rao"] = out / "rao.csv"
        header = "period," + ",".join(f"{m}_amplitude,{m}_phase" for m in MOTIONS) + "," + \
            ",".join(f"tension_{k + 1}" for k in range(rao_table.tension.shape[1]))
        rows = np.column_stack([rao_table.periods]
                               + [np.column_stack([rao_table.amplitude[:, k],
                                                   rao_table.phase[:, k]])
                                  for k in range(6)] + [rao_table.tension])
        np.savetxt(files["rao"], rows, delimiter=",", header=header, comments="")
    if plots:
        files.update(_plots(result, spectra, rao_table, out))
    return files


def _plots(result: MooredBuoyRun, spectra: dict[str, tuple[np.ndarray, np.ndarray]],
           rao_table: RaoTable | None, out: Path) -> dict[str, Path]:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    files = {}
    t = result.times
    fig, ax = plt.subplots(4, 1, figsize=(9, 9), sharex=True)
    ax[0].plot(t, result.elevation, color="tab:blue")
    ax[0].set_ylabel("elevation (m)")
    ax[1].plot(t, result.motions[:, 0], label="surge")
    ax[1].plot(t, result.motions[:, 2], label="heave")
    ax[1].set_ylabel("motion (m)")
    ax[1].legend(loc="upper right")
    ax[2].plot(t, np.degrees(result.motions[:, 4]), label="pitch")
    ax[2].plot(t, np.degrees(result.motions[:, 3]), label="roll")
    ax[2].set_ylabel("angle (deg)")
    ax[2].legend(loc="upper right")
    kilo = np.abs(result.tensions).max(initial=0.0) >= 1e3
    for k, line in enumerate(result.built.lines):
        ax[3].plot(t, result.tensions[:, k, 0] / (1e3 if kilo else 1.0),
                   label=f"{line.name} fairlead")
    ax[3].set_ylabel("tension (kN)" if kilo else "tension (N)")
    ax[3].set_xlabel("time (s)")
    if result.built.lines:
        ax[3].legend(loc="upper right", fontsize="small")
    fig.suptitle(result.built.case.title)
    fig.tight_layout()
    files["motions_plot"] = out / "motions.png"
    fig.savefig(files["motions_plot"], dpi=110)
    plt.close(fig)
    if spectra:
        fig, ax = plt.subplots(1, 2, figsize=(10, 4))
        for name in ("elevation", "heave", "surge"):
            f, p = spectra[name]
            ax[0].semilogy(f, p, label=name)
        ax[0].set_xlim(0, 0.5)
        ax[0].set_xlabel("frequency (Hz)")
        ax[0].set_ylabel("spectral density (m^2/Hz)")
        ax[0].legend()
        for name, (f, p) in spectra.items():
            if name.startswith("tension"):
                ax[1].semilogy(f, p, label=name)
        ax[1].set_xlim(0, 0.5)
        ax[1].set_xlabel("frequency (Hz)")
        ax[1].set_ylabel("tension spectrum (N^2/Hz)")
        if any(n.startswith("tension") for n in spectra):
            ax[1].legend(fontsize="small")
        fig.tight_layout()
        files["spectra_plot"] = out / "spectra.png"
        fig.savefig(files["spectra_plot"], dpi=110)
        plt.close(fig)
    if rao_table is not None:
        fig, ax = plt.subplots(1, 2, figsize=(10, 4))
        for k, name in ((0, "surge"), (2, "heave")):
            ax[0].plot(rao_table.periods, rao_table.amplitude[:, k], "o-", label=name)
        ax[0].set_xlabel("wave period (s)")
        ax[0].set_ylabel("RAO (m/m)")
        ax[0].legend()
        ax[1].plot(rao_table.periods, np.degrees(rao_table.amplitude[:, 4]), "o-",
                   label="pitch")
        ax[1].set_xlabel("wave period (s)")
        ax[1].set_ylabel("RAO (deg/m)")
        ax[1].legend()
        fig.tight_layout()
        files["rao_plot"] = out / "rao.png"
        fig.savefig(files["rao_plot"], dpi=110)
        plt.close(fig)
    return files
