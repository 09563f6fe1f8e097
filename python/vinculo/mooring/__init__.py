"""Mooring lines: MoorDyn input files, the elastic catenary, statics and runs of a mooring.

- :mod:`vinculo.mooring.moordyn_file`: read a MoorDyn v2 input file into a
  :class:`MoorDynFile` (:func:`read_moordyn`) and write one back (:func:`write_moordyn`).
- :mod:`vinculo.mooring.catenary`: the elastic catenary with a frictionless seabed in closed
  form (:func:`solve_catenary`), the reference of the line statics.
- :mod:`vinculo.mooring.motion`: the prescribed motion of the coupled (Vessel) points.
- :mod:`vinculo.mooring.model`: the vinculo model of a file (:func:`build_model`).
- :mod:`vinculo.mooring.analysis`: :func:`statics` (the static equilibrium: end tensions and
  laid lengths) and :func:`run` (a run with the coupled points moved by a motion), the Python
  side of ``vinculo mooring statics`` and ``vinculo mooring run``.
- :mod:`vinculo.mooring.peer`: run MoorDyn itself (the ``moordyn`` package) on the same file
  with the same fairlead motion, for comparisons and benchmarks.

Example:
    >>> import vinculo.mooring as mooring
    >>> result = mooring.statics("tests/data/moordyn/taut_line.txt")  # doctest: +SKIP
    >>> result.to_csv("statics.csv")  # doctest: +SKIP
"""

import contextlib

from vinculo.mooring.catenary import CatenarySolution, solve_catenary, weight_in_water
from vinculo.mooring.moordyn_file import (
    FileLine,
    FileLineType,
    FileOptions,
    FilePoint,
    MoorDynFile,
    format_moordyn,
    parse_moordyn,
    read_moordyn,
    write_moordyn,
)
from vinculo.mooring.motion import Motion

# The submodule vinculo.mooring.statics (the equilibrium solver) is imported before the function
# statics() is bound below: a later import of the submodule then finds it loaded and leaves the
# package's attribute `statics` the function.
with contextlib.suppress(ImportError):
    import vinculo.mooring.statics  # noqa: F401
from vinculo.mooring.analysis import MooringRun, MooringStatics, run, statics
from vinculo.mooring.model import MooringModel, build_model

__all__ = [
    "CatenarySolution",
    "FileLine",
    "FileLineType",
    "FileOptions",
    "FilePoint",
    "MoorDynFile",
    "MooringModel",
    "MooringRun",
    "MooringStatics",
    "Motion",
    "build_model",
    "format_moordyn",
    "parse_moordyn",
    "read_moordyn",
    "run",
    "solve_catenary",
    "statics",
    "weight_in_water",
    "write_moordyn",
]
