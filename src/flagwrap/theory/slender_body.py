"""Slender-body theory for a rigid filament: the 6 x 6 resistance matrix.

The theory is Johnson's: R. E. Johnson, "An improved slender-body theory for Stokes flow",
J. Fluid Mech. 99, 411 (1980). It is the Keller & Rubinow (J. Fluid Mech. 75, 705 (1976))
integral equation with Johnson's treatment of the ends, in the form of Goetz (2000) and
Tornberg & Shelley (J. Comput. Phys. 196, 8 (2004), Eqs. 2-4). A centreline ``x(s)``,
``0 <= s <= L``, with unit tangent ``t(s)`` and radius ``r(s)`` carries a line density
``f(s)`` of force exerted on the fluid: Stokeslets ``f / (8 pi mu)`` plus source doublets
``-r^2 (I - t t) f / (16 pi mu)``. No slip on the surface, to leading orders in the
slenderness, is the integral equation for the centreline velocity

    8 pi mu u(s) = Lambda[f](s) + K[f](s),                                           (1)
    Lambda[f](s) = [ L(s) (I + t t) + (I - 3 t t) ] f(s),  L(s) = ln(4 s (L - s) / r(s)^2),  (2)
    K[f](s) = int_0^L [ G(x(s) - x(s')) f(s') - (I + t t) f(s) / |s - s'| ] ds',        (3)

with ``G(R) = I / |R| + R R / |R|^3`` the Stokeslet (times 8 pi mu). ``Lambda`` is the
local term: the Stokeslets of a straight segment of length ``L`` seen from the surface at
distance ``r`` (``int ds'/sqrt(sigma^2 + r^2) -> L(s)``), plus the doublets that make the
surface velocity the same all around the cross-section. ``K`` is the finite-part
non-local term: the whole Stokeslet line minus its local straight-line part.

**Radius profile.** With Johnson's prolate-spheroidal ends, ``r(s) = 2 r0 sqrt(s (L - s)) / L``
(:func:`spheroidal_profile`), ``L(s) = 2 ln(L / r0)`` is a constant. Then Eq. (1) is regular
to the ends and, for a straight spheroid, exact to the order kept: a uniform ``f`` solves it.
Johnson's analysis puts the error at ``O(eps^2 ln eps)``, ``eps = r0 / L``, for such tapered
ends; the exact spheroid drags bear it out (:func:`prolate_spheroid_drag`, the tests).
:func:`blunt_profile` ``r = r0 sqrt(1 - |2 s/L - 1|^p)`` is the spheroid at ``p = 2`` and
blunter for larger even ``p``. ``L(s)`` then stays finite: it drops by ``ln(p/2)`` from the
middle to the tips, over the last ``~L/p`` of each end. A uniform radius right up to blunt
ends (``p -> inf``) is not usable. ``L(s) -> -inf`` at the tips, and the discrete Eq. (1) has
no convergent solution: the force density oscillates and turns negative near the ends, at
every resolution tried (16-192 nodes, ``L / r0`` = 100 and 400).

**Rotlets.** A filament spinning about its own tangent feels a torque per length
``4 pi mu r^2 (Omega . t) t`` (Johnson 1980; Keller & Rubinow 1976). With ``rotlet=True``
this local torque is added to the resistance matrix. It is ``O(eps^2)`` relative to the
rest, and a bead chain of point forces has none.

**Numerics (Nystrom).** The unknown ``f`` is sampled at ``n`` Gauss-Legendre nodes on
``[0, L]`` and interpolated between them by the Lagrange polynomial (barycentric form;
Berrut & Trefethen, SIAM Rev. 46, 501 (2004)). Eq. (3) at node ``s_i`` is split at ``s_i``:
on each side the integrand is smooth (it is bounded, but jumps at ``s' = s_i``), so
``m``-point Gauss-Legendre rules on ``[0, s_i]`` and ``[s_i, L]`` converge spectrally. A
rigid motion ``u(s) = U + Omega x (x(s) - x0)`` for the six unit motions gives six ``f``;
then ``F = int f ds`` and ``T = int (x - x0) x f ds`` are the columns of ``R``, with
``[F; T] = R [U; Omega]`` as in :func:`flagwrap.body.multiblob.resistance_matrix`.

High Legendre modes make Eq. (1) ill-posed (Goetz 2000). On a straight line the non-local
operator's eigenvalue for mode ``k`` is ``-2 H_k (I + t t)``, ``H_k = sum_{j<=k} 1/j``. Along
the tangent it overtakes the local ``2 L - 2`` near ``k ~ 0.3 L / r0``. Keep
``n`` well below that. At the L / r0 of a few hundred used here, ``n`` = 24-96 converge to
1e-5 or better, well inside that bound.

**Bead chains.** A chain of RPY beads of radius ``a`` at spacing ``b`` (the filament of this
code) sums Stokeslets where Eq. (3) integrates them. Matching the sums to Eq. (2) along an
infinite straight chain gives one effective radius for motion along the chain and another
across it (:func:`chain_effective_radii`). A single-radius slender body comes close to both
only for ``b`` near ``2 a`` (touching beads). ``normal_radius_profile`` in
:func:`johnson_resistance` lets the normal part of ``Lambda`` use the second radius (a
two-radius local operator). With it equal to ``radius_profile`` (the default) it is
Johnson's.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

__all__ = [
    "Centreline",
    "bead_chain_centreline",
    "bead_helix",
    "blunt_profile",
    "chain_effective_radii",
    "compare_helix",
    "fit_chain_radii",
    "helix_centreline",
    "helix_pitch",
    "johnson_operator",
    "johnson_resistance",
    "normalised_deviation",
    "points_centreline",
    "prolate_spheroid_drag",
    "propulsion_coefficients",
    "spheroidal_profile",
    "straight_centreline",
    "straight_chain",
]


# centrelines -------------------------------------------------------------------------------
@dataclass(frozen=True)
class Centreline:
    """A centreline ``x(s)`` (positions, shape (m, 3)) and its unit tangent ``t(s)``,
    arc length ``s`` in ``[0, length]``."""

    length: float
    position: Callable[[np.ndarray], np.ndarray]
    tangent: Callable[[np.ndarray], np.ndarray]


def helix_centreline(length: float, helix_radius: float, pitch: float,
                     handedness: str = "left", phase: float = 0.0) -> Centreline:
    """A helix of contour ``length`` about the z axis, centred on the origin:
    ``x = (R cos phi, h R sin phi, p phi)``, ``phi = phase + k (s - L/2)``, ``p = P / (2 pi)``,
    ``k = 1 / sqrt(R^2 + p^2)``; ``h = +1`` right-handed, ``-1`` left-handed."""
    R, p = float(helix_radius), float(pitch) / (2 * math.pi)
    h = {"right": 1.0, "left": -1.0}[handedness]
    k = 1.0 / math.hypot(R, p)
    L = float(length)

    def position(s):
        phi = phase + k * (np.asarray(s, float) - 0.5 * L)
        return np.stack([R * np.cos(phi), h * R * np.sin(phi), p * (phi - phase)], axis=-1)

    def tangent(s):
        phi = phase + k * (np.asarray(s, float) - 0.5 * L)
        return k * np.stack([-R * np.sin(phi), h * R * np.cos(phi), p + 0 * phi], axis=-1)

    return Centreline(L, position, tangent)


def straight_centreline(length: float, direction=(0.0, 0.0, 1.0)) -> Centreline:
    """A straight segment of ``length`` along ``direction``, centred on the origin."""
    d = np.asarray(direction, float)
    d = d / np.linalg.norm(d)
    L = float(length)
    return Centreline(L, lambda s: (np.asarray(s, float)[..., None] - 0.5 * L) * d,
                      lambda s: np.broadcast_to(d, np.shape(s) + (3,)).copy())


def points_centreline(points: np.ndarray) -> Centreline:
    """A centreline through ``points`` (m, 3): a cubic spline in the chord-length parameter,
    reparametrised by its arc length (Gauss-Legendre sums per interval)."""
    from scipy.interpolate import CubicSpline

    pts = np.asarray(points, float)
    u = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(pts, axis=0), axis=1))])
    spl = CubicSpline(u, pts, axis=0)
    dspl = spl.derivative()
    g, w = np.polynomial.legendre.leggauss(8)
    lo, hi = u[:-1, None], u[1:, None]
    q = 0.5 * (hi - lo) * g + 0.5 * (hi + lo)
    seg = (0.5 * (hi - lo) * w * np.linalg.norm(dspl(q), axis=-1)).sum(axis=1)
    sk = np.concatenate([[0.0], np.cumsum(seg)])

    def u_of_s(s):
        s = np.asarray(s, float)
        uu = np.interp(s, sk, u)
        for _ in range(4):  # Newton on the arc length of the spline
            j = np.clip(np.searchsorted(u, uu) - 1, 0, len(u) - 2)
            a = u[j]
            qq = 0.5 * (uu - a)[..., None] * g + 0.5 * (uu + a)[..., None]
            arc = sk[j] + (0.5 * (uu - a)[..., None] * w
                           * np.linalg.norm(dspl(qq), axis=-1)).sum(axis=-1)
            uu = uu - (arc - s) / np.linalg.norm(dspl(uu), axis=-1)
        return uu

    def tangent(s):
        d = dspl(u_of_s(s))
        return d / np.linalg.norm(d, axis=-1, keepdims=True)

    return Centreline(float(sk[-1]), lambda s: spl(u_of_s(s)), tangent)


# radius profiles ---------------------------------------------------------------------------
def blunt_profile(r0: float, length: float, p: int = 2) -> Callable[[np.ndarray], np.ndarray]:
    """``r(s) = r0 sqrt(1 - |2 s / L - 1|^p)`` (radius ``r0`` at the middle, even ``p >= 2``).
    ``p = 2`` is Johnson's prolate spheroid. A larger ``p`` keeps the radius near ``r0``
    closer to the tips. ``L(s)`` of Eq. (2) is ``ln(L^2 / r0^2) - ln(sum_{j<p/2} xi^(2j))``,
    with ``xi = 2 s / L - 1``: smooth, and ``ln(p / 2)`` lower at the tips."""
    L, p = float(length), int(p)
    if p < 2 or p % 2:
        raise ValueError(f"blunt_profile: p must be an even integer >= 2, got {p}")
    return lambda s: r0 * np.sqrt(np.clip(1.0 - np.abs(2.0 * np.asarray(s) / L - 1.0) ** p,
                                          0.0, None))


def spheroidal_profile(r0: float, length: float) -> Callable[[np.ndarray], np.ndarray]:
    """Johnson's prolate-spheroidal profile ``r(s) = 2 r0 sqrt(s (L - s)) / L`` (radius ``r0``
    at the middle): ``L(s)`` of Eq. (2) is ``2 ln(L / r0)`` all along."""
    return blunt_profile(r0, length, 2)


def _local_log(s, L, profile):
    r = profile(s)
    return np.log(4.0 * s * (L - s) / r**2)


# the solver --------------------------------------------------------------------------------
def _bary_weights(x):
    """Barycentric weights of the Gauss-Legendre nodes ``x`` on [-1, 1] (ascending):
    ``(-1)^j sqrt((1 - x_j^2) w_j)`` (Wang & Xiang, Math. Comp. 81, 861 (2012))."""
    _, w = np.polynomial.legendre.leggauss(len(x))
    return (-1.0) ** np.arange(len(x)) * np.sqrt((1 - x**2) * w)


def _interp_matrix(xn, lam, xq):
    """Lagrange interpolation from nodes ``xn`` to points ``xq`` (any shape): ``(..., n)``."""
    d = xq[..., None] - xn
    hit = d == 0.0
    d = np.where(hit, 1.0, d)
    c = lam / d
    P = c / c.sum(axis=-1, keepdims=True)
    rows = hit.any(axis=-1)
    if rows.any():
        P[rows] = hit[rows].astype(float)
    return P


def johnson_operator(centreline: Centreline, radius_profile, n: int = 64, m: int | None = None,
                     normal_radius_profile=None):
    """The discrete Eq. (1): ``(A, s, w, x, t)`` with ``8 pi mu u_i = sum_j A_ij f_j``
    (``A`` (3n, 3n)), Gauss-Legendre nodes ``s`` and weights ``w`` on ``[0, L]``, and the
    positions ``x`` and tangents ``t`` there. ``m``: Gauss points per side of the split
    non-local integral (default ``max(n, 32)``)."""
    L = centreline.length
    m = max(n, 32) if m is None else int(m)
    xi, wi = np.polynomial.legendre.leggauss(n)
    s, w = 0.5 * L * (xi + 1), 0.5 * L * wi
    lam = _bary_weights(xi)
    x, t = centreline.position(s), centreline.tangent(s)
    tt = t[:, :, None] * t[:, None, :]
    eye = np.eye(3)
    # local term, Eq. (2)
    Ls = _local_log(s, L, radius_profile)
    if normal_radius_profile is None:
        loc = Ls[:, None, None] * (eye + tt) + (eye - 3 * tt)
    else:  # tangential part 2 L_par - 2, normal part L_perp + 1
        Ln = _local_log(s, L, normal_radius_profile)
        loc = (2 * Ls - 2)[:, None, None] * tt + (Ln + 1)[:, None, None] * (eye - tt)
    # non-local term, Eq. (3): Gauss rules on [0, s_i] and [s_i, L]
    g, gw = np.polynomial.legendre.leggauss(m)
    lo = np.stack([np.zeros(n), s], axis=1)[:, :, None]   # (n, 2, 1)
    hi = np.stack([s, np.full(n, L)], axis=1)[:, :, None]
    q = (0.5 * (hi - lo) * g + 0.5 * (hi + lo)).reshape(n, 2 * m)
    qw = (0.5 * (hi - lo) * gw).reshape(n, 2 * m)
    Rv = x[:, None, :] - centreline.position(q)             # (n, 2m, 3)
    r = np.linalg.norm(Rv, axis=-1)
    G = (eye / r[..., None, None] + Rv[..., :, None] * Rv[..., None, :] / r[..., None, None] ** 3)
    G *= qw[..., None, None]
    P = _interp_matrix(xi, lam, 2.0 * q / L - 1.0)          # (n, 2m, n)
    A = np.einsum("ikab,ikj->iajb", G, P)
    sub = (qw / np.abs(s[:, None] - q)).sum(axis=1)         # int ds'/|s - s'| by the same rule
    diag = loc - sub[:, None, None] * (eye + tt)
    idx = np.arange(n)
    A[idx, :, idx, :] += diag
    return A.reshape(3 * n, 3 * n), s, w, x, t


def _skew(v):
    z = np.zeros(v.shape[:-1])
    return np.stack([np.stack([z, -v[..., 2], v[..., 1]], -1),
                     np.stack([v[..., 2], z, -v[..., 0]], -1),
                     np.stack([-v[..., 1], v[..., 0], z], -1)], -2)


def johnson_resistance(centreline, radius_profile, n: int = 64, m: int | None = None,
                       origin=(0.0, 0.0, 0.0), viscosity: float = 1.0, rotlet: bool = False,
                       normal_radius_profile=None, return_density: bool = False):
    """The 6 x 6 resistance matrix ``[F; T] = R [U; Omega]`` (torques about ``origin``) of a
    rigid slender filament by Johnson's slender-body theory, Eqs. (1)-(3) of the module
    docstring.

    Parameters
    ----------
    centreline : Centreline or array (k, 3)
        the centreline; points are joined by :func:`points_centreline`.
    radius_profile : callable
        ``r(s)``, e.g. :func:`spheroidal_profile` or :func:`blunt_profile`.
    n, m : int
        Gauss-Legendre nodes of ``f`` and points per side of each split integral.
    rotlet : bool
        add the local spin torque ``4 pi mu r^2 (Omega . t) t`` per length.
    normal_radius_profile : callable or None
        a different radius in the normal part of the local term (see the module docstring);
        ``None``: Johnson's theory.
    return_density : bool
        also return ``(s, w, f)``, ``f`` of shape (6, n, 3): the force density of each unit
        motion.
    """
    if not isinstance(centreline, Centreline):
        centreline = points_centreline(centreline)
    A, s, w, x, t = johnson_operator(centreline, radius_profile, n, m, normal_radius_profile)
    rel = x - np.asarray(origin, float)
    # unit rigid motions: u = U + Omega x rel = [I, -[rel]_x] [U; Omega]
    Kg = np.concatenate([np.broadcast_to(np.eye(3), (len(s), 3, 3)), -_skew(rel)], axis=2)
    Kg = Kg.reshape(3 * len(s), 6)
    f = 8 * math.pi * viscosity * np.linalg.solve(A, Kg)     # (3n, 6)
    f = f.reshape(len(s), 3, 6)
    F = np.einsum("i,iak->ak", w, f)
    T = np.einsum("i,iak->ak", w, np.cross(rel[:, :, None], f, axis=1))
    R = np.concatenate([F, T], axis=0)
    if rotlet:
        r2 = radius_profile(s) ** 2
        R[3:, 3:] += 4 * math.pi * viscosity * np.einsum("i,i,ia,ib->ab", w, r2, t, t)
    if return_density:
        return R, (s, w, np.moveaxis(f, 2, 0))
    return R


# exact and reference results ---------------------------------------------------------------
def prolate_spheroid_drag(semi_major: float, semi_minor: float, viscosity: float = 1.0):
    """Exact resistances of a prolate spheroid (Oberbeck 1876; Perrin 1934; Chwang & Wu,
    J. Fluid Mech. 67, 787 (1975), Eqs. 2.13-2.16), eccentricity ``e = sqrt(1 - b^2/c^2)``,
    ``Le = ln((1 + e)/(1 - e))``:

    * along the axis:    ``F = 16 pi mu c e^3 / ((1 + e^2) Le - 2 e)``;
    * across it:         ``F = 32 pi mu c e^3 / ((3 e^2 - 1) Le + 2 e)``;
    * spin about it:     ``T = 32 pi mu c^3 e^3 (1 - e^2) / (3 (2 e - (1 - e^2) Le))``;
    * rotation across:   ``T = 32 pi mu c^3 e^3 (2 - e^2) / (3 ((1 + e^2) Le - 2 e))``.

    Returns the dict ``{"axial", "transverse", "spin", "rotation"}``."""
    c, b = float(semi_major), float(semi_minor)
    e = math.sqrt(1.0 - (b / c) ** 2)
    Le = math.log((1 + e) / (1 - e))
    mu = float(viscosity)
    return {
        "axial": 16 * math.pi * mu * c * e**3 / ((1 + e**2) * Le - 2 * e),
        "transverse": 32 * math.pi * mu * c * e**3 / ((3 * e**2 - 1) * Le + 2 * e),
        "spin": 32 * math.pi * mu * c**3 * e**3 * (1 - e**2) / (3 * (2 * e - (1 - e**2) * Le)),
        "rotation": 32 * math.pi * mu * c**3 * e**3 * (2 - e**2) / (3 * ((1 + e**2) * Le - 2 * e)),
    }


def chain_effective_radii(bead_radius: float, spacing: float) -> tuple[float, float]:
    """``(r_par, r_perp)``: the radii of the uniform slender body of Eq. (2) whose local term
    equals that of an infinite straight chain of RPY beads (radius ``a``, spacing ``b``,
    ``b >= 2 a``) with a uniform force per length, along and across the chain.

    The bead's self-mobility is ``1 / (6 pi mu a)``. Its neighbours at ``k b`` add
    ``(I + e e)/(k b) + (2 a^2 / 3)(I - 3 e e)/(k b)^3`` (times ``1/(8 pi mu)``). Their sums
    out to distances ``s`` and ``L - s`` are ``ln(s (L - s) / b^2) + 2 gamma`` and
    ``2 zeta(3)``. Setting the chain's velocity equal to Eq. (2)'s (``2 L(s) - 2`` along,
    ``L(s) + 1`` across) gives

        ln(r_par / b)  = ln 2 - 1/2 - b/(3 a)   - gamma + (2/3) zeta(3) (a/b)^2,
        ln(r_perp / b) = ln 2 + 1/2 - 2b/(3 a)  - gamma - (2/3) zeta(3) (a/b)^2.

    Their ratio is never 1: it is smallest, 1.07, near touching beads (``b ~ 2 a``), and 1.75
    at the simulator's ``b = 4.44 a``. The chain's end beads see
    ``H_k = sum_{j<=k} 1/j = ln(k + 1/2) + gamma + O(k^-2)`` neighbours on one side. So the
    chain of ``N`` beads is, to that order, a uniform-radius body of length ``N b``, with
    its nodes at the bead centres: blunt-ended, unlike Johnson's spheroid."""
    a, b = float(bead_radius), float(spacing)
    gam, z3 = 0.5772156649015329, 1.2020569031595942
    lp = math.log(2) - 0.5 - b / (3 * a) - gam + (2 / 3) * z3 * (a / b) ** 2
    ln = math.log(2) + 0.5 - 2 * b / (3 * a) - gam - (2 / 3) * z3 * (a / b) ** 2
    return b * math.exp(lp), b * math.exp(ln)


