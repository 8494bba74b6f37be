"""A circular tube, straight or with a constriction, as a no-slip surface of blobs
(docs/confinement.md, "Tubes").

Geometry. The tube's axis is the line through ``center`` along the unit vector ``axis``; ``s``
is the signed distance along it from ``center``, the tube spans ``|s| <= length/2``. Its wall
radius is

    R(s) = R_t - (R_t - R_c) (1 + cos(2 pi (s - s_c) / L_c)) / 2   for |s - s_c| < L_c / 2,
    R(s) = R_t                                                      elsewhere,

a constriction of radius ``R_c`` and length ``L_c`` centred at ``s_c`` (a cosine bump: radius
and slope continuous), or a straight tube without one. Ends are open (a channel between two
reservoirs) or closed by flat discs (``closed=True``: a sealed test cell, whose far field is
the infinite tube's when the ends are far from what moves inside; the wall-drag checks use it).

Blobs. Rings of blobs about ``spacing`` apart along the wall's meridian and around each ring
(successive rings turned by half a step), placed ``BLOB_INSET`` blob radii outside the
surface (:meth:`Tube.blob_offset`, as the cell body's shell is inset by as much). The blobs
hold the wall still: their forces solve ``M_bb lambda = -u`` like a held body's
(:class:`flagwrap.body.fixed_mobility.FixedBodyMobility`). Unlike a body's shell, a tube has
fluid on both sides, and a shell of blobs is a porous wall: fluid that the inside pushes
leaks through the gaps. With blob radii of half the spacing (the body's rule) a sphere on a
closed tube's axis feels 2-16 % too little drag at a/R_t = 0.1-0.6 (spacing 0.1 R_t), and the
longer the tube, the less (more wall to leak through); with radii equal to the spacing
(``BLOB_RADIUS_RATIO``) the error is below 0.6 % (docs/confinement.md, "Tubes", the table).

Distance. ``gap(x)`` is a point's distance to the wall on the fluid's side (positive inside),
``(R(s) - r) / sqrt(1 + R'(s)^2)``: exact for the straight tube, first order in the slope's
change across the gap for the constriction.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from flagwrap.body.multiblob import BLOB_INSET
from flagwrap.errors import UserInputError

#: blob radius over blob spacing of a tube's shell: 1 (overlapping blobs) where a body's is 1/2,
#: since a thin shell with fluid on both sides leaks through its gaps (module docstring)
BLOB_RADIUS_RATIO = 1.0


@dataclass(frozen=True)
class Tube:
    """A tube in one unit of length (core or SI; the caller's). ``constriction_radius`` None:
    straight."""

    radius: float
    length: float
    center: tuple = (0.0, 0.0, 0.0)
    axis: tuple = (0.0, 0.0, 1.0)
    constriction_radius: float | None = None
    constriction_length: float = 0.0
    constriction_center: float = 0.0
    closed: bool = False

    def __post_init__(self):
        if not (math.isfinite(self.radius) and self.radius > 0):
            raise UserInputError(f"tube.radius must be > 0, got {self.radius!r}")
        if not (math.isfinite(self.length) and self.length > 0):
            raise UserInputError(f"tube.length must be > 0, got {self.length!r}")
        ax = np.asarray(self.axis, float)
        if ax.shape != (3,) or not np.all(np.isfinite(ax)) or np.linalg.norm(ax) == 0:
            raise UserInputError(f"tube.axis must be three finite numbers, not all zero, got "
                                 f"{self.axis!r}")
        c = np.asarray(self.center, float)
        if c.shape != (3,) or not np.all(np.isfinite(c)):
            raise UserInputError(f"tube.center must be three finite numbers, got {self.center!r}")
        object.__setattr__(self, "axis", tuple(float(v) for v in ax / np.linalg.norm(ax)))
        object.__setattr__(self, "center", tuple(float(v) for v in c))
        rc = self.constriction_radius
        if rc is not None:
            if not (math.isfinite(rc) and 0 < rc < self.radius):
                raise UserInputError(f"tube.constriction_radius must be in (0, tube.radius = "
                                     f"{self.radius:g}), got {rc!r}")
            lc, sc = self.constriction_length, self.constriction_center
            if not (math.isfinite(lc) and 0 < lc <= self.length):
                raise UserInputError(f"tube.constriction_length must be in (0, tube.length = "
                                     f"{self.length:g}], got {lc!r}")
            if not (math.isfinite(sc) and abs(sc) + lc / 2 <= self.length / 2 * (1 + 1e-12)):
                raise UserInputError(
                    f"tube.constriction_center must keep the constriction inside the tube: "
                    f"|center| + length/2 <= {self.length / 2:g}, got {sc!r} (length {lc:g})")

    # --- the surface --------------------------------------------------------------------
    def profile(self, s):
        """``(R, dR/ds, d^2R/ds^2)`` at ``s`` (module docstring), in one pass."""
        s = np.asarray(s, float)
        R = np.full(s.shape, float(self.radius))
        R1, R2 = np.zeros(s.shape), np.zeros(s.shape)
        if self.constriction_radius is not None:
            lc, depth = self.constriction_length, self.radius - self.constriction_radius
            u = (s - self.constriction_center) / lc
            inside = np.abs(u) < 0.5
            ph = 2 * np.pi * u[inside]
            R[inside] -= depth * 0.5 * (1 + np.cos(ph))
            R1[inside] = depth * np.pi / lc * np.sin(ph)
            R2[inside] = 2.0 * depth * (np.pi / lc) ** 2 * np.cos(ph)
        return R, R1, R2

    def wall_radius(self, s):
        """``R(s)`` (module docstring)."""
        return self.profile(s)[0]

    def wall_slope(self, s):
        """``dR/ds``."""
        return self.profile(s)[1]

    def gap_gradient(self, x):
        """``(gap, grad gap, r_hat, r)`` of points ``x`` (n, 3): the gradient of :meth:`gap`'s
        formula, exact (``+inf`` gaps have zero gradient; a point on the axis takes any radial
        direction)."""
        x = np.asarray(x, float)
        a = np.asarray(self.axis)
        d = x - np.asarray(self.center)
        s = d @ a
        rv = d - s[:, None] * a
        r = np.linalg.norm(rv, axis=1)
        rhat = np.where(r[:, None] > 1e-300, rv / np.maximum(r, 1e-300)[:, None], self.frame()[0])
        R, R1, R2 = self.profile(s)
        c = 1.0 / np.sqrt(1.0 + R1 * R1)
        g = (R - r) * c
        dg_ds = R1 * c - (R - r) * R1 * R2 * c ** 3
        grad = dg_ds[:, None] * a - c[:, None] * rhat
        out = np.abs(s) > 0.5 * self.length
        g = np.where(out, np.inf, g)
        grad[out] = 0.0
        return g, grad, rhat, r

    @property
    def about_z(self) -> bool:
        """The tube is coaxial with the z axis (the motor's): its wall, constriction and ends
        are then unchanged by a rotation about it."""
        a, c = self.axis, self.center
        scale = max(self.radius, abs(c[2]), 1e-300)
        return math.hypot(a[0], a[1]) < 1e-12 and math.hypot(c[0], c[1]) < 1e-12 * scale

    @property
    def narrowest(self) -> float:
        return self.radius if self.constriction_radius is None else self.constriction_radius

    def frame(self) -> np.ndarray:
        """``(e1, e2, axis)`` as rows: a right-handed frame with the tube's axis last."""
        a = np.asarray(self.axis)
        t = np.array([1.0, 0.0, 0.0]) if abs(a[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
        e1 = t - (t @ a) * a
        e1 /= np.linalg.norm(e1)
        return np.array([e1, np.cross(a, e1), a])

    def cylindrical(self, x):
        """``(s, r)`` of points ``x`` (..., 3): along the axis from ``center``, and from it."""
        d = np.asarray(x, float) - np.asarray(self.center)
        s = d @ np.asarray(self.axis)
        r = np.linalg.norm(d - s[..., None] * np.asarray(self.axis), axis=-1)
        return s, r

    def gap(self, x):
        """Distance of points ``x`` (..., 3) from the wall on the fluid's side (module
        docstring): positive inside the tube, negative across its wall. Past the open ends a
        point is outside the tube (``+inf``: nothing to meet)."""
        s, r = self.cylindrical(x)
        R, R1, _ = self.profile(s)
        g = (R - r) / np.sqrt(1.0 + R1 ** 2)
        return np.where(np.abs(s) <= 0.5 * self.length, g, np.inf)

    # --- blobs ---------------------------------------------------------------------------
    @staticmethod
    def blob_offset(blob_radius: float) -> float:
        """How far outside the surface the blob centres sit: ``BLOB_INSET`` blob radii."""
        return BLOB_INSET * blob_radius

    def surface_mesh(self, n_around: int = 48, n_along: int | None = None):
        """Its wall as triangles, for drawing (ParaView): vertices (m, 3) on ``R(s)`` at
        ``n_along`` stations (default: the spacing of ``n_around`` points round the narrowest
        ring, at most 400) and faces (k, 3); closed ends add a fan of triangles each."""
        if n_along is None:
            step = 2 * math.pi * self.narrowest / n_around
            n_along = int(min(400, max(8, math.ceil(self.length / step) + 1)))
        ss = np.linspace(-0.5 * self.length, 0.5 * self.length, n_along)
        R, _, _ = self.profile(ss)
        e1, e2, a = self.frame()
        ang = 2 * math.pi * np.arange(n_around) / n_around
        ring = np.cos(ang)[:, None] * e1 + np.sin(ang)[:, None] * e2  # (n_around, 3)
        v = (ss[:, None, None] * a + R[:, None, None] * ring[None]).reshape(-1, 3)
        i, j = np.meshgrid(np.arange(n_along - 1), np.arange(n_around), indexing="ij")
        p00 = i * n_around + j
        p01 = i * n_around + (j + 1) % n_around
        p10 = p00 + n_around
        p11 = p01 + n_around
        f = np.concatenate([np.stack([p00, p10, p11], -1).reshape(-1, 3),
                            np.stack([p00, p11, p01], -1).reshape(-1, 3)])
        if self.closed:
            faces, pts = [f], [v]
            for k, s_end in ((0, ss[0]), (n_along - 1, ss[-1])):
                c = len(np.concatenate(pts))
                pts.append((s_end * a)[None])
                jj = np.arange(n_around)
                faces.append(np.column_stack([np.full(n_around, c), k * n_around + jj,
                                              k * n_around + (jj + 1) % n_around]))
            v, f = np.concatenate(pts), np.concatenate(faces)
        return np.asarray(self.center) + v, f

    def estimated_blobs(self, spacing: float, blob_radius: float) -> int:
        """About how many blobs :meth:`blob_shell` puts at ``spacing``: the area of the
        surface the blob centres lie on (``int 2 pi r sqrt(1 + r'^2) ds``, ``r`` the wall
        offset outward, and the discs if closed) over ``spacing^2``, one blob per square of
        the ring lattice, and one ring more (within 6 % of the shell's count from 3 blobs per
        radius: each ring rounds its count to a whole blob); cheap where building the shell
        may not be (a spacing far too fine is refused from it before any blob exists)."""
        ss = np.linspace(-0.5 * self.length, 0.5 * self.length, 2001)
        R, R1, _ = self.profile(ss)
        R = R + self.blob_offset(blob_radius) * np.sqrt(1.0 + R1 ** 2)
        f = 2 * math.pi * R * np.sqrt(1.0 + R1 ** 2)
        area = float(np.sum(0.5 * (f[1:] + f[:-1]) * np.diff(ss)))
        if self.closed:
            area += math.pi * (R[0] ** 2 + R[-1] ** 2)
        # + one ring: the shell has a ring at each end (n_rings = arc / spacing + 1)
        return int(area / (spacing * spacing) + 2 * math.pi * R[-1] / spacing) + 1

    def blob_shell(self, spacing: float, blob_radius: float) -> np.ndarray:
        """Blob centres (n, 3) (module docstring): rings ``spacing`` apart along the meridian
        of the surface offset ``BLOB_INSET * blob_radius`` outward, ``spacing`` apart around;
        closed ends add flat discs of concentric rings."""
        if not (math.isfinite(spacing) and 0 < spacing < self.narrowest):
            raise UserInputError(f"tube blob spacing must be in (0, {self.narrowest:g}) (the "
                                 f"narrowest radius), got {spacing!r}")
        off = self.blob_offset(blob_radius)
        # the meridian r = R(s) + off, sampled finely, cut at equal arc length
        half = 0.5 * self.length
        ss = np.linspace(-half, half, max(2001, int(40 * self.length / spacing)))
        R, R1, _ = self.profile(ss)
        rr = R + off * np.sqrt(1.0 + R1 ** 2)
        arc = np.concatenate([[0.0], np.cumsum(np.hypot(np.diff(ss), np.diff(rr)))])
        n_rings = max(2, int(round(arc[-1] / spacing)) + 1)
        at = np.linspace(0.0, arc[-1], n_rings)
        s_r, r_r = np.interp(at, arc, ss), np.interp(at, arc, rr)
        rings = [(s, r, 0.5 * k) for k, (s, r) in enumerate(zip(s_r, r_r))]
        if self.closed:  # discs at both ends, inside the last ring
            for s_end, r_end in ((s_r[0], r_r[0]), (s_r[-1], r_r[-1])):
                s_disc = s_end - np.sign(s_end) * 0.0
                n_disc = int(round(r_end / spacing))
                for k in range(1, n_disc):
                    rings.append((s_disc, r_end * k / n_disc, 0.5 * k))
                rings.append((s_disc, 0.0, 0.0))
        e1, e2, a = self.frame()
        pts = []
        for s, r, phase in rings:
            m = 1 if r == 0.0 else max(3, int(round(2 * math.pi * r / spacing)))
            ang = 2 * math.pi * (np.arange(m) + phase) / m
            pts.append(s * a + r * (np.cos(ang)[:, None] * e1 + np.sin(ang)[:, None] * e2))
        return np.asarray(self.center) + np.concatenate(pts)


def rigid_body_drag(boundary_blobs, boundary_radii, body_blobs, body_radii, velocity,
                    solver: str = "auto") -> np.ndarray:
    """Force (3,) the fluid exerts on a rigid blob body translating at ``velocity`` (3,)
    without rotating, beside a still blob boundary (a tube), viscosity 1: the blob forces
    solve ``M lambda = u`` with ``u`` the body's velocity on its blobs and 0 on the
    boundary's (Balboa Usabiaga et al., J. Chem. Phys. 146, 134104 (2017)), and the drag is
    ``-sum lambda`` over the body's blobs. The check of the tube against Haberman & Sayre's
    factor (tests/unit/test_tube.py)."""
    from flagwrap.body.solver import make_blob_solver

    blobs = np.concatenate([np.asarray(body_blobs, float), np.asarray(boundary_blobs, float)])
    radii = np.concatenate([np.broadcast_to(body_radii, (len(body_blobs),)),
                            np.broadcast_to(boundary_radii, (len(boundary_blobs),))])
    u = np.zeros((len(blobs), 3))
    u[:len(body_blobs)] = np.asarray(velocity, float)
    lam = make_blob_solver(solver, blobs, radii, None).solve(u.ravel()).reshape(-1, 3)
    return -lam[:len(body_blobs)].sum(axis=0)
