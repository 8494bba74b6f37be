"""Rigid bodies with a no-slip surface: the rigid multiblob method.

The rigid multiblob method follows Usabiaga, Kallemov, Delmotte, Bhalla, Griffith & Donev,
"Hydrodynamics of suspensions of passive and active rigid particles: a rigid multiblob
approach", Commun. Appl. Math. Comput. Sci. 11, 217 (2016). Its body is a rigid cluster of
``n`` blobs (RPY spheres of radius ``a_b``) on its surface. The body moves rigidly with
velocity ``U`` and angular velocity ``Omega``, and blob ``i`` at ``r_i`` (relative to the
reference point ``q``) then moves at

    u_i = U + Omega x r_i        i.e.  u = K [U; Omega],   K = [I, -[r_i]_x] stacked (3n x 6).

The blob forces ``lambda`` that make the surface move so satisfy ``M lambda = K [U; Omega]``,
with ``M`` the blobs' RPY mobility (3n x 3n; :mod:`flagwrap.hydrodynamics.mobility`). The total
force and torque about ``q`` are ``K^T lambda``. So the body's resistance matrix is
``R = K^T M^-1 K`` (6 x 6, symmetric positive definite) and its mobility ``N = R^-1``. A
body's blob model has a hydrodynamic size a little larger than its blob surface: the blobs
stick out by ~a_b. :func:`effective_radii` states the two radii of a blob sphere, from its
translational and its rotational drag.

Shapes (positions relative to the reference point):
* :func:`sphere_blobs`: the vertices of a subdivided icosahedron (12, 42, 162, 642, 2562
  blobs);
* :func:`spheroid_blobs`: the same, stretched along z;
* :func:`capped_cylinder_blobs`: the paper's cell body, a cylinder closed below by a
  hemisphere and above by a flat disk, lowest point at the origin (as
  :class:`~flagwrap.body.cell_body.CappedCylinder`), blobs about ``spacing`` apart.

The blob radius sets how close the blobs must sit for the surface to hold fluid back. With
gaps of more than ``MAX_SPACING_RATIO`` blob radii the flow passes through them
(:func:`check_spacing`). Usabiaga et al. use blob radii of about half the spacing. Measured on
the 642-blob sphere (the widest gap over the blob radius -> R_r/R_t, which is 1 for a true
sphere): 1.6 -> 0.9967, 2.2 -> 0.9987, 2.8 -> 0.9997, 3.4 -> 1.0011, 4.5 -> 1.0041,
7.5 -> 1.0136. The two drags drift apart beyond ~3, and R_t falls below the geometric radius
beyond 4.5.
"""

from __future__ import annotations

import math

import numpy as np

from flagwrap.errors import UserInputError

#: largest gap between neighbouring blobs, in blob radii, that still makes a closed surface:
#: at 2 the blobs touch; beyond ~3 the sphere's translational and rotational radii drift apart
#: (module docstring)
MAX_SPACING_RATIO = 3.0