# the helix of the simulator -----------------------------------------------------------------
def helix_pitch(length: float, helix_radius: float, turns: float) -> float:
    """``P`` with ``L = n sqrt((2 pi R)^2 + P^2)``."""
    return math.sqrt((length / turns) ** 2 - (2 * math.pi * helix_radius) ** 2)


def _chord_step(R, p, b):
    """Helix angle step ``dphi`` with chord ``b``: ``2 R^2 (1 - cos dphi) + p^2 dphi^2 = b^2``."""
    x = b / math.hypot(R, p)
    for _ in range(60):
        g = 2 * R * R * (1 - math.cos(x)) + p * p * x * x - b * b
        step = g / (2 * R * R * math.sin(x) + 2 * p * p * x)
        x -= step
        if abs(step) < 1e-15 * x:
            break
    return x


def bead_helix(length: float, helix_radius: float, pitch: float, n_beads: int,
               handedness: str = "left"):
    """Bead centres of a helix as the simulator builds it (consecutive beads an exact chord
    ``b = L / (N - 1)`` apart, so the bonds add up to ``L``), about the z axis and centred on
    the origin like :func:`helix_centreline`. Returns ``(beads (N, 3), arc step ds)``: the
    beads lie on the continuous helix at arc length ``ds`` apart."""
    R, p = float(helix_radius), float(pitch) / (2 * math.pi)
    b = length / (n_beads - 1)
    dphi = _chord_step(R, p, b)
    ds = dphi * math.hypot(R, p)
    s = ds * (np.arange(n_beads) + 0.5)
    line = helix_centreline(n_beads * ds, R, pitch, handedness)
    return line.position(s), ds


