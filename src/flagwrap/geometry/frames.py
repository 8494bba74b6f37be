"""Frame algebra: parallel transport and signed angles (numba kernels, pure functions).

Parallel transport of a vector ``v`` from unit tangent ``t1`` to unit tangent ``t2`` is the
rotation about ``t1 x t2`` that takes ``t1`` to ``t2`` (Bergou et al., SIGGRAPH 2008, Sec. 4):

    P v = (t1.t2) v + (t1 x t2) x v + ((t1 x t2).v) (t1 x t2) / (1 + t1.t2),

valid for ``t1 . t2 > -1``.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np


@nb.njit(cache=True, inline="always")
def cross(a0, a1, a2, b0, b1, b2):
    return a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0


@nb.njit(cache=True, inline="always")
def transport3(a0, a1, a2, b0, b1, b2, v0, v1, v2):
    """:func:`transport` on scalars (tangents ``a``, ``b``, vector ``v``): returns a tuple and
    allocates nothing, for the kernels that transport every bond at every force call."""
    c = a0 * b0 + a1 * b1 + a2 * b2
    k0, k1, k2 = cross(a0, a1, a2, b0, b1, b2)
    kx0, kx1, kx2 = cross(k0, k1, k2, v0, v1, v2)
    kv = (k0 * v0 + k1 * v1 + k2 * v2) / (1.0 + c)
    return c * v0 + kx0 + kv * k0, c * v1 + kx1 + kv * k1, c * v2 + kx2 + kv * k2


@nb.njit(cache=True)
def transport(t1, t2, v):
    """Parallel transport of ``v`` (3,) from unit tangent ``t1`` to ``t2``."""
    out = np.empty(3)
    out[0], out[1], out[2] = transport3(t1[0], t1[1], t1[2], t2[0], t2[1], t2[2],
                                        v[0], v[1], v[2])
    return out


@nb.njit(cache=True, inline="always")
def signed_angle3(u0, u1, u2, v0, v1, v2, a0, a1, a2):
    """:func:`signed_angle` on scalars."""
    c0, c1, c2 = cross(u0, u1, u2, v0, v1, v2)
    return math.atan2(c0 * a0 + c1 * a1 + c2 * a2, u0 * v0 + u1 * v1 + u2 * v2)


@nb.njit(cache=True)
def signed_angle(u, v, axis):
    """Angle from ``u`` to ``v`` about ``axis`` in (-pi, pi] (vectors perpendicular to ``axis``)."""
    return signed_angle3(u[0], u[1], u[2], v[0], v[1], v[2], axis[0], axis[1], axis[2])


def perpendicular(t: np.ndarray) -> np.ndarray:
    """Some unit vector perpendicular to unit vector ``t``."""
    e = np.array([1.0, 0.0, 0.0]) if abs(t[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    u = e - np.dot(e, t) * t
    return u / np.linalg.norm(u)


def space_parallel_frames(x: np.ndarray):
    """Reference directors by parallel transport along the rod (zero reference twist).

    Returns ``tangents`` (N-1, 3) and ``d1`` (N-1, 3), orthonormal pairs.
    """
    e = np.diff(x, axis=0)
    t = e / np.linalg.norm(e, axis=1)[:, None]
    d1 = np.empty_like(t)
    d1[0] = perpendicular(t[0])
    for j in range(1, len(t)):
        u = transport(t[j - 1], t[j], d1[j - 1])
        u -= np.dot(u, t[j]) * t[j]
        d1[j] = u / np.linalg.norm(u)
    return t, d1


def rotation_matrix(axis: np.ndarray, angle: float) -> np.ndarray:
    """Rotation matrix by ``angle`` about unit ``axis`` (right-hand rule), Rodrigues' formula."""
    axis = np.asarray(axis, float)
    axis = axis / np.linalg.norm(axis)
    K = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + math.sin(angle) * K + (1 - math.cos(angle)) * (K @ K)


def quaternion_matrix(q) -> np.ndarray:
    """Rotation matrix of the quaternion ``q = (w, x, y, z)`` (normalised here); ``q`` of shape
    (..., 4) gives (..., 3, 3) (a free body's orientation, one or every frame)."""
    q = np.asarray(q, float)
    if q.ndim == 1:  # one pose (a swimmer's every velocity): floats, without stacking
        return np.array(_quaternion_rows(*(q / math.sqrt(q @ q)).tolist()))
    rows = _quaternion_rows(*np.moveaxis(q / np.linalg.norm(q, axis=-1, keepdims=True), -1, 0))
    return np.stack([np.stack(row, -1) for row in rows], -2)


def _quaternion_rows(w, x, y, z):
    """The rotation matrix's rows for the unit quaternion ``(w, x, y, z)`` (scalars or arrays)."""
    return ((1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)),
            (2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)),
            (2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)))
