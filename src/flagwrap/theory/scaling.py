"""Elastohydrodynamic scaling theory of the torque-induced buckling (main text, "Scaling argument").

Closed forms, all in SI units, used as oracles for the simulator and to place bacteria on
the stability diagram:

* ``M = eta omega L^4 / A``                  (main text, after Machin 1958)
* ``Re = rho R^2 omega / eta``               (main text)
* ``zeta = pi eta / ln(0.18 P / a)``         (main text, resistive-force theory, Lighthill)
* ``omega_c ~ A / (zeta R^3 L) ~ (E/eta)(a/R)^3 (a/L)``   (main text Eq. 2)
* ``M_c = c (R/L)^-3`` with ``c = 0.06``     (main text, Fig. 5)
* ``N_c ~= 0.5 A/R``, ``N_m ~= 0.9 A/R``      (main text, Fig. 4(c) and "Considering the maximal torque")

The two forms of Eq. 2 differ by ``ln(0.18 P/a)/4`` (from ``A = pi E a^4/4`` and ``zeta``):
``A/(zeta R^3 L) = (E/eta)(a/R)^3(a/L) ln(0.18 P/a)/4``. A prefactor ``c_omega`` on the first
form maps to ``M_c = (c_omega ln(0.18 P/a)/pi) (R/L)^-3`` (:func:`machin_prefactor_from_omega`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from flagwrap.errors import UserInputError
from flagwrap.units import MICRON, PN_NM, PN_UM2

__all__ = [
    "M_C_PREFACTOR",
    "N_C_COEFFICIENT",
    "N_PEAK_COEFFICIENT",
    "bending_stiffness",
    "twist_stiffness",
    "machin_number",
    "reynolds_number",
    "rft_friction",
    "critical_angular_frequency",
    "critical_angular_frequency_material",
    "critical_machin_number",
    "machin_prefactor_from_omega",
    "critical_torque",
    "peak_torque",
    "torque_pn_nm",
    "PaperNumbers",
    "paper_numbers",
]

#: prefactor ``c`` of ``M_c = c (R/L)^-3`` fitted to the diagram (main text, Fig. 5)
M_C_PREFACTOR = 0.06
#: ``N_c R / A`` at the onset of buckling (main text, Fig. 4(c))
N_C_COEFFICIENT = 0.5
#: ``N_m R / A`` at the torque peak for ``omega/omega_c ~ 2`` (main text, Fig. 4(c))
N_PEAK_COEFFICIENT = 0.9


def _pos(name: str, value: float) -> float:
    v = float(value)
    if not (math.isfinite(v) and v > 0.0):
        raise UserInputError(f"{name} must be a finite number > 0, got {value!r}")
    return v


def bending_stiffness(youngs_modulus: float, radius: float) -> float:
    """``A = pi E a^4 / 4`` [N m^2] of a round filament (main text, after Eq. 1).

    Parameters
    ----------
    youngs_modulus : float
        ``E`` [Pa].
    radius : float
        cross-section radius ``a`` [m].
    """
    return math.pi * _pos("youngs_modulus", youngs_modulus) * _pos("radius", radius) ** 4 / 4.0


def twist_stiffness(bending: float, poisson_ratio: float) -> float:
    """``C = A / (1 + nu)`` [N m^2] (main text, after Eq. 1)."""
    nu = float(poisson_ratio)
    if not (-1.0 < nu <= 0.5):
        raise UserInputError(f"poisson_ratio must lie in (-1, 0.5], got {poisson_ratio!r}")
    return _pos("bending", bending) / (1.0 + nu)


def machin_number(viscosity: float, omega: float, length: float, bending: float) -> float:
    """``M = eta omega L^4 / A`` (dimensionless; main text).

    Parameters
    ----------
    viscosity : float
        ``eta`` [Pa s].
    omega : float
        motor angular velocity [rad/s].
    length : float
        filament arclength ``L`` [m].
    bending : float
        bending stiffness ``A`` [N m^2].
    """
    return (
        _pos("viscosity", viscosity) * _pos("omega", omega) * _pos("length", length) ** 4 / _pos("bending", bending)
    )


def reynolds_number(density: float, radius: float, omega: float, viscosity: float) -> float:
    """``Re = rho R^2 omega / eta`` with the helix radius as length scale (main text).

    Parameters
    ----------
    density : float
        liquid density ``rho`` [kg/m^3].
    radius : float
        helix radius ``R`` [m].
    omega : float
        angular velocity [rad/s].
    viscosity : float
        ``eta`` [Pa s].
    """
    return _pos("density", density) * _pos("radius", radius) ** 2 * _pos("omega", omega) / _pos("viscosity", viscosity)


def rft_friction(viscosity: float, pitch: float, filament_radius: float) -> float:
    """Resistive-force friction per length ``zeta = pi eta / ln(0.18 P / a)`` [Pa s] (main text).

    Lighthill's normal coefficient for a helix of pitch ``P`` and filament radius ``a``;
    defined only for ``0.18 P / a > 1``.
    """
    arg = 0.18 * _pos("pitch", pitch) / _pos("filament_radius", filament_radius)
    if arg <= 1.0:
        raise UserInputError(f"rft_friction needs 0.18 P / a > 1 (slender helix), got {arg:.4g}")
    return math.pi * _pos("viscosity", viscosity) / math.log(arg)


def critical_angular_frequency(
    bending: float, friction: float, radius: float, length: float, prefactor: float = 1.0
) -> float:
    """``omega_c = c A / (zeta R^3 L)`` [rad/s] (main text Eq. 2, first form).

    From balancing the motor power ``A omega / R`` with the dissipation ``zeta R^2 omega^2 L``.

    Parameters
    ----------
    bending : float
        ``A`` [N m^2].
    friction : float
        ``zeta`` [Pa s] (see :func:`rft_friction`).
    radius, length : float
        helix radius ``R`` and arclength ``L`` [m].
    prefactor : float
        ``c``; the scaling fixes it only up to O(1) (default 1).
    """
    return (
        _pos("prefactor", prefactor)
        * _pos("bending", bending)
        / (_pos("friction", friction) * _pos("radius", radius) ** 3 * _pos("length", length))
    )


def critical_angular_frequency_material(
    youngs_modulus: float,
    viscosity: float,
    filament_radius: float,
    radius: float,
    length: float,
    prefactor: float = 1.0,
) -> float:
    """``omega_c = c (E/eta) (a/R)^3 (a/L)`` [rad/s] (main text Eq. 2, second form)."""
    a = _pos("filament_radius", filament_radius)
    return (
        _pos("prefactor", prefactor)
        * _pos("youngs_modulus", youngs_modulus)
        / _pos("viscosity", viscosity)
        * (a / _pos("radius", radius)) ** 3
        * (a / _pos("length", length))
    )


def critical_machin_number(radius_over_length: float, prefactor: float = M_C_PREFACTOR) -> float:
    """``M_c = c (R/L)^-3`` (main text; ``c = 0.06`` from Fig. 5). Dimensionless."""
    return _pos("prefactor", prefactor) * _pos("radius_over_length", radius_over_length) ** -3


def machin_prefactor_from_omega(omega_prefactor: float, pitch: float, filament_radius: float) -> float:
    """Prefactor of ``M_c (R/L)^3`` implied by ``omega_c = c_omega A/(zeta R^3 L)``.

    ``M_c = eta omega_c L^4 / A = (c_omega eta / zeta) (L/R)^3``, i.e. the returned
    ``c_M = c_omega ln(0.18 P/a) / pi``. Dimensionless.
    """
    return _pos("omega_prefactor", omega_prefactor) * rft_friction(1.0, pitch, filament_radius) ** -1


def critical_torque(bending: float, radius: float, coefficient: float = N_C_COEFFICIENT) -> float:
    """Critical motor torque ``N_c = 0.5 A / R`` [N m] (main text, Fig. 4(c))."""
    return _pos("coefficient", coefficient) * _pos("bending", bending) / _pos("radius", radius)


def peak_torque(bending: float, radius: float, coefficient: float = N_PEAK_COEFFICIENT) -> float:
    """Peak motor torque ``N_m = 0.9 A / R`` [N m] for ``omega/omega_c ~ 2`` (main text, Fig. 4(c))."""
    return critical_torque(bending, radius, coefficient)


def torque_pn_nm(bending_pn_um2: float, radius_um: float, coefficient: float = N_C_COEFFICIENT) -> float:
    """``coefficient * A / R`` in pN nm for ``A`` in pN um^2 and ``R`` in um (main text).

    ``torque_pn_nm(3.0, 0.6)`` is the paper's ``N_c ~ 2500 pN nm``;
    ``torque_pn_nm(3.0, 0.6, 0.9)`` its peak ``~ 4500 pN nm``.
    """
    return critical_torque(bending_pn_um2 * PN_UM2, radius_um * MICRON, coefficient) / PN_NM


@dataclass(frozen=True)
class PaperNumbers:
    """The bacterial- and model-scale numbers quoted in the main text, recomputed.

    Attributes
    ----------
    machin_bacterium : float
        ``M`` for ``A = 3 pN um^2``, ``eta = 1e-3 Pa s``, ``f = 150 Hz``, ``L = 7 um`` (paper: ~750).
    reynolds_bacterium : float
        ``Re`` for ``R = 0.6 um``, ``f = 50 Hz``, water (paper: ~1e-4).
    reynolds_model : float
        ``Re`` for ``R = 15 mm``, ``f = 0.01 Hz``, ``rho = 1250``, ``eta = 1.1`` (paper: ~2e-2).
    critical_torque_pn_nm, peak_torque_pn_nm : float
        ``0.5 A/R`` and ``0.9 A/R`` for ``A = 3 pN um^2``, ``R = 0.6 um`` (paper: 2500, 4500).
    omega_c_bacterium_material : tuple of float
        ``(E/eta)(a/R)^3(a/L)`` [rad/s] for ``E = 4e8``, ``eta = 1e-2`` and ``1e-3``, ``R/a = 100``,
        ``L/a = 1000`` (paper: "10^2 - 10^3 Hz").
    omega_c_model_material : float
        same for ``E = 1.3 MPa``, ``eta = 1.1``, ``R/a = 20``, ``L/a = 200`` [rad/s] (paper: "0.01-0.1 Hz").
    omega_c_model_rft : float
        ``A/(zeta R^3 L)`` [rad/s] for the same model with ``a = 1.5 mm``, ``P = 34 mm``.
    """

    machin_bacterium: float
    reynolds_bacterium: float
    reynolds_model: float
    critical_torque_pn_nm: float
    peak_torque_pn_nm: float
    omega_c_bacterium_material: tuple[float, float]
    omega_c_model_material: float
    omega_c_model_rft: float


def paper_numbers() -> PaperNumbers:
    """Recompute every order-of-magnitude number of the main text's scaling paragraphs."""
    two_pi = 2.0 * math.pi
    A_bact = 3.0 * PN_UM2
    a_model = 1.5e-3
    A_model = bending_stiffness(1.3e6, a_model)
    return PaperNumbers(
        machin_bacterium=machin_number(1e-3, two_pi * 150.0, 7.0 * MICRON, A_bact),
        reynolds_bacterium=reynolds_number(1e3, 0.6 * MICRON, two_pi * 50.0, 1e-3),
        reynolds_model=reynolds_number(1.25e3, 15e-3, two_pi * 0.01, 1.1),
        critical_torque_pn_nm=torque_pn_nm(3.0, 0.6, N_C_COEFFICIENT),
        peak_torque_pn_nm=torque_pn_nm(3.0, 0.6, N_PEAK_COEFFICIENT),
        omega_c_bacterium_material=(
            critical_angular_frequency_material(4e8, 1e-2, 1.0, 100.0, 1000.0),
            critical_angular_frequency_material(4e8, 1e-3, 1.0, 100.0, 1000.0),
        ),
        omega_c_model_material=critical_angular_frequency_material(1.3e6, 1.1, 1.0, 20.0, 200.0),
        omega_c_model_rft=critical_angular_frequency(
            A_model, rft_friction(1.1, 34e-3, a_model), 20 * a_model, 200 * a_model
        ),
    )
