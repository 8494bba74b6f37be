"""RPY mobility: symmetry, positive definiteness, matrix-free = dense, known limits."""

import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from flagwrap.hydrodynamics.mobility import LocalMobility, RPYMobility


@settings(max_examples=50, deadline=None)
@given(st.integers(2, 25), st.integers(0, 100_000), st.floats(0.05, 2.0))
def test_rpy_symmetric_positive_definite_with_overlaps(n, seed, spread):
    rng = np.random.default_rng(seed)
    x = spread * rng.standard_normal((n, 3))  # many pairs overlap (r < 2a) when spread is small
    mob = RPYMobility(0.3)
    M = mob.matrix(x)
    np.testing.assert_allclose(M, M.T, atol=1e-15)
    assert np.linalg.eigvalsh(M).min() > 0


@settings(max_examples=30, deadline=None)
@given(st.integers(1, 40), st.integers(0, 100_000))
def test_matrix_free_equals_dense(n, seed):
    rng = np.random.default_rng(seed)
    x = rng.standard_normal((n, 3))
    F = rng.standard_normal((n, 3))
    mob = RPYMobility(0.2)
    v1 = mob.apply(x, F)
    v2 = (mob.matrix(x) @ F.ravel()).reshape(-1, 3)
    np.testing.assert_allclose(v1, v2, rtol=1e-10, atol=1e-12 * np.abs(v2).max())


def test_rpy_limits():
    a = 0.1
    mob = RPYMobility(a)
    # far field -> Oseen tensor 1/(8 pi r) (I + rr) (relative correction 2a^2/3r^2)
    r = 100.0
    M = mob.matrix(np.array([[0, 0, 0], [r, 0, 0.0]]))
    assert math.isclose(M[0, 3], 2 / (8 * math.pi * r), rel_tol=1e-5)
    assert math.isclose(M[1, 4], 1 / (8 * math.pi * r), rel_tol=1e-5)
    # coincident beads move as one sphere: mu_ij -> 1/(6 pi a)
    M0 = mob.matrix(np.array([[0, 0, 0], [0, 0, 0.0]]))
    assert math.isclose(M0[0, 3], 1 / (6 * math.pi * a), rel_tol=1e-12)
    # continuity at r = 2a
    Mi = mob.matrix(np.array([[0, 0, 0], [2 * a * (1 - 1e-12), 0, 0.0]]))
    Mo = mob.matrix(np.array([[0, 0, 0], [2 * a * (1 + 1e-12), 0, 0.0]]))
    np.testing.assert_allclose(Mi, Mo, rtol=1e-9)


def test_local_mobility_is_self_term_only():
    x = np.random.default_rng(0).standard_normal((5, 3))
    F = np.ones((5, 3))
    np.testing.assert_allclose(LocalMobility(0.5).apply(x, F), F / (6 * math.pi * 0.5))
