"""Polymorph order parameter of a filament: a double-well local energy, a gradient
(domain-wall) energy, the rest curvature and twist it selects, and the analytic results
(tanh domain wall, its width and energy, spinodal and Maxwell torques) the tests check.

The model (docs/polymorph.md) is the continuous bistable-filament picture of Goldstein,
Goriely, Huber & Wolgemuth, Phys. Rev. Lett. 84, 1631 (2000): a Landau energy with two wells
plus a square-gradient term, here written for an order parameter ``phi`` per vertex of the
discrete rod rather than for the twist density itself. ``phi = -1`` is polymorph A (e.g.
normal), ``phi = +1`` polymorph B (e.g. semicoiled). Per unit length

    e(phi) = W f(phi) - h(N) phi + (K/2) (dphi/ds)^2,   f(phi) = (1 - phi^2)^2 / 4      (P1)

with the tilt by the axial moment ``N`` (the fixed-moment Legendre transform of the twist
energy ``C/2 (Omega_3 - omega_3(phi))^2``, whose rest twist density moves by ``Delta`` from A
to B, see :func:`interpolate_rest`)

    h(N) = (N - N_M) Delta / 2                                                          (P2)

``N_M`` is the Maxwell (coexistence) torque, a parameter of the landscape (the two polymorphs'
intrinsic energy difference, not published for flagellin). Discretised on vertices ``i`` with
Voronoi lengths ``v_i`` and bonds ``j`` of length ``l_j`` between vertices ``j`` and ``j+1``:

    E = sum_i v_i [W f(phi_i) - h phi_i] + sum_j K / (2 l_j) (phi_{j+1} - phi_j)^2       (P3)

Analytic results of the continuum (P1):

* domain wall at ``h = 0``: ``phi(s) = tanh((s - s_0)/w)``, ``w = sqrt(2 K / W)``       (P4)
* its energy ``sigma = (2 sqrt 2 / 3) sqrt(K W)``                                       (P5)
* spinodal tilt ``h_s = 2 W / (3 sqrt 3)`` (a uniform well vanishes), i.e. the torques
  ``N_M +- H`` with the half-width ``H = 4 W / (3 sqrt 3 |Delta|)``; a quasi-static sweep
  switches A -> B at ``N_M + sign(Delta) H`` and back at ``N_M - sign(Delta) H``          (P6)
* Maxwell: the two wells' energies are equal at ``h = 0``, i.e. ``N = N_M``              (P7)

Units: the package's dimensionless core units (length ``L``, energy and torque ``A/L``), so
``W`` is an energy per length ``[A/L^2]``, ``K`` an energy times length ``[A]``, ``Delta`` a
twist density ``[1/L]``; any consistent units work since nothing here converts. Pure numpy;
the loops are vectorised (no hot loop that would need numba).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from flagwrap.errors import UserInputError, check_finite, check_positive

__all__ = [
    "SPINODAL_TILT",
    "PolymorphModel",
    "double_well",
    "double_well_prime",
    "local_energy",
    "local_energy_grad",
    "gradient_energy",
    "gradient_energy_grad",
    "total_energy",
    "total_energy_grad",
    "total_energy_hessian_bands",
    "interpolate_rest",
    "rest_derivative",
    "elastic_phi_gradient",
    "wall_profile",
    "helix_curvature_torsion",
    "check_wall_resolution",
]

#: the spinodal tilt in units of the barrier ``W``: ``max_phi |f'(phi)|`` on the inner branch,
#: ``|f'(+-1/sqrt 3)| = 2 / (3 sqrt 3)`` (P6)
SPINODAL_TILT = 2.0 / (3.0 * math.sqrt(3.0))


def double_well(phi):
    """``f(phi) = (1 - phi^2)^2 / 4``: minima 0 at ``phi = +-1``, barrier ``1/4`` at 0 (P1)."""
    phi = np.asarray(phi, dtype=float)
    return 0.25 * (1.0 - phi * phi) ** 2


def double_well_prime(phi):
    """``f'(phi) = phi^3 - phi``."""
    phi = np.asarray(phi, dtype=float)
    return phi * phi * phi - phi


