"""Stereo triangulation of a point from two cameras at right angles (SI, "3D tracking").

Geometry (SI Fig. S5): camera C1 at ``(D1, 0, 0)`` looks along ``-x``, camera C2 at
``(0, D2, 0)`` looks along ``-y``, both at the height ``z = 0`` of the origin. A point on
camera ``i``'s picture, ``p_i = (x_i, y_i)`` [pixels from the principal point], defines the
ray direction with polar angle ``phi_i = atan(r_i / a)`` from the optical axis
(``r_i = hypot(x_i, y_i)``, ``a`` the apparent focal length [pixels]; the SI prints
``atan(a / r_i)``, a misprint: ``phi -> 0`` must be the image centre) and azimuth
``theta_i = atan2(y_i, x_i)``::

    t1 = (-cos phi1, sin phi1 cos theta1, sin phi1 sin theta1)     (image x1 -> +y, y1 -> +z)
    t2 = (-sin phi2 cos theta2, -cos phi2, sin phi2 sin theta2)    (image x2 -> -x, y2 -> +z)

With a tank wall (SI, "Different refractive indices case") the ray leaves camera ``i`` in air
(``n0``), meets the outer wall face a distance ``l_i`` along the axis and continues in the
liquid (``n``; the acrylic, n = 1.49, is lumped with glycerin, n = 1.47) at the angle
``phi'_i`` with ``n0 sin phi_i = n sin phi'_i`` (Snell) and the same azimuth.

:func:`triangulate` intersects the two rays in the least-squares sense (midpoint of the
shortest segment), which equals the SI's closed form (:func:`triangulate_closed_form`) on
consistent data and stays defined where the closed form divides by ``tan theta = 0``.
The SI's closed form with refraction (SI Eq. tracking:L1L2:n) misprints ``tan phi_2`` for
``tan theta_2`` in ``L1`` and ``tan phi_1`` for ``tan theta_1`` in ``L2``; the corrected form is
implemented here and checked against the general solver in the tests.

Lengths in metres (any one length unit works), image coordinates and focal length in pixels.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import ArrayLike

from flagwrap.errors import UserInputError

__all__ = [
    "GLYCERIN_REFRACTIVE_INDEX",
    "StereoRig",
    "snell_angle",
    "project",
    "camera_rays",
    "triangulate",
    "triangulate_closed_form",
    "CalibrationResult",
    "calibrate",
]

#: refractive index of glycerin at 20 C (SI)
GLYCERIN_REFRACTIVE_INDEX = 1.47

# camera frames: (optical axis, image x direction, image y direction), world coordinates
_FRAMES = (
    (np.array([-1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0]), np.array([0.0, 0.0, 1.0])),
    (np.array([0.0, -1.0, 0.0]), np.array([-1.0, 0.0, 0.0]), np.array([0.0, 0.0, 1.0])),
)


@dataclass(frozen=True)
class StereoRig:
    """Two cameras at right angles, optionally looking through a flat tank wall.

    Attributes
    ----------
    distance_1, distance_2 : float
        ``D1``, ``D2``: distance of camera C1 (C2) from the origin along +x (+y) [length], > 0.
    focal_px : float
        apparent focal length ``a`` [pixels], > 0 (SI: 1680).
    wall_1, wall_2 : float or None
        ``l1``, ``l2``: distance from camera to the outer wall face along its axis
        [length], ``0 <= l_i < D_i``; ``None`` for a uniform medium (no refraction).
    n_medium : float
        refractive index behind the wall (default 1.47, glycerin), >= 1.
    n_air : float
        refractive index at the cameras (default 1.0), >= 1.
    """

    distance_1: float
    distance_2: float
    focal_px: float
    wall_1: float | None = None
    wall_2: float | None = None
    n_medium: float = GLYCERIN_REFRACTIVE_INDEX
    n_air: float = 1.0

    def __post_init__(self) -> None:
        for name in ("distance_1", "distance_2", "focal_px"):
            v = float(getattr(self, name))
            if not (math.isfinite(v) and v > 0):
                raise UserInputError(f"{name} must be a finite number > 0, got {v!r}")
        if (self.wall_1 is None) != (self.wall_2 is None):
            raise UserInputError("wall_1 and wall_2 must both be given (refraction) or both be None")
        for name, dist in (("wall_1", self.distance_1), ("wall_2", self.distance_2)):
            w = getattr(self, name)
            if w is not None and not (0.0 <= float(w) < dist):
                raise UserInputError(f"{name} must satisfy 0 <= {name} < distance = {dist!r}, got {w!r}")
        for name in ("n_medium", "n_air"):
            v = float(getattr(self, name))
            if not (math.isfinite(v) and v >= 1.0):
                raise UserInputError(f"{name} must be a finite number >= 1, got {v!r}")

    @property
    def refracting(self) -> bool:
        """Whether a wall (and hence refraction) is present."""
        return self.wall_1 is not None

    def camera(self, i: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, float]:
        """``(centre, axis, ex, ey, wall distance)`` of camera ``i`` in {0, 1} (world coordinates)."""
        axis, ex, ey = _FRAMES[i]
        centre = -axis * (self.distance_1 if i == 0 else self.distance_2)
        wall = (self.wall_1 if i == 0 else self.wall_2) if self.refracting else 0.0
        return centre, axis, ex, ey, float(wall)


def snell_angle(angle: ArrayLike, n_from: float, n_to: float) -> np.ndarray:
    """Refraction angle from Snell's law ``n_from sin(angle) = n_to sin(angle')`` [rad].

    Parameters
    ----------
    angle : array_like
        incidence angle from the interface normal [rad], ``|angle| < pi/2``.
    n_from, n_to : float
        refractive indices (>= 1).

    Raises
    ------
    UserInputError
        on total internal reflection (``|n_from sin(angle) / n_to| > 1``).
    """
    s = float(n_from) / float(n_to) * np.sin(np.asarray(angle, dtype=float))
    if np.any(np.abs(s) > 1.0):
        raise UserInputError("total internal reflection: n_from sin(angle) / n_to exceeds 1")
    return np.arcsin(s)


def _as_points(points: ArrayLike, width: int, name: str) -> np.ndarray:
    arr = np.asarray(points, dtype=float)
    if arr.ndim == 1:
        arr = arr[None, :]
    if arr.ndim != 2 or arr.shape[1] != width:
        raise UserInputError(f"{name} must have shape (N, {width}), got {np.shape(points)}")
    if not np.all(np.isfinite(arr)):
        raise UserInputError(f"{name} contains non-finite values")
    return arr


def project(rig: StereoRig, points: ArrayLike) -> np.ndarray:
    """Image coordinates of world points on both cameras (the forward model).

    Parameters
    ----------
    rig : StereoRig
    points : array_like, shape (N, 3)
        world positions [length]; they must lie in front of both cameras (beyond the walls).

    Returns
    -------
    ndarray, shape (N, 4)
        ``(x1, y1, x2, y2)`` [pixels].

    Notes
    -----
    With refraction the in-plane offset ``rho`` of a point at depth ``h`` along the axis
    satisfies ``rho = l tan(phi) + (h - l) tan(phi')``; with ``t = tan(phi)`` and
    ``k = n0/n``, ``tan(phi') = k t / sqrt(1 + (1 - k^2) t^2)``. The left side is concave
    and increasing in ``t``, so Newton's method from the paraxial guess
    ``t0 = rho / (l + (h - l) k)`` converges monotonically; iterated to 1e-15 relative.
    """
    pts = _as_points(points, 3, "points")
    out = np.empty((pts.shape[0], 4))
    k = rig.n_air / rig.n_medium
    for i in range(2):
        centre, axis, ex, ey, wall = rig.camera(i)
        rel = pts - centre
        h = rel @ axis
        if np.any(h <= wall):
            raise UserInputError(f"a point lies behind camera {i + 1} or its tank wall")
        u, v = rel @ ex, rel @ ey
        rho = np.hypot(u, v)
        if rig.refracting and k != 1.0:
            d = h - wall
            t = rho / (wall + d * k)
            for _ in range(100):
                root = np.sqrt(1.0 + (1.0 - k * k) * t * t)
                f = wall * t + d * k * t / root - rho
                df = wall + d * k / root**3
                dt = f / df
                t = t - dt
                if np.all(np.abs(dt) <= 1e-15 * np.maximum(np.abs(t), 1e-300)):
                    break
        else:
            t = rho / h
        scale = np.divide(rig.focal_px * t, rho, out=np.zeros_like(rho), where=rho > 0)
        out[:, 2 * i] = scale * u
        out[:, 2 * i + 1] = scale * v
    return out


def camera_rays(rig: StereoRig, image: ArrayLike) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Rays in the medium for each camera: ``(origin_1, dir_1, origin_2, dir_2)``, each (N, 3).

    The origin is the camera centre (uniform medium) or the point where the ray crosses the
    wall; directions are unit vectors after refraction (SI Eq. tracking:XYZ:1:n).
    """
    img = _as_points(image, 4, "image")
    res = []
    for i in range(2):
        centre, axis, ex, ey = rig.camera(i)[:4]
        wall = rig.camera(i)[4]
        x, y = img[:, 2 * i], img[:, 2 * i + 1]
        r = np.hypot(x, y)
        cos_t = np.divide(x, r, out=np.ones_like(r), where=r > 0)
        sin_t = np.divide(y, r, out=np.zeros_like(r), where=r > 0)
        phi = np.arctan2(r, rig.focal_px)
        m = cos_t[:, None] * ex + sin_t[:, None] * ey
        if rig.refracting:
            origin = centre + wall * (axis + np.tan(phi)[:, None] * m)
            phi_in = snell_angle(phi, rig.n_air, rig.n_medium)
        else:
            origin = np.broadcast_to(centre, (img.shape[0], 3)).copy()
            phi_in = phi
        direction = np.cos(phi_in)[:, None] * axis + np.sin(phi_in)[:, None] * m
        res += [origin, direction]
    return res[0], res[1], res[2], res[3]


def triangulate(rig: StereoRig, image: ArrayLike, *, return_gap: bool = False):
    """3D positions from a pair of image points (SI, "3D tracking using 2-way imaging").

    Least-squares intersection of the two (refracted) rays: the midpoint of their common
    perpendicular. Exact for consistent data.

    Parameters
    ----------
    rig : StereoRig
    image : array_like, shape (N, 4)
        ``(x1, y1, x2, y2)`` [pixels].
    return_gap : bool
        also return the distance between the two rays at closest approach [length], a
        consistency check of calibration and point matching.

    Returns
    -------
    ndarray, shape (N, 3)
        ``(X, Y, Z)`` [length]; and the gap, shape (N,), if requested.
    """
    o1, d1, o2, d2 = camera_rays(rig, image)
    w = o1 - o2
    b = np.einsum("ij,ij->i", d1, d2)
    dd = np.einsum("ij,ij->i", d1, w)
    e = np.einsum("ij,ij->i", d2, w)
    den = 1.0 - b * b
    if np.any(den < 1e-12):
        raise UserInputError("camera rays are parallel; the point cannot be triangulated")
    s = (b * e - dd) / den
    t = (e - b * dd) / den
    p1 = o1 + s[:, None] * d1
    p2 = o2 + t[:, None] * d2
    mid = 0.5 * (p1 + p2)
    if return_gap:
        return mid, np.linalg.norm(p1 - p2, axis=1)
    return mid


def triangulate_closed_form(rig: StereoRig, image: ArrayLike) -> np.ndarray:
    """The SI's closed-form solution (SI Eqs. tracking:Li and tracking:L1L2:n, corrected).

    ``L1 = [D1 tan th2 + l1 (tan ph1 sin th1 - tan th2)] / (cos ph1' tan th2 - sin ph1' sin th1)``
    and ``X = D1 - l1 - L1 cos ph1'``, ``(Y, Z) = (l1 tan ph1 + L1 sin ph1') (cos th1, sin th1)``
    (``l1 = 0``, ``ph' = ph`` without a wall). Uses the X and Z equations only; singular for
    ``theta_2 = 0`` (point at camera height). Returns shape (N, 3).
    """
    img = _as_points(image, 4, "image")
    x1, y1, x2, y2 = img.T
    ph1 = np.arctan2(np.hypot(x1, y1), rig.focal_px)
    ph2 = np.arctan2(np.hypot(x2, y2), rig.focal_px)
    th1 = np.arctan2(y1, x1)
    th2 = np.arctan2(y2, x2)
    l1 = float(rig.wall_1) if rig.refracting else 0.0
    p1 = snell_angle(ph1, rig.n_air, rig.n_medium) if rig.refracting else ph1
    tan_t2 = np.tan(th2)
    L1 = (rig.distance_1 * tan_t2 + l1 * (np.tan(ph1) * np.sin(th1) - tan_t2)) / (
        np.cos(p1) * tan_t2 - np.sin(p1) * np.sin(th1)
    )
    lateral = l1 * np.tan(ph1) + L1 * np.sin(p1)
    return np.column_stack([rig.distance_1 - l1 - L1 * np.cos(p1), lateral * np.cos(th1), lateral * np.sin(th1)])


@dataclass(frozen=True)
class CalibrationResult:
    """Fitted rig and the uncertainty of its fitted parameters.

    Attributes
    ----------
    rig : StereoRig
        rig with the fitted parameters.
    names : tuple of str
        fitted attribute names.
    values, errors : tuple of float
        fitted values and one-sigma errors (from the covariance ``s^2 (J^T J)^-1``).
    rms_px : float
        root-mean-square reprojection residual [pixels].
    """

    rig: StereoRig
    names: tuple[str, ...]
    values: tuple[float, ...]
    errors: tuple[float, ...]
    rms_px: float


def calibrate(
    rig: StereoRig,
    known_points: ArrayLike,
    image: ArrayLike,
    fit: tuple[str, ...] = ("distance_1", "distance_2", "focal_px"),
) -> CalibrationResult:
    """Fit rig parameters to points of known 3D position (SI Fig. S5 b: P0, P_Cyl1, P_Cyl2).

    Minimises the reprojection error of :func:`project` with ``scipy.optimize.least_squares``
    starting from ``rig``; the unfitted attributes are kept.

    Parameters
    ----------
    rig : StereoRig
        initial guess and fixed parameters.
    known_points : array_like, shape (N, 3)
        world positions [length].
    image : array_like, shape (N, 4)
        their measured image coordinates [pixels].
    fit : tuple of str
        attributes of :class:`StereoRig` to fit (at least 2 image coordinates per unknown).

    Returns
    -------
    CalibrationResult
    """
    from scipy.optimize import least_squares

    pts = _as_points(known_points, 3, "known_points")
    img = _as_points(image, 4, "image")
    if pts.shape[0] != img.shape[0]:
        raise UserInputError("known_points and image must have the same number of rows")
    allowed = {"distance_1", "distance_2", "focal_px", "wall_1", "wall_2", "n_medium"}
    bad = set(fit) - allowed
    if bad:
        raise UserInputError(f"cannot fit {sorted(bad)}; choose from {sorted(allowed)}")
    if img.size <= len(fit):
        raise UserInputError(f"need more than {len(fit)} image coordinates to fit {len(fit)} parameters")
    x0 = np.array([float(getattr(rig, n)) for n in fit])
    scale = np.abs(x0) + 1e-12

    def resid(xs: np.ndarray) -> np.ndarray:
        trial = replace(rig, **{n: float(v) for n, v in zip(fit, xs * scale)})
        return (project(trial, pts) - img).ravel()

    try:
        project(rig, pts)
    except UserInputError as exc:
        raise UserInputError(f"the starting rig does not see the known points: {exc} (give distances "
                             "near the true ones, in the known points' length unit)") from None
    try:
        sol = least_squares(resid, np.ones_like(x0), xtol=1e-15, ftol=1e-15, gtol=1e-15, x_scale="jac")
    except UserInputError as exc:  # a trial rig left the physical range (a point behind a camera)
        from flagwrap.errors import ResultError

        raise ResultError(f"the calibration of {', '.join(fit)} left the physical range ({exc}): "
                          "the known points do not fit this rig; check their coordinates and units") from None
    # a degenerate set of known points (one point, all on the optical axes, one repeated) leaves
    # some of the fitted parameters free: the Jacobian is rank-deficient, and the fit's values
    # and its zero errors would be arbitrary
    sv = np.linalg.svd(sol.jac, compute_uv=False)
    rank = int(np.sum(sv > 1e-9 * max(float(sv[0]) if sv.size else 0.0, 1e-300)))
    if rank < len(fit):
        raise UserInputError(
            f"the {pts.shape[0]} known point(s) determine only {rank} of the {len(fit)} fitted parameters "
            f"({', '.join(fit)}): give points at different positions, off the cameras' axes")
    dof = max(img.size - len(fit), 1)
    s2 = float(sol.fun @ sol.fun) / dof
    jac = sol.jac * scale[None, :] ** -1
    cov = np.linalg.pinv(jac.T @ jac) * s2
    values = sol.x * scale
    return CalibrationResult(
        rig=replace(rig, **{n: float(v) for n, v in zip(fit, values)}),
        names=tuple(fit),
        values=tuple(float(v) for v in values),
        errors=tuple(float(e) for e in np.sqrt(np.diag(cov))),
        rms_px=float(np.sqrt(np.mean(sol.fun**2))),
    )
