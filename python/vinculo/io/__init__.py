"""Result files: NetCDF archives of a run and ParaView time series.

- :mod:`vinculo.io.netcdf`: :func:`save_netcdf` writes every array of a
  :class:`vinculo.Solution` (with units, the constraint names, the particle masses and the run's
  parameters) to a NetCDF4 file through xarray; :func:`load_netcdf` reads it back as an
  ``xarray.Dataset``.
- :mod:`vinculo.io.vtk`: :func:`export_vtk` writes one VTK file per stored time (particles as
  points, distance constraints as lines) and a ``.pvd`` index for ParaView.

Both need the optional dependencies of ``vinculo[io]`` (xarray, h5netcdf, meshio).
"""

from vinculo.io.netcdf import load_netcdf, save_netcdf
from vinculo.io.vtk import export_vtk, read_pvd

__all__ = ["export_vtk", "load_netcdf", "read_pvd", "save_netcdf"]