def icosphere(level: int) -> np.ndarray:
    """Unit vectors of an icosahedron subdivided ``level`` times (10 4^level + 2 points)."""
    if not 0 <= level <= 6:
        raise UserInputError(f"sphere refinement level must be in [0, 6], got {level}")
    p = (1.0 + math.sqrt(5.0)) / 2.0
    v = [(-1, p, 0), (1, p, 0), (-1, -p, 0), (1, -p, 0), (0, -1, p), (0, 1, p), (0, -1, -p),
         (0, 1, -p), (p, 0, -1), (p, 0, 1), (-p, 0, -1), (-p, 0, 1)]
    verts = [np.array(x, float) / np.linalg.norm(x) for x in v]
    faces = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4),
             (11, 10, 2), (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8),
             (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    for _ in range(level):
        cache = {}

        def mid(i, j):
            key = (min(i, j), max(i, j))
            if key not in cache:
                m = verts[i] + verts[j]
                verts.append(m / np.linalg.norm(m))
                cache[key] = len(verts) - 1
            return cache[key]

        new = []
        for a, b, c in faces:
            ab, bc, ca = mid(a, b), mid(b, c), mid(c, a)
            new += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        faces = new
    return np.array(verts)


def sphere_blobs(radius: float, level: int) -> np.ndarray:
    """Blob centres on a sphere of ``radius`` about the origin."""
    return radius * icosphere(level)


def spheroid_blobs(axial: float, equatorial: float, level: int) -> np.ndarray:
    """Blob centres on a spheroid with semi-axis ``axial`` along z and ``equatorial`` across
    (prolate for axial > equatorial), about the origin."""
    u = icosphere(level)
    return u * np.array([equatorial, equatorial, axial])


def capped_cylinder_blobs(radius: float, length: float, spacing: float) -> np.ndarray:
    """Blob centres on the paper's cell body: hemisphere of ``radius`` below (lowest point at
    the origin), cylinder of ``length`` above it, flat disk on top; blobs about ``spacing``
    apart (rings along z, points along each ring and on concentric rings of the disk)."""
    if not (radius > 0 and length >= 0 and 0 < spacing < radius):
        raise UserInputError(f"capped cylinder: need radius > 0, length >= 0 and 0 < spacing < "
                             f"radius, got {radius:g}, {length:g}, {spacing:g}")
    pts = [(0.0, 0.0, 0.0)]
    n_cap = max(1, int(round(0.5 * math.pi * radius / spacing)))
    for k in range(1, n_cap + 1):  # hemisphere rings: polar angle from the bottom
        th = 0.5 * math.pi * k / n_cap
        r, z = radius * math.sin(th), radius * (1 - math.cos(th))
        _ring(pts, r, z, spacing, phase=0.5 * k)
    n_cyl = max(1, int(round(length / spacing)))
    for k in range(1, n_cyl + 1):
        _ring(pts, radius, radius + length * k / n_cyl, spacing, phase=0.5 * (n_cap + k))
    top = radius + length
    n_disk = int(round(radius / spacing))
    for k in range(1, n_disk):  # concentric rings inside the rim (the rim is the last ring)
        _ring(pts, radius * k / n_disk, top, spacing, phase=0.5 * k)
    pts.append((0.0, 0.0, top))
    return np.array(pts)


def _ring(pts, r, z, spacing, phase=0.0):
    m = max(3, int(round(2 * math.pi * r / spacing)))
    for j in range(m):
        a = 2 * math.pi * (j + phase) / m
        pts.append((r * math.cos(a), r * math.sin(a), z))


def nearest_spacing(blobs: np.ndarray) -> float:
    """The largest nearest-neighbour distance among the blobs (the widest gap)."""
    from scipy.spatial import cKDTree

    d, _ = cKDTree(blobs).query(blobs, k=2)
    return float(d[:, 1].max())


def check_spacing(blobs: np.ndarray, blob_radius: float, what: str = "body.blob_radius") -> None:
    """Refuse a blob surface whose widest gap is more than ``MAX_SPACING_RATIO`` blob radii."""
    s = nearest_spacing(blobs)
    if s > MAX_SPACING_RATIO * blob_radius:
        raise UserInputError(
            f"{what} = {blob_radius:g} is too small for a blob spacing of {s:g}: neighbours "
            f"farther apart than {MAX_SPACING_RATIO:g} blob radii leave gaps the fluid flows "
            f"through; use a blob radius >= {s / MAX_SPACING_RATIO:g} or more blobs")


def geometric_matrix(blobs: np.ndarray) -> np.ndarray:
    """``K`` (3n x 6): blob velocities ``u = K [U; Omega]`` of a rigid motion about the
    origin of the ``blobs`` coordinates."""
    r = np.asarray(blobs, float)
    n = len(r)
    K = np.zeros((n, 3, 6))
    K[:, [0, 1, 2], [0, 1, 2]] = 1.0
    # Omega x r = -[r]_x Omega
    K[:, 0, 4], K[:, 0, 5] = r[:, 2], -r[:, 1]
    K[:, 1, 3], K[:, 1, 5] = -r[:, 2], r[:, 0]
    K[:, 2, 3], K[:, 2, 4] = r[:, 1], -r[:, 0]
    return K.reshape(3 * n, 6)


def blob_mobility(blobs: np.ndarray, blob_radius: float) -> np.ndarray:
    """The blobs' RPY mobility matrix ``mu_hat`` (3n x 3n; viscosity 1)."""
    from flagwrap.hydrodynamics.mobility import RPYMobility

    return RPYMobility(blob_radius).matrix(np.ascontiguousarray(blobs, float))


def resistance_matrix(blobs: np.ndarray, blob_radius: float, mobility=None) -> np.ndarray:
    """``R = K^T M^-1 K`` (6 x 6, viscosity 1): ``[F; T] = R [U; Omega]`` about the origin.
    ``mobility``: the blobs' 3n x 3n matrix, if already built (several bodies in one: the
    joint matrix of all their blobs)."""
    import scipy.linalg as sl

    M = blob_mobility(blobs, blob_radius) if mobility is None else mobility
    K = geometric_matrix(blobs)
    c = sl.cho_factor(M, check_finite=False)
    R = K.T @ sl.cho_solve(c, K, check_finite=False)
    return 0.5 * (R + R.T)


def effective_radii(blobs: np.ndarray, blob_radius: float) -> tuple[float, float]:
    """``(R_t, R_r)`` of a blob sphere about its centre: ``6 pi R_t`` = its translational drag
    and ``8 pi R_r^3`` = its rotational drag (viscosity 1), averaged over the three axes."""
    R = resistance_matrix(blobs, blob_radius)
    zt = np.trace(R[:3, :3]) / 3.0
    zr = np.trace(R[3:, 3:]) / 3.0
    return zt / (6 * math.pi), (zr / (8 * math.pi)) ** (1.0 / 3.0)


def stimson_jeffery(separation_over_radius: float, terms: int = 200000) -> float:
    """Drag factor ``lambda = F / (6 pi eta a U)`` on each of two equal spheres translating
    together along their line of centres (Stimson & Jeffery, Proc. R. Soc. A 111, 110
    (1926)), centre distance ``d = separation_over_radius * a``:

        lambda = (4/3) sinh(alpha) sum_n n(n+1)/((2n-1)(2n+3))
                 [1 - (4 sinh^2((n+1/2) alpha) - (2n+1)^2 sinh^2(alpha))
                      / (2 sinh((2n+1) alpha) + (2n+1) sinh(2 alpha))],
        cosh(alpha) = d / (2a).

    Far apart, ``lambda -> 1 - 3a/(2d) + ...``; in contact, 0.645."""
    x = float(separation_over_radius) / 2.0
    if not x > 1.0:
        raise ValueError(f"the spheres overlap or touch: d/a = {separation_over_radius}")
    al = math.acosh(x)
    s = 0.0
    for n in range(1, terms + 1):
        num = 4 * math.sinh((n + 0.5) * al) ** 2 - (2 * n + 1) ** 2 * math.sinh(al) ** 2
        den = 2 * math.sinh((2 * n + 1) * al) + (2 * n + 1) * math.sinh(2 * al)
        term = n * (n + 1) / ((2 * n - 1) * (2 * n + 3)) * (1 - num / den)
        s += term
        if abs(term) < 1e-16 * abs(s):
            break
    return 4.0 / 3.0 * math.sinh(al) * s


#: a blob surface is hydrodynamically larger than the shell its centres sit on by this many
#: blob radii: (R_t - R) / a_b of the icosphere shells, 0.385, 0.348, 0.327 at 162, 642, 2562
#: blobs (blob radius half the mean spacing); 0.32-0.34 for the rotational radius
BLOB_INSET = 0.33


def inset_capped_cylinder_blobs(radius: float, length: float, spacing: float,
                                blob_radius: float) -> np.ndarray:
    """:func:`capped_cylinder_blobs` on the shell ``BLOB_INSET * blob_radius`` inside the
    body's surface, so that the blob body's hydrodynamic surface is the body's (lowest point
    of the surface at the origin). On the geometric surface the body is too large by ~a_b/3
    and its motion converges at first order in the spacing; inset, faster
    (docs/bacterium.md)."""
    d = BLOB_INSET * blob_radius
    if not d < radius and d < length + radius:
        raise UserInputError(f"blob radius {blob_radius:g} too large for a body of radius {radius:g}")
    return capped_cylinder_blobs(radius - d, max(length - d, 0.0), spacing) + np.array([0.0, 0.0, d])


def spheroid_ring_blobs(equatorial: float, axial: float, spacing: float) -> np.ndarray:
    """Blob centres about ``spacing`` apart on the spheroid of semi-axes ``equatorial`` and
    ``axial``, centred at ``(0, 0, axial)`` (lowest point at the origin): rings at equal arc
    length along the meridian, one blob at each pole (unlike the stretched icosphere of
    :func:`spheroid_blobs`, whose blobs spread apart along a long axis)."""
    a, c = float(equatorial), float(axial)
    if not (a > 0 and c > 0 and 0 < spacing < min(a, c)):
        raise UserInputError(f"spheroid: need semi-axes > 0 and 0 < spacing < both, got {a:g}, "
                             f"{c:g}, {spacing:g}")
    th = np.linspace(0.0, math.pi, 4001)
    rho, z = a * np.sin(th), c * (1.0 - np.cos(th))
    arc = np.concatenate([[0.0], np.cumsum(np.hypot(np.diff(rho), np.diff(z)))])
    n = max(2, int(round(arc[-1] / spacing)))
    pts = [(0.0, 0.0, 0.0)]
    for k in range(1, n):
        t = np.interp(arc[-1] * k / n, arc, th)
        _ring(pts, a * math.sin(t), c * (1.0 - math.cos(t)), spacing, phase=0.5 * k)
    pts.append((0.0, 0.0, 2.0 * c))
    return np.array(pts)


def cell_body_blobs(config) -> tuple[np.ndarray, np.ndarray]:
    """The blobs of ``config``'s no-slip cell body in core units (lengths in ``L``): centres
    (n, 3) inset by ``BLOB_INSET`` blob radii under the surface of its shape
    (:meth:`flagwrap.body.shapes.BodyShape.blob_shell`; lowest point at the origin) and their
    radii (n,)."""
    from flagwrap.body.shapes import config_shape

    b, fil = config.body, config.filament
    R, L = fil.helix_radius, fil.length
    ab = b.resolved_blob_radius(R) / L
    blobs = config_shape(config).blob_shell(b.resolved_blob_spacing(R) / L, ab)
    return blobs, np.full(len(blobs), ab)
