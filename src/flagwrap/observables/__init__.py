"""Observables of a filament trajectory: pure functions of arrays, no file I/O.

Positions are arrays of shape ``(T, N, 3)`` (or ``(N, 3)`` for one frame) in any length unit;
scalars passed alongside (filament length, body radius, ...) must use the same unit. The
geometry is the simulator's: body axis +z, clamp (bead 0) at the origin, the hemispherical
cap of radius ``R_cell`` centred at ``(0, 0, R_cell)`` and the cylinder above it, the
filament hanging toward -z (see :mod:`flagwrap.io.runfile`).

=====================  ==================================================================
module                 observables
=====================  ==================================================================
:mod:`.tip`            free-end height ``(z(L) - z(0))/L``, tip trajectory
:mod:`.torque`         rescaled motor torque ``N_m R / A``, its peak and plateau
:mod:`.handedness`     discrete torsion sign, perversion positions, RH fraction
:mod:`.winding`        azimuth and unwrapped winding angle about the body axis
:mod:`.contact`        signed bead-surface distance, near-body masks and fractions
=====================  ==================================================================
"""

from flagwrap.observables.contact import body_distance, near_body_fraction, near_body_mask
from flagwrap.observables.handedness import (
    discrete_torsion,
    local_handedness,
    perversion_index,
    perversions,
    right_handed_fraction,
)
from flagwrap.observables.tip import free_end_height, free_end_heights, tip_trajectory
from flagwrap.observables.torque import cw_torque_peak, plateau_value, reduced_torque, torque_peak
from flagwrap.observables.winding import azimuth, winding_angle, winding_turns

__all__ = [
    "azimuth",
    "body_distance",
    "discrete_torsion",
    "free_end_height",
    "free_end_heights",
    "local_handedness",
    "near_body_fraction",
    "near_body_mask",
    "perversion_index",
    "perversions",
    "right_handed_fraction",
    "plateau_value",
    "reduced_torque",
    "tip_trajectory",
    "torque_peak",
    "cw_torque_peak",
    "winding_angle",
    "winding_turns",
]