def bead_chain_centreline(length: float, helix_radius: float, pitch: float, n_beads: int,
                          handedness: str = "left") -> Centreline:
    """The slender body of a bead chain: the continuous helix through the beads of
    :func:`bead_helix`, extended by half an arc step beyond the end beads (each bead
    stands for one step of the contour), contour ``N ds``. ``helix_radius = 0``: straight."""
    if helix_radius == 0:
        return straight_centreline(n_beads * length / (n_beads - 1))
    _, ds = bead_helix(length, helix_radius, pitch, n_beads, handedness)
    return helix_centreline(n_beads * ds, helix_radius, pitch, handedness)


def propulsion_coefficients(R: np.ndarray, axis: int = 2) -> tuple[float, float, float]:
    """Purcell's propulsion matrix along ``axis``: ``(A, B, D)`` with
    ``[F; T] = [[A, B], [B, D]] [U; Omega]`` (B: the mean of the two couplings)."""
    return (float(R[axis, axis]), float(0.5 * (R[axis, 3 + axis] + R[3 + axis, axis])),
            float(R[3 + axis, 3 + axis]))


# calibration on the straight bead chain and the helix comparison -----------------------------
def straight_chain(n_beads: int, spacing: float) -> np.ndarray:
    """Bead centres of a straight chain along z, centred on the origin, shape (N, 3)."""
    x = np.zeros((int(n_beads), 3))
    x[:, 2] = (np.arange(n_beads) - 0.5 * (n_beads - 1)) * spacing
    return x


