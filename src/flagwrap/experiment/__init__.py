"""Experimental toolbox of the macroscale model (SI): stereo tracking, viscosity, density."""

from flagwrap.experiment.density import density_mismatch, effective_density, powder_mass_for_density
from flagwrap.experiment.triangulation import (
    CalibrationResult,
    StereoRig,
    calibrate,
    project,
    snell_angle,
    triangulate,
    triangulate_closed_form,
)
from flagwrap.experiment.viscosity import (
    AndradeFit,
    andrade_viscosity,
    fit_andrade,
    fit_rod_viscosity,
    machin_at_temperature,
    rod_force,
    sphere_terminal_velocity,
    sphere_viscosity,
    terminal_velocity_fit,
)

__all__ = [
    "AndradeFit",
    "CalibrationResult",
    "StereoRig",
    "andrade_viscosity",
    "calibrate",
    "density_mismatch",
    "effective_density",
    "fit_andrade",
    "fit_rod_viscosity",
    "machin_at_temperature",
    "powder_mass_for_density",
    "project",
    "rod_force",
    "snell_angle",
    "sphere_terminal_velocity",
    "sphere_viscosity",
    "terminal_velocity_fit",
    "triangulate",
    "triangulate_closed_form",
]