@dataclass(frozen=True)
class PolymorphModel:
    """The landscape of one two-polymorph transition, in consistent (e.g. core) units.

    Attributes
    ----------
    barrier : float
        ``W > 0``, the well depth scale per length: the barrier between the wells is ``W/4``.
    stiffness : float
        ``K > 0``, the gradient (domain-wall) coefficient of (P1).
    delta_twist : float
        ``Delta``: rest twist density of B minus that of A (the conjugate of the axial moment);
        0 makes the load unable to switch the state.
    maxwell_torque : float
        ``N_M``: the axial moment at which both polymorphs have equal energy (P7).
    """

    barrier: float
    stiffness: float
    delta_twist: float
    maxwell_torque: float = 0.0

    def __post_init__(self):
        check_positive("polymorph.barrier", self.barrier)
        check_positive("polymorph.stiffness", self.stiffness)
        check_finite("polymorph.delta_twist", self.delta_twist)
        check_finite("polymorph.maxwell_torque", self.maxwell_torque)

    @classmethod
    def from_thresholds(cls, torque_forward: float, torque_back: float, delta_twist: float,
                        wall_width: float) -> "PolymorphModel":
        """The model whose quasi-static loop (P6) switches A -> B at ``torque_forward`` and
        B -> A at ``torque_back``, with the domain-wall width ``wall_width`` (P4):
        ``N_M`` = their midpoint, ``W = 3 sqrt 3 |Delta| H / 4`` with ``H`` half their distance,
        ``K = W w^2 / 2``. ``sign(Delta)`` must match the loop's direction (forward above back
        for ``Delta > 0``)."""
        f = check_finite("torque_forward", torque_forward)
        bk = check_finite("torque_back", torque_back)
        d = check_finite("delta_twist", delta_twist)
        w = check_positive("wall_width", wall_width)
        if d == 0.0 or f == bk:
            raise UserInputError("a switching loop needs delta_twist != 0 and two different "
                                 f"thresholds, got delta_twist={d!r}, {f!r} and {bk!r}")
        if (f - bk) * d < 0:
            raise UserInputError(f"torque_forward ({f:g}) must be {'above' if d > 0 else 'below'} "
                                 f"torque_back ({bk:g}) for delta_twist {d:g} (P6)")
        half = 0.5 * abs(f - bk)
        barrier = 3.0 * math.sqrt(3.0) * abs(d) * half / 4.0
        return cls(barrier=barrier, stiffness=barrier * w * w / 2.0, delta_twist=d,
                   maxwell_torque=0.5 * (f + bk))

    # --- analytic results -------------------------------------------------------------
    @property
    def wall_width(self) -> float:
        """``w = sqrt(2 K / W)`` of the tanh wall (P4)."""
        return math.sqrt(2.0 * self.stiffness / self.barrier)

    @property
    def wall_energy(self) -> float:
        """``sigma = (2 sqrt 2 / 3) sqrt(K W)`` (P5)."""
        return 2.0 * math.sqrt(2.0) / 3.0 * math.sqrt(self.stiffness * self.barrier)

    @property
    def spinodal_half_width(self) -> float:
        """``H = 4 W / (3 sqrt 3 |Delta|)`` (P6); ``inf`` when ``Delta = 0``."""
        if self.delta_twist == 0.0:
            return math.inf
        return 2.0 * SPINODAL_TILT * self.barrier / abs(self.delta_twist)

    @property
    def switch_torques(self) -> tuple[float, float]:
        """The quasi-static loop's two thresholds ``(A -> B, B -> A)`` (P6)."""
        s = math.copysign(1.0, self.delta_twist) * self.spinodal_half_width
        return self.maxwell_torque + s, self.maxwell_torque - s

    def tilt(self, torque: float) -> float:
        """``h(N) = (N - N_M) Delta / 2`` (P2)."""
        return (torque - self.maxwell_torque) * self.delta_twist / 2.0


def check_wall_resolution(wall_width: float, bead_spacing: float,
                          name: str = "polymorph.wall_width") -> float:
    """``wall_width`` as a float, or a one-line :class:`UserInputError` when it is below the
    bead spacing (a wall narrower than a bond is not resolved: (P3) then pins it to the
    lattice and its energy is off by more than (b/w)^2 ~ 1)."""
    w = check_positive(name, wall_width)
    b = check_positive("bead spacing", bead_spacing)
    if w < b:
        raise UserInputError(f"{name} must be >= the bead spacing {b:g} (in [{b:g}, inf)), got {w:g}")
    return w


# --- the discrete energy (P3) and its gradient ----------------------------------------
def local_energy(phi, model: PolymorphModel, torque: float, vor) -> float:
    """``sum_i v_i [W f(phi_i) - h(N) phi_i]`` (P3, first sum); ``vor`` scalar or per vertex."""
    phi = np.asarray(phi, dtype=float)
    h = model.tilt(torque)
    return float(np.sum(np.asarray(vor, dtype=float) * (model.barrier * double_well(phi) - h * phi)))


def local_energy_grad(phi, model: PolymorphModel, torque: float, vor) -> np.ndarray:
    """``d/dphi_i`` of :func:`local_energy`: ``v_i [W (phi_i^3 - phi_i) - h]``."""
    phi = np.asarray(phi, dtype=float)
    h = model.tilt(torque)
    return np.asarray(vor, dtype=float) * (model.barrier * double_well_prime(phi) - h) * np.ones_like(phi)


def gradient_energy(phi, stiffness: float, lengths) -> float:
    """``sum_j K / (2 l_j) (phi_{j+1} - phi_j)^2`` (P3, second sum); ``lengths`` scalar or
    per bond (``len(phi) - 1``)."""
    d = np.diff(np.asarray(phi, dtype=float))
    return float(np.sum(0.5 * stiffness * d * d / np.asarray(lengths, dtype=float)))