def _chain_resistance(beads, bead_radius):
    from flagwrap.body.multiblob import resistance_matrix  # the bead model (RPY)

    return resistance_matrix(beads, bead_radius)


def fit_chain_radii(bead_radius: float, spacing: float, n_beads: int, p: int = 2,
                    n: int = 32):
    """Calibrate the slender body of a bead chain on the STRAIGHT chain (N beads, radius
    ``a``, spacing ``b``): the body is straight, of length ``N b``, with
    ``blunt_profile(r, N b, p)``. ``r_par`` makes its axial drag the chain's, ``r_perp`` its
    transverse drag. Returns ``(r_par, r_perp, R_chain, R_sbt)``; ``R_sbt`` is the
    two-radius body's matrix (its rotational entries are not fitted)."""
    from scipy.optimize import brentq

    Rc = _chain_resistance(straight_chain(n_beads, spacing), bead_radius)
    line = straight_centreline(n_beads * spacing)

    def radius(idx):
        def g(lr):
            return johnson_resistance(line, blunt_profile(math.exp(lr), line.length, p),
                                      n=n)[idx, idx] - Rc[idx, idx]
        lo, hi = math.log(0.05 * bead_radius), math.log(2.0 * bead_radius)
        while g(lo) > 0:
            lo -= 1.0
        while g(hi) < 0:
            hi += 0.5
        return math.exp(brentq(g, lo, hi, xtol=1e-13, rtol=1e-13))

    r_par, r_perp = radius(2), radius(0)
    Rs = johnson_resistance(line, blunt_profile(r_par, line.length, p), n=n,
                            normal_radius_profile=blunt_profile(r_perp, line.length, p))
    return r_par, r_perp, Rc, Rs


