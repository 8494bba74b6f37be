"""The RPY mobility of unequal spheres (Zuk et al. 2014): its equal-size limit, positive
definiteness and continuity."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from flagwrap.hydrodynamics.mobility import RPYMobility
from flagwrap.hydrodynamics.polydisperse import PolydisperseRPY, _pair, rpy_cross_radii


def test_equal_radii_give_the_equal_size_rpy_tensor():
    rng = np.random.default_rng(0)
    x = rng.uniform(-1, 1, (40, 3))  # overlapping and separated pairs at a = 0.2
    a = 0.2
    A = RPYMobility(a).matrix(x)
    B = PolydisperseRPY(np.full(40, a)).matrix(x)
    np.testing.assert_allclose(B, A, rtol=0, atol=1e-14 * np.abs(A).max())
    F = rng.standard_normal((40, 3))
    np.testing.assert_allclose(PolydisperseRPY(np.full(40, a)).apply(x, F), (A @ F.ravel()).reshape(-1, 3),
                               atol=1e-13)


@pytest.mark.parametrize("ai, aj", [(1.0, 0.3), (0.3, 1.0), (0.5, 0.5), (2.0, 0.1)])
def test_pair_tensor_is_continuous_at_contact_and_at_engulfment(ai, aj):
    for r0 in (ai + aj, abs(ai - aj)):
        if r0 == 0.0:
            continue
        lo = _pair(r0 * (1 - 1e-9), ai, aj)
        hi = _pair(r0 * (1 + 1e-9), ai, aj)
        assert lo[0] == pytest.approx(hi[0], rel=1e-7, abs=1e-12)
        assert lo[1] == pytest.approx(hi[1], rel=1e-7, abs=1e-12)


def test_far_field_is_oseen_plus_the_faxen_terms():
    # r >> a: the Stokeslet (I + rr)/(8 pi r) plus (a_i^2 + a_j^2)/(24 pi r^3) (I - 3 rr)
    ai, aj, r = 0.3, 1.1, 50.0
    f, g = _pair(r, ai, aj)
    s = ai**2 + aj**2
    assert f == pytest.approx(1 / (8 * math.pi * r) + s / (24 * math.pi * r**3), rel=1e-14)
    assert g == pytest.approx(1 / (8 * math.pi * r) - 3 * s / (24 * math.pi * r**3), rel=1e-14)


@settings(max_examples=60, deadline=None)
@given(st.integers(min_value=0, max_value=10**6), st.integers(min_value=2, max_value=25))
def test_matrix_is_symmetric_positive_definite_for_any_configuration(seed, n):
    # Zuk et al.'s regularisation keeps mu positive definite for every configuration,
    # overlapping spheres of different sizes included
    rng = np.random.default_rng(seed)
    radii = rng.uniform(0.05, 1.0, n)
    x = rng.uniform(-1.0, 1.0, (n, 3))
    M = PolydisperseRPY(radii).matrix(x)
    np.testing.assert_allclose(M, M.T, atol=1e-15)
    assert np.linalg.eigvalsh(M).min() > 0.0


@settings(max_examples=40, deadline=None)
@given(st.integers(min_value=0, max_value=10**6))
def test_cross_block_is_the_full_matrix_block(seed):
    # the beads x blobs kernel (its own fast path for apart pairs) against the generic
    # matrix of all spheres together, with apart, overlapping and engulfed pairs
    rng = np.random.default_rng(seed)
    n, m, a = 7, 11, 0.05
    x = rng.uniform(-0.5, 0.5, (n, 3))
    y = rng.uniform(-0.5, 0.5, (m, 3))
    y[0] = x[0]  # a coincident pair
    b = rng.uniform(0.02, 0.4, m)
    M = PolydisperseRPY(np.concatenate([np.full(n, a), b])).matrix(np.vstack([x, y]))
    C = np.empty((3 * n, 3 * m))
    rpy_cross_radii(x, a, y, b, C)
    np.testing.assert_allclose(C, M[:3 * n, 3 * n:], rtol=0, atol=1e-14 * np.abs(M).max())


def _sphere_body(level=3):
    from scipy.spatial import cKDTree

    from flagwrap.body.multiblob import effective_radii, sphere_blobs

    b = sphere_blobs(1.0, level)
    d, _ = cKDTree(b).query(b, k=2)
    ab = 0.5 * d[:, 1].mean()
    return b, ab, effective_radii(b, ab)[0]


@pytest.mark.parametrize("d, tol", [(10.0, 0.03), (20.0, 0.008), (40.0, 0.002)])
def test_fixed_sphere_screens_a_far_bead_by_its_first_reflection(d, tol):
    # a bead at distance d from a fixed no-slip sphere of radius R: its force's Oseen flow
    # u = (I + dd) F / (8 pi d) meets the sphere, which pushes back with -6 pi R u; that
    # force's flow at the bead is the leading screening: -6 pi R (I + dd)^2 / (8 pi d)^2,
    # i.e. -3R/(8 pi d^2) along the line and -3R/(32 pi d^2) across (method of reflections).
    # The next reflection is O((R/d)^2) relative: measured 1.06e-2, 2.6e-3, 7e-4 radial and
    # 2.1e-2, 5.3e-3, 1.3e-3 across at d/R = 10, 20, 40; tol about 1.5x that (across)
    from flagwrap.body.fixed_mobility import FixedBodyMobility

    b, ab, Rt = _sphere_body()
    mob = FixedBodyMobility(0.05, b, ab)
    S = -mob.screening(np.array([[0.0, 0.0, d]]))
    assert S[2, 2] / (-3 * Rt / (8 * math.pi * d**2)) == pytest.approx(1.0, abs=tol)
    assert S[0, 0] / (-3 * Rt / (32 * math.pi * d**2)) == pytest.approx(1.0, abs=tol)


def test_fixed_body_mobility_is_the_schur_complement_and_positive_definite():
    from flagwrap.body.fixed_mobility import FixedBodyMobility

    b, ab, _ = _sphere_body(2)
    rng = np.random.default_rng(4)
    x = np.column_stack([rng.uniform(-0.5, 0.5, 12), rng.uniform(-0.5, 0.5, 12),
                         np.linspace(1.3, 2.5, 12)])  # beads beside the sphere
    a = 0.03
    mob = FixedBodyMobility(a, b, ab)
    full = PolydisperseRPY(np.r_[np.full(12, a), np.full(len(b), ab)]).matrix(np.vstack([x, b]))
    n3 = 36
    schur = full[:n3, :n3] - full[:n3, n3:] @ np.linalg.solve(full[n3:, n3:], full[n3:, :n3])
    M = mob.matrix(x)
    np.testing.assert_allclose(M, schur, atol=1e-10 * np.abs(schur).max())
    assert np.linalg.eigvalsh(M).min() > 0.0
    # screening only takes mobility away
    assert np.linalg.eigvalsh(RPYMobility(a).matrix(x) - M).min() > -1e-12
    F = rng.standard_normal((12, 3))
    np.testing.assert_allclose(mob.apply(x, F).ravel(), M @ F.ravel(), atol=1e-10)
