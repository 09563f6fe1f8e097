"""Mooring lines: MoorDyn input files, the elastic catenary, statics and runs of a mooring.

- :mod:`vinculo.mooring.moordyn_file`: read a MoorDyn v2 input file into a
  :class:`MoorDynFile` (:func:`read_moordyn`) and write one back (:func:`write_moordyn`).
- :mod:`vinculo.mooring.catenary`: the elastic catenary with a frictionless seabed in closed
  form (:func:`solve_catenary`; on a sloping seabed :func:`solve_catenary_on_slope`), the
  reference of the line statics.
- :mod:`vinculo.mooring.seafloor`: a seabed of varying height, MoorDyn's 3D seafloor
  (:class:`Seafloor`, :func:`read_seafloor`), which a file names by its SeafloorFile option.
- :mod:`vinculo.mooring.current_profile`: MoorDyn's steady current (``Currents 1``,
  :func:`read_current_profile`).
- :mod:`vinculo.mooring.stiffness_curve`: MoorDyn's nonlinear EA, a tension-strain table
  (:func:`read_stiffness_curve`).
- :mod:`vinculo.mooring.wave_components`: MoorDyn's waves summed from their components
  (``WaveKin 7``, :func:`read_wave_frequencies`).
- :mod:`vinculo.mooring.channels`: MoorDyn's output channels (``FAIRTEN1``, ``L1N5PZ``, ...),
  which a run writes (:meth:`MooringRun.channels`).
- :mod:`vinculo.mooring.motion`: the prescribed motion of the coupled (Vessel) points.
- :mod:`vinculo.mooring.model`: the vinculo model of a file (:func:`build_model`).
- :mod:`vinculo.mooring.analysis`: :func:`statics` (the static equilibrium: end tensions,
  laid lengths, and the linearised stiffness at the coupled points and on a vessel carrying
  them, :meth:`MooringStatics.vessel_stiffness`) and :func:`run` (a run with the coupled points
  moved by a motion), the Python side of ``vinculo mooring statics`` and ``vinculo mooring
  run``.
- :mod:`vinculo.mooring.offsets`: the offset curve (:func:`offset_curve`): restoring force and
  line tensions as the coupled points are moved together, ``vinculo mooring offsets``.
- :mod:`vinculo.mooring.peer`: run MoorDyn itself (the ``moordyn`` package) on the same file
  with the same fairlead motion, for comparisons and benchmarks.

Example:
    >>> import vinculo.mooring as mooring
    >>> result = mooring.statics("tests/data/moordyn/taut_line.txt")  # doctest: +SKIP
    >>> result.to_csv("statics.csv")  # doctest: +SKIP
"""

import importlib
import types
from typing import Any

from vinculo.mooring.analysis import MooringRun, MooringStatics, StepCheck, check_step, run
from vinculo.mooring.analysis import statics as _statics
from vinculo.mooring.catenary import (
    CatenarySolution,
    SlopeCatenarySolution,
    solve_catenary,
    solve_catenary_on_slope,
    weight_in_water,
)
from vinculo.mooring.current_profile import CurrentProfile, read_current_profile
from vinculo.mooring.model import MooringModel, build_model
from vinculo.mooring.moordyn_file import (
    FileBody,
    FileLine,
    FileOptions,
    FilePoint,
    MoorDynFile,
    format_moordyn,
    parse_moordyn,
    read_moordyn,
    write_moordyn,
)
from vinculo.mooring.motion import Motion, read_motion
from vinculo.mooring.offsets import OffsetCurve, offset_curve, plot_offset_curve
from vinculo.mooring.seafloor import Seafloor, read_seafloor
from vinculo.mooring.stiffness_curve import StiffnessCurve, read_stiffness_curve
from vinculo.mooring.wave_components import WaveComponents, read_wave_frequencies


class _CallableModule(types.ModuleType):
    """The module vinculo.mooring.statics (the equilibrium solver), callable as the analysis
    :func:`vinculo.mooring.analysis.statics`: ``vinculo.mooring.statics(path)`` and
    ``vinculo.mooring.statics.solve_statics(system)`` both work."""

    def __call__(self, *args: Any, **kwargs: Any) -> MooringStatics:
        return _statics(*args, **kwargs)


def _statics_entry() -> Any:
    """The solver module made callable, or the analysis function alone without the module."""
    try:
        module = importlib.import_module("vinculo.mooring.statics")
    except ModuleNotFoundError as missing:  # the equilibrium solver is not in this tree
        if missing.name != "vinculo.mooring.statics":
            raise
        return _statics
    module.__class__ = _CallableModule
    return module


statics = _statics_entry()
"""The static equilibrium of a MoorDyn file: ``statics(path)`` is
:func:`vinculo.mooring.analysis.statics` (end forces, tensions and laid lengths); the same name is
the module of the equilibrium solver (``vinculo.mooring.statics.solve_statics``)."""

__all__ = [
    "CatenarySolution",
    "CurrentProfile",
    "FileBody",
    "FileLine",
    "FileOptions",
    "FilePoint",
    "MoorDynFile",
    "MooringModel",
    "MooringRun",
    "MooringStatics",
    "Motion",
    "OffsetCurve",
    "Seafloor",
    "SlopeCatenarySolution",
    "StepCheck",
    "StiffnessCurve",
    "WaveComponents",
    "build_model",
    "check_step",
    "format_moordyn",
    "offset_curve",
    "parse_moordyn",
    "plot_offset_curve",
    "read_current_profile",
    "read_moordyn",
    "read_motion",
    "read_seafloor",
    "read_stiffness_curve",
    "read_wave_frequencies",
    "run",
    "solve_catenary",
    "solve_catenary_on_slope",
    "statics",
    "weight_in_water",
    "write_moordyn",
]