def compare_helix(length: float = 1.0, helix_radius: float = 0.075, turns: float = 2.0,
                  n_beads: int = 61, bead_radius: float | None = None, p: int = 2,
                  n: int = 48, handedness: str = "left") -> dict:
    """The bead helix's resistance matrix against the slender body calibrated on the straight
    chain of the same beads (:func:`fit_chain_radii`). Default: the Fig. 4(a) helix,
    ``R = 0.075 L``, 2 turns, 61 beads, ``a = 0.225 b`` (``examples/fig4a.toml``: a = 1.5 mm,
    b = 0.4 m / 60). ``"one"``: Johnson's body of the single radius ``r_par``; ``"two"``: the
    two-radius body (``r_par`` along, ``r_perp`` across the tangent)."""
    b = length / (n_beads - 1)
    a = 0.225 * b if bead_radius is None else float(bead_radius)
    P = helix_pitch(length, helix_radius, turns)
    r_par, r_perp, Rc, Rs = fit_chain_radii(a, b, n_beads, p)
    beads, _ = bead_helix(length, helix_radius, P, n_beads, handedness)
    line = bead_chain_centreline(length, helix_radius, P, n_beads, handedness)
    Rb = _chain_resistance(beads, a)
    one = johnson_resistance(line, blunt_profile(r_par, line.length, p), n=n)
    two = johnson_resistance(line, blunt_profile(r_par, line.length, p), n=n,
                             normal_radius_profile=blunt_profile(r_perp, line.length, p))
    return {"a": a, "b": b, "pitch": P, "r_par": r_par, "r_perp": r_perp,
            "straight_chain": Rc, "straight_sbt": Rs,
            "straight_rotation_error": Rs[3, 3] / Rc[3, 3] - 1,
            "beads": Rb, "one": one, "two": two, "curvature": helix_radius
            / (helix_radius**2 + (P / (2 * math.pi)) ** 2)}


