"""NetCDF archives of a run: every array of a :class:`vinculo.Solution`, with units.

:func:`save_netcdf` writes a NetCDF4 file (through xarray and h5netcdf) with the dimensions
``time``, ``particle``, ``component`` (x, y, z) and ``constraint`` (one per constraint equation)
and these variables, named after the :class:`~vinculo.Solution` attributes they come from:

============================  ===================================  ==========================
variable                      dimensions                           units
============================  ===================================  ==========================
``time``                      time                                 s
``positions``                 time, particle, component            m
``velocities``                time, particle, component            m s-1
``multipliers``               time, constraint                     see ``multiplier_units``
``tension``                   time, constraint                     N (NaN: not a distance)
``constraint_residual``       time                                 m
``newton_iterations``         time                                 1
``step_sizes``                time                                 s
``residual_norms``            time                                 1
``increment_norms``           time                                 1
``masses``                    particle                             kg
``inertia``                   particle                             kg
``fixed``                     particle                             (0 or 1)
``constraint_names``          constraint                           (text)
``constraint_kinds``          constraint                           (text)
``constraint_lengths``        constraint                           m (NaN: not a distance)
``multiplier_units``          constraint                           (text)
============================  ===================================  ==========================

Every variable has CF-style ``units`` and ``long_name`` attributes. The file's attributes hold the
vinculo version, the linear solver, the run's status (``'completed'`` or ``'failed'``, with the
failure's kind, message and time), the gravity vector, and any parameters the caller passes
(nested mappings are flattened to ``'outer.inner'`` names).

The tension of a distance constraint is ``2 lambda L`` (:meth:`vinculo.Solution.distance_tension`);
its multiplier is in N/m. A plane or a fixed coordinate has its multiplier in N (a force along the
plane's normal or the axis) and no tension.
"""

from __future__ import annotations

import math
import numbers
import os
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from vinculo.errors import InvalidInputError
from vinculo.io.output import checked_file, file_written_in_place
from vinculo.io.topology import constraint_kinds
from vinculo.solution import Solution

__all__ = ["SUFFIXES", "load_netcdf", "save_netcdf", "tensions", "to_dataset"]

#: The accepted suffixes of a NetCDF file.
SUFFIXES = (".nc", ".nc4")

#: The engine xarray writes and reads with (NetCDF4 on HDF5).
ENGINE = "h5netcdf"

#: Attributes of the file that vinculo sets; a caller's parameters must not reuse these names.
RESERVED_ATTRIBUTES = frozenset(
    {
        "title",
        "Conventions",
        "source",
        "vinculo_version",
        "linear_solver",
        "status",
        "error_kind",
        "error_message",
        "error_time",
        "gravity",
        "num_steps",
    }
)

_MULTIPLIER_UNITS = {
    "distance": "N m-1",
    "point distance": "N m-1",
    "plane": "N",
    "fixed coordinate": "N",
}


def _xarray() -> Any:
    """Import xarray, or say which extra provides it."""
    try:
        import h5netcdf  # noqa: F401  (the engine must be importable too)
        import xarray
    except ImportError as exc:  # pragma: no cover - the test environment has both
        raise ImportError(
            f"NetCDF files need xarray and h5netcdf ({exc}); install them with "
            f"`pip install 'vinculo[io]'`"
        ) from exc
    return xarray


def tensions(solution: Solution) -> np.ndarray:
    """The tension of every distance constraint at every stored time.

    Arguments:
        solution: the run.

    Returns:
        (s, m) tensions in N, ``2 lambda L`` for distance constraints (to another particle or to
        a point), NaN for the other constraints. Column k equals
        ``solution.distance_tension(ConstraintId k)``.
    """
    lengths = np.asarray(solution.system.constraint_lengths, dtype=np.float64)
    return 2.0 * solution.multipliers * lengths[np.newaxis, :]


