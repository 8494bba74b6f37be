"""A no-slip plane wall: the Rotne-Prager-Blake mobility of spheres of any radii above it.

Swan & Brady, Phys. Fluids 19, 113306 (2007): the Faxen operators of both spheres applied to
Blake's solution for a point force above a no-slip plane (J. R. Blake, Proc. Camb. Phil.
Soc. 70, 303 (1971)). Its free-space part is the RPY tensor of
:mod:`flagwrap.hydrodynamics.polydisperse`; the wall's part ``W`` for radii ``a_i``,
``a_j`` is derived symbolically by studies/derive_rpb.py
(:mod:`flagwrap.hydrodynamics._wall_kernel`). For equal radii it is Swan & Brady's closed form
(tests/unit/test_wall.py), and its self term is ``mu_par = (1 - 9/16 a/h + 1/8 (a/h)^3 -
1/16 (a/h)^5)/(6 pi a)``, ``mu_perp = (1 - 9/8 a/h + 1/2 (a/h)^3 - 1/8 (a/h)^5)/(6 pi a)``.

**Spheres that reach the wall** (centre height ``z < a``; a tube-matched bead is wider than
the filament, which is what touches the wall). The blob regularisation of Balboa Usabiaga,
Delmotte & Donev, J. Chem. Phys. 146, 134104 (2017), as RigidMultiblobsWall implements it:
the whole mobility is ``B M(x~) B``, with every height raised to ``z~ = max(z, a)`` and
``B = diag(min(1, z/a))`` from the true heights, so that a sphere's mobility vanishes as its
centre reaches the plane, continuously, and the matrix stays positive definite. A centre at or
below the plane is outside the model; steric contact
(:class:`flagwrap.interactions.wall.WallContact`) keeps the filament off it.

Everything here is the *difference* from the free-space RPY mobility (which the other
backends compute), so that a wall is an addition to any of them: ``Delta_ij = b_i b_j
[RPY_ij(x~) + W_ij(x~)] - RPY_ij(x)``, whose RPY terms cancel for pairs away from the wall.
Viscosity 1 (the core's units).
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from flagwrap.hydrodynamics._wall_kernel import wall_block, wall_coefficients
from flagwrap.hydrodynamics.polydisperse import _pair

_C8 = 1.0 / (8.0 * math.pi)


class PlaneWall:
    """The plane through ``point`` with unit ``normal`` pointing into the fluid (core units).

    ``frame``: rows ``t1, t2, n``, an orthonormal basis with the normal last, so that
    ``(x - point) @ frame.T`` are coordinates in which the wall is ``z = 0``."""

    def __init__(self, point, normal):
        n = np.asarray(normal, float)
        norm = float(np.linalg.norm(n))
        if not (math.isfinite(norm) and norm > 0.0):
            raise ValueError(f"PlaneWall: normal must be a non-zero vector, got {normal!r}")
        n = n / norm
        t1 = np.cross(n, [1.0, 0.0, 0.0] if abs(n[0]) < 0.9 else [0.0, 1.0, 0.0])
        t1 /= np.linalg.norm(t1)
        self.point = np.asarray(point, float).copy()
        self.normal = n
        self.frame = np.ascontiguousarray(np.array([t1, np.cross(n, t1), n]))

    @property
    def square_to_z(self) -> bool:
        """The plane is ``z = const`` (normal along the body axis): it is symmetric about every
        axis along z, so a motor on the body axis sees it the same at every angle."""
        return bool(math.hypot(self.normal[0], self.normal[1]) < 1e-12)

    def heights(self, x) -> np.ndarray:
        """Signed distances of the points ``x`` (..., 3) from the plane (positive in the fluid)."""
        return (np.asarray(x, float) - self.point) @ self.normal

    def local(self, x) -> np.ndarray:
        """``x`` (n, 3) in the wall's frame (the wall is z = 0)."""
        return np.ascontiguousarray((np.asarray(x, float) - self.point) @ self.frame.T)

    def __repr__(self):
        return f"PlaneWall(point={self.point.tolist()}, normal={self.normal.tolist()})"


@nb.njit(cache=True, inline="always")
def _rpy_difference(xi, yi, zi, ai, xj, yj, zj, aj, out):
    """``out`` += ``b_i b_j RPY(x~) - RPY(x)`` (wall frame): the free part's change where a
    sphere reaches below its radius (zero otherwise)."""
    zti = max(zi, ai)
    ztj = max(zj, aj)
    bij = min(1.0, zi / ai) * min(1.0, zj / aj)
    for s in range(2):
        d0 = xi - xj
        d1 = yi - yj
        d2 = (zti - ztj) if s == 0 else (zi - zj)
        r = math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
        f, g = _pair(r, ai, aj)
        g = g / (r * r) if r > 0.0 else 0.0
        c = bij if s == 0 else -1.0
        out[0, 0] += c * (f + g * d0 * d0)
        out[0, 1] += c * g * d0 * d1
        out[0, 2] += c * g * d0 * d2
        out[1, 0] += c * g * d1 * d0
        out[1, 1] += c * (f + g * d1 * d1)
        out[1, 2] += c * g * d1 * d2
        out[2, 0] += c * g * d2 * d0
        out[2, 1] += c * g * d2 * d1
        out[2, 2] += c * (f + g * d2 * d2)