def sphere_and_helix_swimmer(R_helix: np.ndarray, sphere_radius: float, centre,
                             axis=(0.0, 0.0, -1.0), omega: float = 1.0):
    """A force- and torque-free swimmer from resistance matrices (viscosity 1): a sphere of
    ``sphere_radius`` (exact drag ``6 pi r``, ``8 pi r^3``) at ``centre`` turning a rigid
    helix (``R_helix``, 6x6 about the origin) at ``omega`` about ``axis`` relative to itself;
    the sphere-helix hydrodynamic interaction is left out. The helix's matrix about the
    sphere's centre is ``P^T R P``, ``P = [[I, [c]x], [0, I]]``. Returns (speed along
    ``-axis``, body rotation about ``axis``, motor torque about ``axis``)."""
    c = np.asarray(centre, float)
    P = np.eye(6)
    P[:3, 3:] = _skew(c)
    Rh = P.T @ np.asarray(R_helix, float) @ P
    r = float(sphere_radius)
    Rs = np.diag([6 * math.pi * r] * 3 + [8 * math.pi * r**3] * 3)
    e = np.asarray(axis, float)
    drive = np.concatenate([np.zeros(3), omega * e])
    V = np.linalg.solve(Rs + Rh, -Rh @ drive)
    return float(-e @ V[:3]), float(e @ V[3:]), float(e @ (Rh @ (V + drive))[3:])