def _attribute(name: str, value: Any) -> Any:
    """Convert one parameter to a value a NetCDF attribute can hold."""
    if isinstance(value, (bool, np.bool_)):
        return "true" if value else "false"
    if isinstance(value, str):
        return value
    if isinstance(value, numbers.Integral):
        return int(value)
    if isinstance(value, numbers.Real):
        return float(value)
    if isinstance(value, (list, tuple, np.ndarray)):
        array = np.asarray(value)
        if array.ndim == 1 and array.size > 0 and array.dtype.kind in "iuf":
            return array.astype(np.float64 if array.dtype.kind == "f" else np.int64)
        if array.ndim == 1 and array.size > 0 and all(isinstance(v, str) for v in value):
            return ", ".join(value)
    raise InvalidInputError(
        f"attribute {name!r} = {value!r} cannot be stored in a NetCDF file: give a str, a "
        f"number, a bool, a non-empty list of numbers or of str, or a mapping of these",
        name=name,
        value=value,
    )


def _flatten(attributes: Mapping[str, Any], prefix: str = "") -> dict[str, Any]:
    """Flatten nested mappings into ``'outer.inner'`` names and convert the values."""
    flat: dict[str, Any] = {}
    for key, value in attributes.items():
        if not isinstance(key, str) or not key:
            raise InvalidInputError(
                f"attribute names must be non-empty str, got {key!r}", name="attributes", value=key
            )
        name = f"{prefix}{key}"
        if isinstance(value, Mapping):
            flat.update(_flatten(value, f"{name}."))
        elif value is None:
            continue  # a parameter left unset is simply absent
        else:
            flat[name] = _attribute(name, value)
    return flat


def _run_attributes(solution: Solution) -> dict[str, Any]:
    """The file attributes that describe the run itself."""
    import vinculo

    attributes: dict[str, Any] = {
        "title": "vinculo simulation results",
        "Conventions": "CF-1.11",
        "source": f"vinculo {vinculo.__version__}",
        "vinculo_version": vinculo.__version__,
        "linear_solver": solution.linear_solver,
        "status": "completed" if solution.success else "failed",
        "gravity": np.array(solution.system.gravity, dtype=np.float64),
        "num_steps": solution.num_steps,
    }
    if solution.error is not None:
        attributes["error_kind"] = str(solution.error.get("kind", ""))
        attributes["error_message"] = str(solution.error.get("message", ""))
        time = solution.error.get("time")
        if time is not None and math.isfinite(float(time)):
            attributes["error_time"] = float(time)
    return attributes


def to_dataset(solution: Solution, attributes: Mapping[str, Any] | None = None) -> Any:
    """The run as an ``xarray.Dataset`` (what :func:`save_netcdf` writes).

    Arguments:
        solution: the run.
        attributes: parameters of the run to store as file attributes (for example
            ``{"case": case.to_dict(), "frequency": 0.9}``).

    Returns:
        The dataset.

    Raises:
        InvalidInputError: ``solution`` is not a Solution, an attribute cannot be stored, or it
            reuses a name vinculo sets.
    """
    if not isinstance(solution, Solution):
        raise InvalidInputError(
            f"expected a vinculo.Solution, got {type(solution).__name__}",
            name="solution",
            value=type(solution).__name__,
        )
    if attributes is not None and not isinstance(attributes, Mapping):
        raise InvalidInputError(
            f"attributes must be a mapping of names to values, got {type(attributes).__name__}",
            name="attributes",
            value=attributes,
        )
    user = _flatten(attributes or {})
    clash = sorted(RESERVED_ATTRIBUTES & user.keys())
    if clash:
        raise InvalidInputError(
            f"attribute {clash[0]!r} is set by vinculo itself; rename the parameter",
            name="attributes",
            value=clash[0],
        )
    xr = _xarray()
    system = solution.system
    kinds = constraint_kinds(system)
    num_particles = solution.positions.shape[1]
    num_constraints = solution.multipliers.shape[1]
    multiplier_units = [_MULTIPLIER_UNITS.get(kind, "") for kind in kinds]
    distinct = set(multiplier_units)

    def var(dims: tuple[str, ...], data: Any, units: str, long_name: str) -> Any:
        return xr.Variable(dims, data, attrs={"units": units, "long_name": long_name})

    data_vars = {
        "positions": var(("time", "particle", "component"), solution.positions, "m",
                         "particle position"),
        "velocities": var(("time", "particle", "component"), solution.velocities, "m s-1",
                          "particle velocity"),
        "multipliers": var(
            ("time", "constraint"), solution.multipliers,
            distinct.pop() if len(distinct) == 1 else "mixed: see multiplier_units",
            "Lagrange multiplier of each constraint equation",
        ),
        "tension": var(("time", "constraint"), tensions(solution), "N",
                       "tension of a distance constraint, 2 lambda L (NaN: not a distance)"),
        "constraint_residual": var(("time",), solution.constraint_residual, "m",
                                   "largest scaled constraint residual max_k |s_k Phi_k|"),
        "newton_iterations": var(("time",), solution.newton_iterations, "1",
                                 "Newton iterations of the step ending at this time"),
        "step_sizes": var(("time",), solution.step_sizes, "s",
                          "size of the step ending at this time (0 for the initial state)"),
        "residual_norms": var(("time",), solution.residual_norms, "1",
                              "final residual norm of the step's Newton solve"),
        "increment_norms": var(("time",), solution.increment_norms, "1",
                               "norm of the step's last Newton increment"),
        "masses": var(("particle",), system.masses(), "kg", "particle mass"),
        "inertia": var(("particle",), system.inertia, "kg",
                       "translational inertia of the particle: mass plus added mass"),
        "fixed": var(("particle",), system.fixed().astype(np.int8), "1",
                     "1 if the particle is fixed in space, else 0"),
        "constraint_names": var(("constraint",), np.array(system.constraint_names()),
                                "", "name of the constraint equation"),
        "constraint_kinds": var(("constraint",), np.array(kinds), "",
                                "kind of the constraint"),
        "constraint_lengths": var(("constraint",), system.constraint_lengths, "m",
                                  "length of a distance constraint (NaN: not a distance)"),
        "multiplier_units": var(("constraint",), np.array(multiplier_units), "",
                                "units of the constraint's Lagrange multiplier"),
    }
    coords = {
        "time": var(("time",), solution.times, "s", "time"),
        "particle": var(("particle",), np.arange(num_particles, dtype=np.int64), "1",
                        "particle index"),
        "component": var(("component",), np.array(["x", "y", "z"]), "",
                         "Cartesian component"),
        "constraint": var(("constraint",), np.arange(num_constraints, dtype=np.int64), "1",
                          "constraint equation index"),
    }
    return xr.Dataset(data_vars, coords=coords, attrs={**_run_attributes(solution), **user})


