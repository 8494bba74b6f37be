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


@nb.njit(cache=True)
def transport(t1, t2, v):
    """Parallel transport of ``v`` (3,) from unit tangent ``t1`` to ``t2``."""
    c = t1[0] * t2[0] + t1[1] * t2[1] + t1[2] * t2[2]
    b0, b1, b2 = cross(t1[0], t1[1], t1[2], t2[0], t2[1], t2[2])
    bxv0, bxv1, bxv2 = cross(b0, b1, b2, v[0], v[1], v[2])
    bv = (b0 * v[0] + b1 * v[1] + b2 * v[2]) / (1.0 + c)
    out = np.empty(3)
    out[0] = c * v[0] + bxv0 + bv * b0
    out[1] = c * v[1] + bxv1 + bv * b1
    out[2] = c * v[2] + bxv2 + bv * b2
    return out


@nb.njit(cache=True)
def signed_angle(u, v, axis):
    """Angle from ``u`` to ``v`` about ``axis`` in (-pi, pi] (vectors perpendicular to ``axis``)."""
    c0, c1, c2 = cross(u[0], u[1], u[2], v[0], v[1], v[2])
    s = c0 * axis[0] + c1 * axis[1] + c2 * axis[2]
    c = u[0] * v[0] + u[1] * v[1] + u[2] * v[2]
    return math.atan2(s, c)


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