def normalised_deviation(R: np.ndarray, R_ref: np.ndarray) -> np.ndarray:
    """``|R - R_ref|_ij / sqrt(R_ref_ii R_ref_jj)``: each entry's error on the scale of the
    largest value it can take (Cauchy-Schwarz for a positive-definite matrix)."""
    d = np.sqrt(np.diag(R_ref))
    return np.abs(R - R_ref) / np.outer(d, d)


def _report():  # pragma: no cover - the tables of docs/bacterium.md
    import time

    t0 = time.perf_counter()
    print("Straight rod (prolate spheroid, semi-axes c = 1, r0): SBT / exact - 1")
    print("| c / r0 | axial | transverse | rotation across | spin (rotlet) |")
    print("|---:|---:|---:|---:|---:|")
    for ar in (50, 100):
        ex = prolate_spheroid_drag(1.0, 1.0 / ar)
        R = johnson_resistance(straight_centreline(2.0), spheroidal_profile(1.0 / ar, 2.0),
                               n=32, rotlet=True)
        print(f"| {ar} | {R[2, 2] / ex['axial'] - 1:+.1e} | {R[0, 0] / ex['transverse'] - 1:+.1e}"
              f" | {R[3, 3] / ex['rotation'] - 1:+.1e} | {R[5, 5] / ex['spin'] - 1:+.1e} |")
    print("\nConvergence (Fig. 4(a) bead helix body, two radii): max |R_n - R_96| / max |R_96|")
    c = compare_helix()
    line = bead_chain_centreline(1.0, 0.075, c["pitch"], 61)
    kw = {"normal_radius_profile": blunt_profile(c["r_perp"], line.length, 2)}
    ref = johnson_resistance(line, blunt_profile(c["r_par"], line.length, 2), n=96, **kw)
    for n in (12, 16, 24, 32, 48):
        R = johnson_resistance(line, blunt_profile(c["r_par"], line.length, 2), n=n, **kw)
        print(f"n = {n}: {np.abs(R - ref).max() / np.abs(ref).max():.1e}")
    print(f"asymmetry max |R - R^T| / max |R| = "
          f"{np.abs(ref - ref.T).max() / np.abs(ref).max():.1e}")
    for aob in (0.225, 0.5):
        c = compare_helix(bead_radius=aob / 60)
        rp, rn = chain_effective_radii(c["a"], c["b"])
        print(f"\na/b = {aob}: r_par/a = {c['r_par'] / c['a']:.4f}, r_perp/a = "
              f"{c['r_perp'] / c['a']:.4f} (spheroid); infinite chain, uniform body: "
              f"{rp / c['a']:.4f}, {rn / c['a']:.4f}; straight chain's rotation across, "
              f"two-radius SBT / beads - 1 = {c['straight_rotation_error']:+.4f}")
        A, B, D = propulsion_coefficients(c["beads"])
        print("| | beads | SBT, one radius | rel. | SBT, two radii | rel. |")
        print("|---|---:|---:|---:|---:|---:|")
        for name, k in (("A", 0), ("B", 1), ("D", 2)):
            v1 = propulsion_coefficients(c["one"])[k]
            v2 = propulsion_coefficients(c["two"])[k]
            v0 = (A, B, D)[k]
            print(f"| {name} | {v0:.5g} | {v1:.5g} | {v1 / v0 - 1:+.4f} | {v2:.5g} | "
                  f"{v2 / v0 - 1:+.4f} |")
        for lab, sl_ in (("F-U", np.s_[:3, :3]), ("F-Omega", np.s_[:3, 3:]),
                         ("T-Omega", np.s_[3:, 3:])):
            d1 = normalised_deviation(c["one"], c["beads"])[sl_].max()
            d2 = normalised_deviation(c["two"], c["beads"])[sl_].max()
            print(f"| max dev. {lab} | | | {d1:.4f} | | {d2:.4f} |")
    print("\nTwo radii, a/b = 0.225, finer chains (same L, R, turns): rel. A, B, D; "
          "straight rotation")
    for N in (31, 61, 121, 241):
        c = compare_helix(n_beads=N, bead_radius=0.225 / (N - 1))
        A, B, D = propulsion_coefficients(c["beads"])
        e = [propulsion_coefficients(c["two"])[k] / v - 1 for k, v in enumerate((A, B, D))]
        print(f"| {N} | {c['curvature'] * c['b']:.3f} | {e[0]:+.4f} | {e[1]:+.4f} | "
              f"{e[2]:+.4f} | {c['straight_rotation_error']:+.4f} |")
    print("\nBlunter SBT ends, a/b = 0.225, N = 61: p, r_par/a, r_perp/a, rel. A, B, D, "
          "straight rotation")
    for p in (2, 4, 8, 12):
        c = compare_helix(p=p)
        A, B, D = propulsion_coefficients(c["beads"])
        e = [propulsion_coefficients(c["two"])[k] / v - 1 for k, v in enumerate((A, B, D))]
        print(f"| {p} | {c['r_par'] / c['a']:.3f} | {c['r_perp'] / c['a']:.3f} | {e[0]:+.4f} | "
              f"{e[1]:+.4f} | {e[2]:+.4f} | {c['straight_rotation_error']:+.4f} |")
    c = compare_helix()
    line = bead_chain_centreline(1.0, 0.075, c["pitch"], 61)
    Rr = johnson_resistance(line, spheroidal_profile(0.225 / 60, line.length), rotlet=True)
    R0 = johnson_resistance(line, spheroidal_profile(0.225 / 60, line.length))
    print(f"\nrotlet at r0 = a: D changes by {Rr[5, 5] / R0[5, 5] - 1:+.1e}")
    print(f"({time.perf_counter() - t0:.1f} s)")


if __name__ == "__main__":  # pragma: no cover
    _report()
