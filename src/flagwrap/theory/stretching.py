"""Force-extension of a uniformly deformed helix with moment-free ends (main text Eq. 1, SI).

The helix is an inextensible Kirchhoff rod of arclength ``L`` whose stress-free shape is a
helix of radius ``R`` and pitch ``P``: curvature ``kappa0 = R / (R^2 + (P/2pi)^2)`` and
torsion ``tau0 = (P/2pi) / (R^2 + (P/2pi)^2)`` (SI, after the energy functional; the SI
misprints the second as a second ``kappa_0 =``). The pitch angle ``psi`` is measured from the
helix axis, so that the end-to-end distance of the inextensible centerline is
``z = L cos(psi)`` and ``tan(psi0) = 2 pi R / P``.

Energy (SI, "Detailed analysis of the uniaxial stretching test")::

    E = int_0^L [A1/2 k1^2 + A2/2 (k2 - kappa0)^2 + C/2 (tau - tau0)^2] ds - F z

with ``k1 = kappa cos(theta)``, ``k2 = kappa sin(theta)``, ``tau = theta' + tau_g`` and, for a
helix of pitch angle ``psi`` and radius ``R'``, ``kappa = sin^2(psi)/R'``,
``tau_g = sin(psi) cos(psi)/R'``. Moment-free ends leave both ``R'`` and ``psi`` free (the
number of turns is not conserved); the minimum over ``theta`` is ``theta = pi/2``,
``theta' = 0`` because ``A1 >= A2``. Eliminating ``1/R'`` and varying ``psi`` gives
(derivation in ``docs/theory.md``)::

    F / (A2 kappa0^2) = G (cos psi - lam sin psi)(sin psi + G lam cos psi)
                        / (sin psi (sin^2 psi + G cos^2 psi)^2)

with ``G = Gamma* = C/A2`` and ``lam = tau0/kappa0 = cot(psi0)``. For a round section
(``A1 = A2 = A``, ``G = Gamma = 1/(1+nu)``) this is main text Eq. 1 exactly. The SI's printed
Eq. (HelicalForce) has sine and cosine exchanged in the numerator and an unsquared
denominator; it does not follow from the functional (see :func:`si_printed_force` and the
tests, which compare both printed forms with :func:`minimise_uniform_helix`).

The extension adds the SI's weak axial-stretch term (SI Eq. PitchAngleForce):
``z/L = cos(psi) + F/(pi E a b)``.

All quantities are SI: lengths [m], forces [N], moduli [Pa], stiffnesses [N m^2].
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from flagwrap.errors import UserInputError, check_positive

__all__ = [
    "StretchedHelix",
    "helix_curvature_torsion",
    "reduced_force",
    "main_text_eq1_force",
    "si_printed_force",
    "pitch_angle_at_force",
    "uniform_helix_energy_density",
    "minimise_uniform_helix",
]


def _positive(name: str, value: float) -> float:
    return check_positive(name, value)


def helix_curvature_torsion(radius: float, pitch: float) -> tuple[float, float]:
    """Curvature and torsion of a helix of radius ``R`` and pitch ``P`` (SI, after the energy).

    ``kappa0 = 4 pi^2 R / (P^2 + 4 pi^2 R^2)``, ``tau0 = 2 pi P / (P^2 + 4 pi^2 R^2)``
    (the SI prints the torsion with the label ``kappa_0``; the formula is the torsion).

    Parameters
    ----------
    radius : float
        helix radius ``R`` [length].
    pitch : float
        helix pitch ``P`` [length].

    Returns
    -------
    (kappa0, tau0) : tuple of float
        [1/length].
    """
    R = _positive("radius", radius)
    P = _positive("pitch", pitch)
    denom = P**2 + 4.0 * math.pi**2 * R**2
    return 4.0 * math.pi**2 * R / denom, 2.0 * math.pi * P / denom


@dataclass(frozen=True)
class StretchedHelix:
    """An elastic helix of elliptic (or round) cross-section for the stretching test.

    Attributes
    ----------
    radius : float
        helix radius ``R`` [m] (> 0).
    pitch : float
        helix pitch ``P`` [m] (> 0).
    length : float
        arclength ``L`` [m] (> 0).
    youngs_modulus : float
        ``E`` [Pa] (> 0).
    poisson_ratio : float
        ``nu`` in (-1, 0.5].
    semi_axis_a : float
        larger cross-section semi-axis ``a`` [m] (> 0); for a round rod, its radius.
    semi_axis_b : float or None
        smaller semi-axis ``b`` [m], ``0 < b <= a``; ``None`` means round (``b = a``).

    Notes
    -----
    Stiffnesses (SI): ``A1 = pi E a^3 b / 4``, ``A2 = pi E a b^3 / 4`` and
    ``C = pi E a^3 b^3 / (2 (1+nu) (a^2+b^2))``. The SI prints ``A2 = 3 pi E a b^3 / 4``;
    the factor 3 is a misprint: it contradicts the SI's own ``Gamma* = C/A2 =
    2 Gamma/(1+(b/a)^2)`` and its ``A2 kappa0^2 = 0.020 N`` (``pi/4`` gives 0.0208 N,
    ``3 pi/4`` gives 0.062 N), and it would not reduce to ``A = pi E a^4/4`` for ``b = a``.
    """

    radius: float
    pitch: float
    length: float
    youngs_modulus: float
    poisson_ratio: float
    semi_axis_a: float
    semi_axis_b: float | None = None

    def __post_init__(self) -> None:
        for name in ("radius", "pitch", "length", "youngs_modulus", "semi_axis_a"):
            _positive(name, getattr(self, name))
        nu = float(self.poisson_ratio)
        if not (-1.0 < nu <= 0.5):
            raise UserInputError(f"poisson_ratio must lie in (-1, 0.5], got {nu!r}")
        if self.semi_axis_b is not None:
            b = _positive("semi_axis_b", self.semi_axis_b)
            if b > self.semi_axis_a:
                raise UserInputError(
                    f"semi_axis_b must satisfy 0 < b <= semi_axis_a = {self.semi_axis_a!r}, got {b!r}"
                )

    # --- geometry -------------------------------------------------------------------
    @property
    def b(self) -> float:
        """Smaller semi-axis ``b`` [m] (``a`` for a round rod)."""
        return self.semi_axis_a if self.semi_axis_b is None else float(self.semi_axis_b)

    @property
    def kappa0(self) -> float:
        """Spontaneous curvature [1/m]."""
        return helix_curvature_torsion(self.radius, self.pitch)[0]

    @property
    def tau0(self) -> float:
        """Spontaneous torsion [1/m]."""
        return helix_curvature_torsion(self.radius, self.pitch)[1]

    @property
    def lam(self) -> float:
        """``lambda = tau0/kappa0 = P/(2 pi R) = cot(psi0)`` (SI), dimensionless."""
        return self.pitch / (2.0 * math.pi * self.radius)

    @property
    def psi0(self) -> float:
        """Rest pitch angle from the axis, ``tan(psi0) = 2 pi R / P`` [rad]."""
        return math.atan2(2.0 * math.pi * self.radius, self.pitch)

    @property
    def turns(self) -> float:
        """Number of helical turns at rest, ``L / sqrt(P^2 + 4 pi^2 R^2)``."""
        return self.length / math.hypot(self.pitch, 2.0 * math.pi * self.radius)

    # --- stiffnesses ----------------------------------------------------------------
    @property
    def A1(self) -> float:
        """Bending stiffness about the stiff axis, ``pi E a^3 b / 4`` [N m^2]."""
        return math.pi * self.youngs_modulus * self.semi_axis_a**3 * self.b / 4.0

    @property
    def A2(self) -> float:
        """Bending stiffness in the plane of the spontaneous curvature, ``pi E a b^3 / 4`` [N m^2]."""
        return math.pi * self.youngs_modulus * self.semi_axis_a * self.b**3 / 4.0

    @property
    def C(self) -> float:
        """Twist stiffness ``pi E a^3 b^3 / (2 (1+nu)(a^2+b^2))`` [N m^2]."""
        a, b = self.semi_axis_a, self.b
        return math.pi * self.youngs_modulus * a**3 * b**3 / (2.0 * (1.0 + self.poisson_ratio) * (a * a + b * b))

    @property
    def gamma_star(self) -> float:
        """``Gamma* = C/A2 = 2 Gamma / (1 + (b/a)^2)`` with ``Gamma = 1/(1+nu)`` (SI Eq. Gamma)."""
        return self.C / self.A2

    @property
    def force_scale(self) -> float:
        """``A2 kappa0^2`` [N], the unit of force in Eq. 1 / SI Eq. HelicalForce."""
        return self.A2 * self.kappa0**2

    @property
    def stretch_compliance(self) -> float:
        """``1/(pi E a b)`` [1/N], coefficient of the axial-stretch term of ``z/L``."""
        return 1.0 / (math.pi * self.youngs_modulus * self.semi_axis_a * self.b)

    # --- force-extension ------------------------------------------------------------
    def force(self, psi: ArrayLike) -> np.ndarray:
        """Force ``F(psi)`` [N] at pitch angle ``psi`` [rad] (derived law, main text Eq. 1 form)."""
        return self.force_scale * reduced_force(psi, self.gamma_star, self.lam)

    def extension(self, psi: ArrayLike, *, axial_stretch: bool = True) -> np.ndarray:
        """``z/L = cos(psi) + F/(pi E a b)`` (SI Eq. PitchAngleForce); dimensionless."""
        psi = np.asarray(psi, dtype=float)
        z = np.cos(psi)
        if axial_stretch:
            z = z + self.force(psi) * self.stretch_compliance
        return z

    def force_extension(self, psi: ArrayLike, *, axial_stretch: bool = True) -> tuple[np.ndarray, np.ndarray]:
        """Curve ``(z/L, F [N])`` parametrised by the pitch angle ``psi`` [rad]."""
        return self.extension(psi, axial_stretch=axial_stretch), self.force(psi)


def reduced_force(psi: ArrayLike, gamma: float, lam: float) -> np.ndarray:
    """Derived force law ``F/(A2 kappa0^2)`` of a uniform helix with moment-free ends.

    ``G (cos psi - lam sin psi)(sin psi + G lam cos psi) / (sin psi (sin^2 psi + G cos^2 psi)^2)``;
    identical to main text Eq. 1 with ``G = Gamma`` and ``lam = cot(psi0)``; for an elliptic
    section ``G = Gamma* = C/A2`` and ``lam = tau0/kappa0`` (SI notation).

    Parameters
    ----------
    psi : array_like
        pitch angle from the helix axis [rad], in (0, pi/2].
    gamma : float
        twist-to-bend ratio ``C/A2`` (dimensionless, > 0).
    lam : float
        ``tau0/kappa0`` (dimensionless, >= 0).

    Returns
    -------
    ndarray
        dimensionless force, positive when stretched (``psi < psi0``).
    """
    psi = np.asarray(psi, dtype=float)
    s, c = np.sin(psi), np.cos(psi)
    d = s * s + gamma * c * c
    return gamma * (c - lam * s) * (s + gamma * lam * c) / (s * d * d)


def main_text_eq1_force(psi: ArrayLike, gamma: float, psi0: float) -> np.ndarray:
    """Main text Eq. 1 exactly as printed: ``F/(A kappa0^2)`` for a round section.

    ``Gamma (cos psi - cot psi0 sin psi)(sin psi + Gamma cot psi0 cos psi)
    / (sin psi (sin^2 psi + Gamma cos^2 psi)^2)``, ``Gamma = C/A = 1/(1+nu)``, angles [rad]
    from the helix axis.
    """
    psi = np.asarray(psi, dtype=float)
    s, c = np.sin(psi), np.cos(psi)
    cot0 = 1.0 / math.tan(psi0)
    return gamma * (c - cot0 * s) * (s + gamma * cot0 * c) / (s * (s * s + gamma * c * c) ** 2)


def si_printed_force(psi: ArrayLike, gamma_star: float, lam: float) -> np.ndarray:
    """SI Eq. (HelicalForce) exactly as printed: ``F/(A2 kappa0^2)``.

    ``G (sin psi - lam cos psi)(cos psi + G lam sin psi) / (sin psi (sin^2 psi + G cos^2 psi))``.
    Kept only to document the misprint: with ``psi`` from the axis (as the SI's own
    ``z/L = cos psi`` requires) it vanishes at ``tan psi = lam`` instead of at ``psi0``; read
    with ``psi`` from the plane it has the right zero but the wrong denominator. Neither
    reading matches :func:`minimise_uniform_helix`; use :func:`reduced_force`.
    """
    psi = np.asarray(psi, dtype=float)
    s, c = np.sin(psi), np.cos(psi)
    g = gamma_star
    return g * (s - lam * c) * (c + g * lam * s) / (s * (s * s + g * c * c))


def pitch_angle_at_force(helix: StretchedHelix, force: float) -> float:
    """Invert the derived law: the pitch angle ``psi`` [rad] at which the force is ``force`` [N].

    ``F(psi)`` decreases monotonically from ``+inf`` at ``psi -> 0`` through 0 at ``psi0``;
    the root is bracketed on ``(0, pi/2]`` and found with Brent's method (``xtol`` 1e-15).
    """
    from scipy.optimize import brentq

    f_target = float(force) / helix.force_scale
    g, lam = helix.gamma_star, helix.lam

    def resid(p: float) -> float:
        return float(reduced_force(p, g, lam)) - f_target

    lo, hi = 1e-9, 0.5 * math.pi
    if resid(hi) > 0.0:
        raise UserInputError(
            f"force {force!r} N is below the force at psi = 90 deg ({reduced_force(hi, g, lam) * helix.force_scale!r} N)"
        )
    return float(brentq(resid, lo, hi, xtol=1e-15, rtol=4 * np.finfo(float).eps, maxiter=500))


# --- direct minimisation of the SI energy functional (test oracle) -------------------------
_GL_NODES, _GL_WEIGHTS = np.polynomial.legendre.leggauss(64)


def uniform_helix_energy_density(
    x: ArrayLike, helix: StretchedHelix, force: float
) -> float:
    """SI energy functional per unit length of a helical centerline, in units of ``A2 kappa0``.

    The centerline is a helix of curvature ``kappa`` and geometric torsion ``tau_g``; the
    material frame makes the angle ``theta(s) = theta0 + w s`` with the normal, so that
    ``k1 = kappa cos theta``, ``k2 = kappa sin theta``, ``tau = w + tau_g`` (SI). The
    arclength average over ``[0, L]`` is computed with 64-point Gauss-Legendre quadrature.
    ``z = L tau_g / sqrt(kappa^2 + tau_g^2) = L cos psi``.

    Parameters
    ----------
    x : array_like, shape (4,)
        ``(log(kappa/kappa0), tau_g/kappa0, theta0, w/kappa0)``.
    helix : StretchedHelix
    force : float
        pulling force [N].

    Returns
    -------
    float
        ``(E/L) / (A2 kappa0)`` (dimensionless).
    """
    p, q, th0, w = (float(v) for v in x)
    k0 = helix.kappa0
    kap = math.exp(p)  # in units of kappa0
    lam = helix.lam
    a1 = helix.A1 / helix.A2
    g = helix.gamma_star
    wl = w * k0 * helix.length  # total extra twist angle
    theta = th0 + 0.5 * wl * (_GL_NODES + 1.0)
    bend = float(
        0.5 * np.sum(_GL_WEIGHTS * (0.5 * a1 * (kap * np.cos(theta)) ** 2 + 0.5 * (kap * np.sin(theta) - 1.0) ** 2))
    )
    twist = 0.5 * g * (w + q - lam) ** 2
    cos_psi = q / math.hypot(kap, q)
    return bend + twist - (float(force) / helix.force_scale) * cos_psi


@dataclass(frozen=True)
class UniformHelixMinimum:
    """Result of :func:`minimise_uniform_helix`.

    Attributes
    ----------
    psi : float
        pitch angle from the axis [rad].
    kappa, tau_g : float
        curvature and geometric torsion [1/m].
    theta0 : float
        material-frame angle (``pi/2`` means the spontaneous curvature lies in the bending plane).
    twist_rate : float
        ``theta'`` [1/m].
    energy : float
        energy per length in units of ``A2 kappa0``.
    """

    psi: float
    kappa: float
    tau_g: float
    theta0: float
    twist_rate: float
    energy: float


def minimise_uniform_helix(
    helix: StretchedHelix, force: float, *, allow_frame_twist: bool = False
) -> UniformHelixMinimum:
    """Minimise the SI energy functional directly over helical configurations (test oracle).

    Independent of the closed form. Unknowns: curvature, geometric torsion and the frame
    angle ``theta0`` (a *uniform* deformation: ``k1``, ``k2``, ``tau`` constant along ``s``,
    the SI's assumption); with ``allow_frame_twist=True`` also a constant frame twist rate
    ``w = theta'`` (then ``k1``, ``k2`` vary along ``s`` and the deformation is no longer
    uniform: a finite-length diagnostic, see ``docs/theory.md``). BFGS (gradient tolerance
    1e-13) from the rest shape, then Newton steps on central-difference derivatives.

    Parameters
    ----------
    helix : StretchedHelix
    force : float
        pulling force [N].
    allow_frame_twist : bool
        also vary ``theta'`` (default ``False``).

    Returns
    -------
    UniformHelixMinimum
    """
    from scipy.optimize import minimize

    n = 4 if allow_frame_twist else 3

    def fun(x: np.ndarray) -> float:
        full = x if allow_frame_twist else np.append(x, 0.0)
        return uniform_helix_energy_density(full, helix, force)

    x = np.array([0.0, helix.lam, 0.5 * math.pi + 0.05, 0.0][:n])
    x = minimize(fun, x, method="BFGS", options={"gtol": 1e-13, "maxiter": 10000}).x
    h = 1e-4
    eye = np.eye(n) * h
    for _ in range(20):
        grad = np.array([(fun(x + eye[i]) - fun(x - eye[i])) / (2 * h) for i in range(n)])
        hess = np.empty((n, n))
        for i in range(n):
            for j in range(i, n):
                hess[i, j] = hess[j, i] = (
                    fun(x + eye[i] + eye[j]) - fun(x + eye[i] - eye[j]) - fun(x - eye[i] + eye[j]) + fun(x - eye[i] - eye[j])
                ) / (4 * h * h)
        step = np.linalg.solve(hess, grad)
        x = x - step
        if np.max(np.abs(step)) < 1e-13:
            break
    kap = math.exp(x[0]) * helix.kappa0
    tau_g = x[1] * helix.kappa0
    return UniformHelixMinimum(
        psi=math.atan2(kap, tau_g),
        kappa=kap,
        tau_g=tau_g,
        theta0=float(x[2]),
        twist_rate=float(x[3]) * helix.kappa0 if allow_frame_twist else 0.0,
        energy=float(fun(x)),
    )
