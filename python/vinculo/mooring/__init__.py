"""Mooring lines: MoorDyn input files, the elastic catenary, statics and runs of a mooring.

- :mod:`vinculo.mooring.moordyn_file`: read a MoorDyn v2 input file into a
  :class:`MoorDynFile` (:func:`read_moordyn`) and write one back (:func:`write_moordyn`).
- :mod:`vinculo.mooring.catenary`: the elastic catenary with a frictionless seabed in closed
  form (:func:`solve_catenary`), the reference of the line statics.
- :mod:`vinculo.mooring.peer`: run MoorDyn itself (the ``moordyn`` package) on the same file
  with the same fairlead motion, for comparisons and benchmarks.
"""

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

__all__ = [
    "CatenarySolution",
    "FileLine",
    "FileLineType",
    "FileOptions",
    "FilePoint",
    "MoorDynFile",
    "format_moordyn",
    "parse_moordyn",
    "read_moordyn",
    "solve_catenary",
    "weight_in_water",
    "write_moordyn",
]
