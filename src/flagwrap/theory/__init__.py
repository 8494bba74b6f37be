"""Closed-form theory of the paper: scaling laws (main text) and helix stretching (Eq. 1, SI).

These functions are pure, work in SI units and double as oracles for the simulator's tests.
"""

from flagwrap.theory.scaling import (
    M_C_PREFACTOR,
    PaperNumbers,
    bending_stiffness,
    critical_angular_frequency,
    critical_angular_frequency_material,
    critical_machin_number,
    critical_torque,
    machin_number,
    machin_prefactor_from_omega,
    paper_numbers,
    peak_torque,
    reynolds_number,
    rft_friction,
    torque_pn_nm,
    twist_stiffness,
)
from flagwrap.theory.stretching import (
    StretchedHelix,
    helix_curvature_torsion,
    main_text_eq1_force,
    minimise_uniform_helix,
    pitch_angle_at_force,
    reduced_force,
    si_printed_force,
)

__all__ = [
    "M_C_PREFACTOR",
    "PaperNumbers",
    "StretchedHelix",
    "bending_stiffness",
    "critical_angular_frequency",
    "critical_angular_frequency_material",
    "critical_machin_number",
    "critical_torque",
    "helix_curvature_torsion",
    "machin_number",
    "machin_prefactor_from_omega",
    "main_text_eq1_force",
    "minimise_uniform_helix",
    "paper_numbers",
    "peak_torque",
    "pitch_angle_at_force",
    "reduced_force",
    "reynolds_number",
    "rft_friction",
    "si_printed_force",
    "torque_pn_nm",
    "twist_stiffness",
]