def save_netcdf(
    solution: Solution,
    path: str | os.PathLike[str],
    *,
    attributes: Mapping[str, Any] | None = None,
) -> Path:
    """Write a run to a NetCDF4 file.

    The file is written under a temporary name in the same folder and renamed to ``path`` once
    complete, so an interrupted write leaves no partial file under that name.

    Arguments:
        solution: the run (a partial solution from a failed run is fine: its status says so).
        path: the file to write, ending in ``.nc`` or ``.nc4`` (replaced if it exists).
        attributes: parameters of the run to store as file attributes, for example
            ``{"case": case.to_dict(), "frequency": 0.9}`` (nested mappings become
            ``'case.amplitude'`` and so on; bools become ``'true'``/``'false'``; None values are
            left out).

    Returns:
        The path written.

    Raises:
        InvalidInputError: the path's suffix is not ``.nc``/``.nc4``, the path is a folder or its
            folder does not exist, or an attribute cannot be stored.
    """
    target = checked_file(path, SUFFIXES, "NetCDF file")
    dataset = to_dataset(solution, attributes)
    with file_written_in_place(target) as temporary:
        dataset.to_netcdf(temporary, engine=ENGINE)
    return target


def load_netcdf(path: str | os.PathLike[str]) -> Any:
    """Read a file written by :func:`save_netcdf`.

    Arguments:
        path: the NetCDF file.

    Returns:
        An ``xarray.Dataset`` held in memory (the file is closed): ``ds["positions"].values`` is
        the (s, n, 3) position array, ``ds.attrs`` the run's attributes, and so on.

    Raises:
        InvalidInputError: the file does not exist or is not a NetCDF4 file.
    """
    xr = _xarray()
    source = Path(path)
    if not source.is_file():
        raise InvalidInputError(
            f"no NetCDF file at {str(source)!r}", name="path", value=str(source)
        )
    try:
        with xr.open_dataset(source, engine=ENGINE, decode_timedelta=False) as dataset:
            return dataset.load()
    except (OSError, ValueError) as exc:
        raise InvalidInputError(
            f"cannot read {str(source)!r} as a NetCDF4 file: {exc}",
            name="path",
            value=str(source),
        ) from exc
