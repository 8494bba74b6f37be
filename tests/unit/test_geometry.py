"""Initial helix and frame algebra."""

import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from flagwrap.geometry.frames import rotation_matrix, signed_angle, space_parallel_frames, transport
from flagwrap.geometry.helix import helix_positions, ramp_helix_positions


def discrete_torsion_sign(x):
    e = np.diff(x, axis=0)
    return np.sign(np.einsum("ij,ij->i", np.cross(e[:-2], e[1:-1]), e[2:]))


def test_bond_lengths_exact_and_contour_is_L():
    for builder in (helix_positions, ramp_helix_positions):
        x = builder(0.4, 0.03, 0.0668, 61, "left")
        ln = np.linalg.norm(np.diff(x, axis=0), axis=1)
        np.testing.assert_allclose(ln, 0.4 / 60, rtol=1e-12)


def test_handedness_is_sign_of_torsion():
    # oracle: a right-handed helix has positive torsion, (e1 x e2).e3 > 0
    for builder in (helix_positions, ramp_helix_positions):
        left = discrete_torsion_sign(builder(0.4, 0.03, 0.0668, 61, "left")[5:])
        right = discrete_torsion_sign(builder(0.4, 0.03, 0.0668, 61, "right")[5:])
        assert np.all(left < 0) and np.all(right > 0)


def test_ramp_helix_hangs_below_clamp_on_axis():
    x = ramp_helix_positions(0.4, 0.03, 0.0668, 61, "left", 0.5)
    assert np.allclose(x[0], 0) and np.allclose(x[1, :2], 0) and x[1, 2] < 0
    assert np.all(np.diff(x[:, 2]) < 0)  # monotonically downward
    r = np.hypot(x[:, 0], x[:, 1])
    # beyond the half-turn lead the radius is R (the helix axis is the body axis)
    far = r[25:]
    np.testing.assert_allclose(far, 0.03, rtol=1e-12)


unit = st.tuples(st.floats(-1, 1), st.floats(-1, 1), st.floats(-1, 1)).filter(
    lambda v: np.linalg.norm(v) > 1e-3).map(lambda v: np.array(v) / np.linalg.norm(v))


@settings(max_examples=60, deadline=None)
@given(unit, unit, unit)
def test_transport_is_rotation_taking_t1_to_t2(t1, t2, v):
    if np.dot(t1, t2) < -0.99:
        return
    np.testing.assert_allclose(transport(t1, t2, t1), t2, atol=1e-12)
    pv = transport(t1, t2, v)
    assert abs(np.linalg.norm(pv) - 1.0) < 1e-12
    # inner products are preserved (orthogonality of a frame survives transport)
    np.testing.assert_allclose(np.dot(pv, t2), np.dot(v, t1), atol=1e-12)


@settings(max_examples=40, deadline=None)
@given(st.integers(5, 80), st.floats(0.05, 0.3), st.floats(0.05, 0.5))
def test_space_parallel_frames_orthonormal(n, R, P):
    x = helix_positions(1.0, R, P, n)
    t, d1 = space_parallel_frames(x)
    np.testing.assert_allclose(np.linalg.norm(d1, axis=1), 1, atol=1e-12)
    np.testing.assert_allclose(np.einsum("ij,ij->i", t, d1), 0, atol=1e-12)


def test_signed_angle_and_rotation_matrix():
    axis = np.array([0.0, 0.0, 1.0])
    u = np.array([1.0, 0.0, 0.0])
    for ang in (0.3, -2.0, 3.0):
        v = rotation_matrix(axis, ang) @ u
        assert math.isclose(signed_angle(u, v, axis), ang, abs_tol=1e-12)