def gradient_energy_grad(phi, stiffness: float, lengths) -> np.ndarray:
    """``d/dphi_i`` of :func:`gradient_energy` (free ends: a discrete Neumann Laplacian)."""
    phi = np.asarray(phi, dtype=float)
    flux = stiffness * np.diff(phi) / np.asarray(lengths, dtype=float)
    g = np.zeros_like(phi)
    g[:-1] -= flux
    g[1:] += flux
    return g


def total_energy(phi, model: PolymorphModel, torque: float, vor, lengths) -> float:
    """(P3): :func:`local_energy` + :func:`gradient_energy`."""
    return local_energy(phi, model, torque, vor) + gradient_energy(phi, model.stiffness, lengths)


def total_energy_grad(phi, model: PolymorphModel, torque: float, vor, lengths) -> np.ndarray:
    """Gradient of :func:`total_energy` with respect to every ``phi_i``."""
    return (local_energy_grad(phi, model, torque, vor)
            + gradient_energy_grad(phi, model.stiffness, lengths))


def total_energy_hessian_bands(phi, model: PolymorphModel, vor, lengths):
    """The Hessian of :func:`total_energy` (tridiagonal, independent of the torque) as its
    main diagonal ``v_i W (3 phi_i^2 - 1) + K (1/l_{i-1} + 1/l_i)`` and its off-diagonal
    ``-K / l_j``: the state's block of an implicit integrator's Jacobian."""
    phi = np.asarray(phi, dtype=float)
    k = model.stiffness / (np.asarray(lengths, dtype=float) * np.ones(len(phi) - 1))
    main = np.asarray(vor, dtype=float) * model.barrier * (3.0 * phi * phi - 1.0) * np.ones_like(phi)
    main[:-1] += k
    main[1:] += k
    return main, -k


# --- the rest shape the state selects --------------------------------------------------
def interpolate_rest(rest_a, rest_b, phi):
    """Rest values (curvature vectors ``(n, 2)`` or twists ``(n,)``) at state ``phi``:
    ``a + (phi + 1)/2 (b - a)``, so ``phi = -1`` gives A and ``+1`` gives B. Written so that
    ``a == b`` (a one-state filament) returns ``a`` bit for bit for every ``phi``
    (``b - a = 0`` exactly)."""
    a = np.asarray(rest_a, dtype=float)
    b = np.asarray(rest_b, dtype=float)
    t = 0.5 * (np.asarray(phi, dtype=float) + 1.0)
    if a.ndim == 2:
        t = t[:, None]
    return a + t * (b - a)


def rest_derivative(rest_a, rest_b):
    """``d(rest)/dphi = (b - a) / 2`` of :func:`interpolate_rest`."""
    return 0.5 * (np.asarray(rest_b, dtype=float) - np.asarray(rest_a, dtype=float))


def elastic_phi_gradient(kappa, twist, kbar_a, kbar_b, mbar_a, mbar_b, phi, cbend, ctwist):
    """``dE_el/dphi_i`` of the rod's vertex energy
    ``cbend_i/2 |kappa_i - kbar_i(phi_i)|^2 + ctwist_i/2 (m_i - mbar_i(phi_i))^2``
    (docs/model.md, Elasticity, with ``cbend = A/l_i``, ``ctwist = C/l_i``) at fixed shape:
    ``-cbend_i (kappa_i - kbar_i).dkbar/dphi - ctwist_i (m_i - mbar_i) dmbar/dphi``.
    With the twist moment ``N = ctwist (m - mbar)`` held fixed, its twist part is
    ``-N (mbar_b - mbar_a)/2``: the tilt (P2) per vertex, how the load enters once wired."""
    kbar = interpolate_rest(kbar_a, kbar_b, phi)
    mbar = interpolate_rest(mbar_a, mbar_b, phi)
    dk = rest_derivative(kbar_a, kbar_b)
    dm = rest_derivative(mbar_a, mbar_b)
    bend = -np.asarray(cbend, dtype=float) * np.sum((np.asarray(kappa, dtype=float) - kbar) * dk, axis=-1)
    tw = -np.asarray(ctwist, dtype=float) * (np.asarray(twist, dtype=float) - mbar) * dm
    return bend + tw


def wall_profile(s, s0: float, width: float):
    """The static wall (P4): ``tanh((s - s0)/w)``."""
    return np.tanh((np.asarray(s, dtype=float) - s0) / width)


def helix_curvature_torsion(radius: float, pitch: float, handedness: str) -> tuple[float, float]:
    """Curvature ``kappa = R/(R^2 + p^2)`` and torsion ``tau = +-p/(R^2 + p^2)`` of a helix
    of radius ``R`` and pitch ``P`` (``p = P / 2 pi``; torsion > 0 right-handed, < 0 left),
    the rest values a polymorph's geometry gives a uniform rod."""
    r = check_positive("radius", radius)
    p = check_positive("pitch", pitch) / (2.0 * math.pi)
    if handedness not in ("left", "right"):
        raise UserInputError(f"handedness must be 'left' or 'right', got {handedness!r}")
    d = r * r + p * p
    return r / d, (p if handedness == "right" else -p) / d