@nb.njit(cache=True, inline="always")
def _delta_block(xi, yi, zi, ai, xj, yj, zj, aj, out):
    """``out`` (3, 3), wall frame: ``Delta_ij`` of the module docstring for the target at
    ``(xi, yi, zi)`` of radius ``ai`` and the source at ``(xj, ...)`` of radius ``aj``."""
    zti = max(zi, ai)
    ztj = max(zj, aj)
    bij = min(1.0, zi / ai) * min(1.0, zj / aj)
    w = wall_block(xi - xj, yi - yj, zti + ztj, ztj, ai, aj)
    for k in range(9):
        out[k // 3, k % 3] = bij * _C8 * w[k]
    if zi < ai or zj < aj:
        _rpy_difference(xi, yi, zi, ai, xj, yj, zj, aj, out)


@nb.njit(cache=True)
def wall_cross_matrix(xt, at, xs, as_, Q, out):
    """``out`` (3n, 3m) += ``Delta`` between targets ``xt`` (n, 3; wall frame) of radii ``at``
    and sources ``xs`` (m, 3; wall frame) of radii ``as_``, rotated to the lab by ``Q``
    (:attr:`PlaneWall.frame`). The same set on both sides gives the square matrix, self
    blocks included."""
    B = np.empty((3, 3))
    T = np.empty((3, 3))
    for i in range(xt.shape[0]):
        for j in range(xs.shape[0]):
            _delta_block(xt[i, 0], xt[i, 1], xt[i, 2], at[i], xs[j, 0], xs[j, 1], xs[j, 2],
                         as_[j], B)
            # lab block Q^T B Q
            for p in range(3):
                for q in range(3):
                    s = 0.0
                    for k in range(3):
                        s += B[p, k] * Q[k, q]
                    T[p, q] = s
            for p in range(3):
                for q in range(3):
                    s = 0.0
                    for k in range(3):
                        s += Q[k, p] * T[k, q]
                    out[3 * i + p, 3 * j + q] += s


@nb.njit(cache=True)
def wall_cross_apply(xt, at, xs, as_, Fs, ut):
    """``ut`` (n, 3) += ``Delta Fs`` with everything in the wall frame (O(n m) time, no
    matrix). The image part straight from the coefficients (``8 pi W F = A F + B e (e.F) +
    C e F_z + D n (e.F) + E n F_z``), the regularised RPY difference only for pairs with a
    sphere below its radius."""
    n, m = xt.shape[0], xs.shape[0]
    zs = np.empty(m)  # the sources' raised heights and damping
    bs = np.empty(m)
    near_s = np.zeros(m, np.bool_)
    for j in range(m):
        zs[j] = max(xs[j, 2], as_[j])
        bs[j] = min(1.0, xs[j, 2] / as_[j])
        near_s[j] = xs[j, 2] < as_[j]
    any_near_s = near_s.any()
    for i in range(n):
        ai = at[i]
        zi = max(xt[i, 2], ai)
        bi = min(1.0, xt[i, 2] / ai)
        near_i = xt[i, 2] < ai
        u0 = 0.0
        u1 = 0.0
        u2 = 0.0
        for j in range(m):
            r1 = xt[i, 0] - xs[j, 0]
            r2 = xt[i, 1] - xs[j, 1]
            r3 = zi + zs[j]
            rho = math.sqrt(r1 * r1 + r2 * r2 + r3 * r3)
            ir = 1.0 / rho
            e0, e1, e2 = r1 * ir, r2 * ir, r3 * ir
            A, B, C, D, E = wall_coefficients(rho, e2, zs[j], ai, as_[j])
            c = bi * bs[j] * _C8
            f0, f1, f2 = c * Fs[j, 0], c * Fs[j, 1], c * Fs[j, 2]
            eF = e0 * f0 + e1 * f1 + e2 * f2
            s = B * eF + C * f2
            u0 += A * f0 + s * e0
            u1 += A * f1 + s * e1
            u2 += A * f2 + s * e2 + D * eF + E * f2
        if near_i or any_near_s:
            B3 = np.empty((3, 3))
            for j in range(m):
                if near_i or near_s[j]:
                    B3[:, :] = 0.0
                    _rpy_difference(xt[i, 0], xt[i, 1], xt[i, 2], ai, xs[j, 0], xs[j, 1],
                                    xs[j, 2], as_[j], B3)
                    for p in range(3):
                        v = B3[p, 0] * Fs[j, 0] + B3[p, 1] * Fs[j, 1] + B3[p, 2] * Fs[j, 2]
                        if p == 0:
                            u0 += v
                        elif p == 1:
                            u1 += v
                        else:
                            u2 += v
        ut[i, 0] += u0
        ut[i, 1] += u1
        ut[i, 2] += u2


def config_wall(config) -> PlaneWall | None:
    """The config's ``[[wall]]`` (one; :func:`flagwrap.system.parts.check_walls`) in core
    units, or None."""
    if not config.walls:
        return None
    w, L = config.walls[0], config.filament.length
    return PlaneWall(np.asarray(w.point, float) / L, w.unit_normal)


def _radii(r, n) -> np.ndarray:
    return np.ascontiguousarray(np.broadcast_to(np.asarray(r, float), (n,)))


def wall_correction_matrix(wall: PlaneWall, xt, at, xs=None, as_=None) -> np.ndarray:
    """``Delta`` (3n, 3m) between targets and sources (lab frame; sources default to the
    targets: the square, symmetric correction)."""
    xt = np.asarray(xt, float)
    xs = xt if xs is None else np.asarray(xs, float)
    at = _radii(at, len(xt))
    as_ = at if as_ is None else _radii(as_, len(xs))
    out = np.zeros((3 * len(xt), 3 * len(xs)))
    wall_cross_matrix(wall.local(xt), at, wall.local(xs), as_, wall.frame, out)
    return out


def wall_correction_apply(wall: PlaneWall, xt, at, xs, as_, Fs) -> np.ndarray:
    """``Delta Fs`` (n, 3) at the targets (lab frame), O(n m), no matrix."""
    xt = np.asarray(xt, float)
    xs = np.asarray(xs, float)
    ut = np.zeros((len(xt), 3))
    Fl = np.ascontiguousarray(np.asarray(Fs, float).reshape(-1, 3) @ wall.frame.T)
    wall_cross_apply(wall.local(xt), _radii(at, len(xt)), wall.local(xs), _radii(as_, len(xs)),
                     Fl, ut)
    return ut @ wall.frame


class WallMobility:
    """A bead mobility beside a plane wall: ``base`` (free-space RPY, any backend) plus the
    wall's ``Delta`` (module docstring). Beads of one radius ``base.radius``. Symmetric about
    the motor (body) axis, as the turning frame needs, when the wall is square to it
    (``axisymmetric``): its Delta is then covariant under rotations about z."""

    long_range = True

    def __init__(self, base, wall: PlaneWall):
        self.base = base
        self.wall = wall
        self.axisymmetric = wall.square_to_z and getattr(base, "axisymmetric", True)
        self.radius = base.radius
        self.self_mobility = base.self_mobility
        self.backend = f"{getattr(base, 'backend', 'direct')}+wall"

    def __getattr__(self, name):  # solver memory, lagged screening ... of the base
        if name == "base":
            raise AttributeError(name)
        return getattr(self.base, name)

    def _delta(self, x):
        return wall_correction_matrix(self.wall, x, self.radius)

    def matrix(self, x, out=None):
        M = self.base.matrix(x, out=out)
        M += self._delta(x)
        return M

    def stage_matrix(self, x, out=None):
        base = getattr(self.base, "stage_matrix", self.base.matrix)
        M = base(x, out=out)
        M += self._delta(x)
        return M

    def apply(self, x, F):
        a = np.full(len(x), self.radius)
        return self.base.apply(x, F) + wall_correction_apply(self.wall, x, a, x, a, F)

    def apply_single(self, x, F):
        a = np.full(len(x), self.radius)
        return self.base.apply_single(x, F) + wall_correction_apply(self.wall, x, a, x, a, F)

    def near_field_blocks(self, x, width: int):
        """The base's blocks with the wall's self blocks added (a preconditioner's: the
        wall's coupling between beads is left out)."""
        out = self.base.near_field_blocks(x, width)
        _add_self_blocks(self.wall.local(x), np.full(len(x), self.radius), self.wall.frame,
                         out, out.shape[1] // 2)
        return out


@nb.njit(cache=True)
def _add_self_blocks(xl, a, Q, out, w):
    """``out[i, w]`` += the lab-frame self block of ``Delta`` for every sphere ``i``."""
    B = np.empty((3, 3))
    for i in range(xl.shape[0]):
        _delta_block(xl[i, 0], xl[i, 1], xl[i, 2], a[i], xl[i, 0], xl[i, 1], xl[i, 2], a[i], B)
        for p in range(3):
            for q in range(3):
                s = 0.0
                for k in range(3):
                    for m in range(3):
                        s += Q[k, p] * B[k, m] * Q[m, q]
                out[i, w, p, q] += s
