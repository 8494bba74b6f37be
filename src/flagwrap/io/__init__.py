"""Input and output: TOML configs, netCDF run files (VTK export lives in :mod:`flagwrap.io.vtk`)."""
