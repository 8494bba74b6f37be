"""Shear viscosity of the glycerin bath (SI, "Measurement of shear viscosity of glycerin").

* falling sphere, Stokes drag with buoyancy (SI Eq. etaStokes):
  ``eta = (2/9) (rho - rho_gly) a^2 g / U``
* slender rod pushed along its axis (SI Eq. Force:Stokes:LongRod:all):
  ``F = -rho_gly g S L - 2 pi eta L U / (ln(L/a) - 1/2)``, fitted for ``eta`` (and optionally
  ``rho_gly``) by linear least squares over the immersed lengths ``L``
* Andrade's law (SI Eq. AndradeViscosityEquation): ``eta(T) = eta_inf exp(U / (k_B T))``,
  fitted as ``ln eta = ln eta_inf + U/(k_B T)`` by weighted linear least squares
* the correction of ``M = eta omega L^4 / A`` for the room temperature (SI, same section)

SI units throughout: kg/m^3, m, m/s, N, Pa s, K, J.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from flagwrap.errors import UserInputError
from flagwrap.units import G_ACCEL, K_B

__all__ = [
    "ANDRADE_ETA_INF",
    "ANDRADE_ENERGY",
    "REFERENCE_TEMPERATURE",
    "SphereResult",
    "sphere_viscosity",
    "sphere_terminal_velocity",
    "LinearFit",
    "terminal_velocity_fit",
    "rod_force",
    "RodFit",
    "fit_rod_viscosity",
    "andrade_viscosity",
    "AndradeFit",
    "fit_andrade",
    "machin_at_temperature",
]

#: SI's fitted Andrade prefactor ``eta_inf`` [Pa s]
ANDRADE_ETA_INF = 6.92687e-10
#: SI's fitted Andrade activation energy ``U`` [J]
ANDRADE_ENERGY = 8.559e-20
#: temperature assumed when the room temperature was not recorded (SI): 20 C [K]
REFERENCE_TEMPERATURE = 293.15


def _pos(name: str, value: float) -> float:
    from flagwrap.errors import check_positive

    return check_positive(name, value)


@dataclass(frozen=True)
class SphereResult:
    """Viscosity from a falling sphere.

    Attributes
    ----------
    viscosity, viscosity_error : float
        ``eta`` and its one-sigma error [Pa s] (from the velocity error).
    reynolds_fluid, reynolds_sphere : float
        ``Re = rho U (2a) / eta`` with the liquid's and with the sphere's density; the SI
        quotes "Re ~ 0.3" without saying which density it uses.
    """

    viscosity: float
    viscosity_error: float
    reynolds_fluid: float
    reynolds_sphere: float


def sphere_viscosity(
    terminal_velocity: float,
    sphere_radius: float,
    sphere_density: float,
    fluid_density: float,
    *,
    velocity_error: float = 0.0,
    gravity: float = G_ACCEL,
) -> SphereResult:
    """Viscosity from the terminal velocity of a falling sphere (SI Eq. etaStokes).

    ``eta = (2/9) (rho - rho_gly) a^2 g / U``: Stokes drag ``6 pi eta a U`` balancing weight
    minus buoyancy. No wall or inertia (Oseen) correction, as in the SI.

    Parameters
    ----------
    terminal_velocity : float
        ``U`` [m/s].
    sphere_radius : float
        ``a`` [m].
    sphere_density, fluid_density : float
        ``rho`` and ``rho_gly`` [kg/m^3], ``rho > rho_gly``.
    velocity_error : float
        one-sigma error of ``U`` [m/s].
    gravity : float
        ``g`` [m/s^2].

    Examples
    --------
    The SI's measurement (a = 2.5 mm, rho = 7.42 g/cm^3, U = 73.7 +- 0.8 mm/s):

    >>> r = sphere_viscosity(73.7e-3, 2.5e-3, 7420.0, 1250.0, velocity_error=0.8e-3)
    >>> round(r.viscosity, 2), round(r.viscosity_error, 2)
    (1.14, 0.01)
    """
    U = _pos("terminal_velocity", terminal_velocity)
    a = _pos("sphere_radius", sphere_radius)
    rho = _pos("sphere_density", sphere_density)
    rho_f = _pos("fluid_density", fluid_density)
    if rho <= rho_f:
        raise UserInputError(f"sphere_density ({rho}) must exceed fluid_density ({rho_f}) for the sphere to fall")
    eta = 2.0 / 9.0 * (rho - rho_f) * a * a * _pos("gravity", gravity) / U
    return SphereResult(
        viscosity=eta,
        viscosity_error=eta * abs(float(velocity_error)) / U,
        reynolds_fluid=rho_f * U * 2 * a / eta,
        reynolds_sphere=rho * U * 2 * a / eta,
    )


def sphere_terminal_velocity(
    viscosity: float, sphere_radius: float, sphere_density: float, fluid_density: float, gravity: float = G_ACCEL
) -> float:
    """Inverse of :func:`sphere_viscosity`: Stokes terminal velocity [m/s]."""
    eta = _pos("viscosity", viscosity)
    return sphere_viscosity(1.0, sphere_radius, sphere_density, fluid_density, gravity=gravity).viscosity / eta


@dataclass(frozen=True)
class LinearFit:
    """``y = slope x + intercept`` with one-sigma errors from the covariance."""

    slope: float
    intercept: float
    slope_error: float
    intercept_error: float


def terminal_velocity_fit(time: ArrayLike, distance: ArrayLike, *, t_min: float | None = None) -> LinearFit:
    """Terminal velocity as the slope of distance vs time (SI Fig. S3 a).

    Ordinary least squares on the points with ``time >= t_min`` (default: all); errors from
    the covariance scaled by the residual variance.

    Parameters
    ----------
    time : array_like
        [s].
    distance : array_like
        travelled distance [m].
    t_min : float, optional
        discard the acceleration transient before this time [s].
    """
    t = np.asarray(time, dtype=float)
    z = np.asarray(distance, dtype=float)
    if t.shape != z.shape or t.ndim != 1:
        raise UserInputError("time and distance must be 1-D arrays of equal length")
    if t_min is not None:
        keep = t >= t_min
        t, z = t[keep], z[keep]
    if t.size < 3:
        raise UserInputError("need at least 3 (time, distance) points to fit a velocity")
    (slope, icpt), cov = np.polyfit(t, z, 1, cov=True)
    return LinearFit(float(slope), float(icpt), float(np.sqrt(cov[0, 0])), float(np.sqrt(cov[1, 1])))


def _rod_drag_shape(length: np.ndarray, rod_radius: float) -> np.ndarray:
    ln = np.log(length / rod_radius) - 0.5
    if np.any(ln <= 0):
        raise UserInputError("rod drag needs ln(L/a) > 1/2 for every immersed length")
    return 2.0 * math.pi * length / ln


def rod_force(
    length: ArrayLike,
    viscosity: float,
    speed: float,
    rod_radius: float,
    fluid_density: float,
    gravity: float = G_ACCEL,
) -> np.ndarray:
    """Vertical force on a rod pushed into the liquid (SI Eq. Force:Stokes:LongRod:all) [N].

    ``F = -rho_gly g S L - 2 pi eta L U / (ln(L/a) - 1/2)`` with ``S = pi a^2``; the SI's sign
    convention (force measured relative to the rod's weight in air).

    Parameters
    ----------
    length : array_like
        immersed length ``L`` [m].
    viscosity : float
        ``eta`` [Pa s].
    speed : float
        ``U`` [m/s].
    rod_radius : float
        ``a`` [m].
    fluid_density : float
        ``rho_gly`` [kg/m^3].
    """
    L = np.asarray(length, dtype=float)
    a = _pos("rod_radius", rod_radius)
    buoy = _pos("fluid_density", fluid_density) * gravity * math.pi * a * a * L
    return -buoy - _pos("viscosity", viscosity) * _pos("speed", speed) * _rod_drag_shape(L, a)


@dataclass(frozen=True)
class RodFit:
    """Result of :func:`fit_rod_viscosity`.

    Attributes
    ----------
    viscosity, viscosity_error : float
        [Pa s].
    fluid_density, fluid_density_error : float
        [kg/m^3]; the fixed input and 0 unless it was fitted.
    """

    viscosity: float
    viscosity_error: float
    fluid_density: float
    fluid_density_error: float


def fit_rod_viscosity(
    length: ArrayLike,
    force: ArrayLike,
    speed: float,
    rod_radius: float,
    fluid_density: float,
    *,
    fit_density: bool = False,
    force_error: ArrayLike | None = None,
    gravity: float = G_ACCEL,
) -> RodFit:
    """Fit ``eta`` (and optionally ``rho_gly``) to force vs immersed length (SI Fig. S3 b).

    The model :func:`rod_force` is linear in ``(rho_gly, eta)``; weighted linear least squares.
    With ``force_error`` the errors are absolute; otherwise the covariance is scaled by the
    residual variance.

    Parameters
    ----------
    length, force : array_like
        immersed lengths [m] and measured forces [N], in the SI's sign convention (negative).
    speed, rod_radius, fluid_density : float
        ``U`` [m/s], ``a`` [m], ``rho_gly`` [kg/m^3] (the initial/fixed density).
    fit_density : bool
        also fit the buoyancy density.
    force_error : array_like, optional
        one-sigma errors of ``force`` [N].
    """
    L = np.asarray(length, dtype=float)
    F = np.asarray(force, dtype=float)
    if L.shape != F.shape or L.ndim != 1:
        raise UserInputError("length and force must be 1-D arrays of equal length")
    a = _pos("rod_radius", rod_radius)
    drag = -_pos("speed", speed) * _rod_drag_shape(L, a)
    buoy = -gravity * math.pi * a * a * L
    if fit_density:
        design = np.column_stack([drag, buoy])
        target = F
    else:
        design = drag[:, None]
        target = F - _pos("fluid_density", fluid_density) * buoy
    if L.size <= design.shape[1]:
        raise UserInputError("need more data points than fitted parameters")
    w = np.ones_like(F) if force_error is None else 1.0 / np.asarray(force_error, dtype=float)
    coef, *_ = np.linalg.lstsq(design * w[:, None], target * w, rcond=None)
    cov = np.linalg.inv((design * w[:, None]).T @ (design * w[:, None]))
    if force_error is None:
        r = target - design @ coef
        cov = cov * float(r @ r) / (L.size - design.shape[1])
    err = np.sqrt(np.diag(cov))
    if not coef[0] > 0:
        raise UserInputError(
            f"the fit gives a viscosity eta = {coef[0]:.3g} Pa s <= 0: the forces do not grow with "
            "the immersed length as drag does (the buoyancy term exceeds the measured force; check "
            "the sign of F, --fluid-density and the units)")
    if fit_density and not coef[1] > 0:
        raise UserInputError(f"the fit gives a fluid density {coef[1]:.3g} kg/m^3 <= 0: fix the "
                             "density instead (drop --fit-density)")
    if fit_density:
        return RodFit(float(coef[0]), float(err[0]), float(coef[1]), float(err[1]))
    return RodFit(float(coef[0]), float(err[0]), float(fluid_density), 0.0)


def andrade_viscosity(
    temperature: ArrayLike, eta_inf: float = ANDRADE_ETA_INF, energy: float = ANDRADE_ENERGY
) -> np.ndarray:
    """Andrade's law ``eta(T) = eta_inf exp(U / (k_B T))`` [Pa s] (SI Eq. AndradeViscosityEquation).

    Defaults are the SI's fit to its glycerin, ``eta_inf = 6.92687e-10 Pa s``,
    ``U = 8.559e-20 J``.

    Parameters
    ----------
    temperature : array_like
        absolute temperature [K], > 0.
    """
    T = np.asarray(temperature, dtype=float)
    if np.any(~np.isfinite(T)) or np.any(T <= 0):
        raise UserInputError("temperature must be in kelvin and > 0")
    return _pos("eta_inf", eta_inf) * np.exp(_pos("energy", energy) / (K_B * T))


@dataclass(frozen=True)
class AndradeFit:
    """Andrade parameters with one-sigma errors and their correlation.

    Attributes
    ----------
    eta_inf, eta_inf_error : float
        [Pa s]; the error is propagated from ``ln eta_inf`` (``sigma = eta_inf sigma_ln``).
    energy, energy_error : float
        ``U`` [J].
    log_eta_inf, log_eta_inf_error : float
        ``ln(eta_inf / (1 Pa s))`` and its error, the parameter actually fitted.
    correlation : float
        correlation coefficient of ``(ln eta_inf, U)``.
    chi2_reduced : float
        reduced chi-square (1 expected when ``eta_error`` is right).
    """

    eta_inf: float
    eta_inf_error: float
    energy: float
    energy_error: float
    log_eta_inf: float
    log_eta_inf_error: float
    correlation: float
    chi2_reduced: float

    def viscosity(self, temperature: ArrayLike) -> np.ndarray:
        """``eta(T)`` [Pa s] with the fitted parameters."""
        return andrade_viscosity(temperature, self.eta_inf, self.energy)


def fit_andrade(temperature: ArrayLike, viscosity: ArrayLike, viscosity_error: ArrayLike | None = None) -> AndradeFit:
    """Fit Andrade's law to ``(T, eta)`` data (SI Fig. S3 c).

    Weighted linear least squares of ``ln eta = ln eta_inf + U x`` with ``x = 1/(k_B T)`` and
    ``sigma_ln = sigma_eta / eta``. With ``viscosity_error`` the covariance is absolute;
    without, unit weights and the covariance scaled by the residual variance.

    Parameters
    ----------
    temperature : array_like
        [K].
    viscosity : array_like
        [Pa s], > 0.
    viscosity_error : array_like, optional
        one-sigma errors [Pa s].
    """
    T = np.asarray(temperature, dtype=float)
    eta = np.asarray(viscosity, dtype=float)
    if T.shape != eta.shape or T.ndim != 1 or T.size < 3:
        raise UserInputError("temperature and viscosity must be 1-D arrays of equal length >= 3")
    if np.any(eta <= 0) or np.any(T <= 0):
        raise UserInputError("temperature [K] and viscosity [Pa s] must be > 0")
    x = 1.0 / (K_B * T)
    y = np.log(eta)
    absolute = viscosity_error is not None
    sig = np.asarray(viscosity_error, dtype=float) / eta if absolute else np.ones_like(y)
    if np.any(sig <= 0):
        raise UserInputError("viscosity_error must be > 0")
    # centre and scale x for conditioning: y = c0 + c1 (x - xm)/xs; U = c1/xs, ln eta_inf = c0 - U xm
    xm = float(np.average(x, weights=sig**-2))
    xs = float(np.ptp(x)) or 1.0
    X = np.column_stack([np.ones_like(x), (x - xm) / xs]) / sig[:, None]
    coef, *_ = np.linalg.lstsq(X, y / sig, rcond=None)
    cov_c = np.linalg.inv(X.T @ X)
    resid = y / sig - X @ coef
    chi2 = float(resid @ resid) / (T.size - 2)
    if not absolute:
        cov_c = cov_c * chi2
    jac = np.array([[1.0, -xm / xs], [0.0, 1.0 / xs]])  # (ln eta_inf, U) from (c0, c1)
    cov = jac @ cov_c @ jac.T
    energy = float(coef[1] / xs)
    ln_inf = float(coef[0] - energy * xm)
    err = np.sqrt(np.diag(cov))
    if not (math.isfinite(ln_inf) and abs(ln_inf) < 700.0 and np.all(np.isfinite(err))):
        from flagwrap.errors import ResultError

        raise ResultError(f"the Andrade fit gives ln(eta_inf / Pa s) = {ln_inf:.6g}, U = {energy:.6g} J: "
                          "not a liquid's law (the viscosities do not fall smoothly with temperature)")
    return AndradeFit(
        eta_inf=math.exp(ln_inf),
        eta_inf_error=math.exp(ln_inf) * float(err[0]),
        energy=energy,
        energy_error=float(err[1]),
        log_eta_inf=ln_inf,
        log_eta_inf_error=float(err[0]),
        correlation=float(cov[0, 1] / (err[0] * err[1])),
        chi2_reduced=chi2,
    )


def machin_at_temperature(
    machin_reference: float,
    temperature: float,
    reference_temperature: float = REFERENCE_TEMPERATURE,
    eta_inf: float = ANDRADE_ETA_INF,
    energy: float = ANDRADE_ENERGY,
) -> float:
    """Correct ``M = eta omega L^4 / A`` for the room temperature (SI, "Temperature dependence").

    ``M(T) = M(T_ref) eta(T) / eta(T_ref)`` with Andrade's ``eta(T)``; the ratio
    ``exp(U/k_B (1/T - 1/T_ref))`` does not depend on ``eta_inf``. The SI uses 20 C when the
    room temperature was not recorded. Dimensionless.

    Parameters
    ----------
    machin_reference : float
        ``M`` computed with ``eta(T_ref)``.
    temperature, reference_temperature : float
        [K].
    """
    ratio = float(andrade_viscosity(temperature, eta_inf, energy) / andrade_viscosity(reference_temperature, eta_inf, energy))
    return _pos("machin_reference", machin_reference) * ratio
