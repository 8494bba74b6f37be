"""RPY mobility: symmetry, positive definiteness, matrix-free = dense, known limits."""

import math

import numpy as np
import pytest
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


@settings(max_examples=40, deadline=None)
@given(st.integers(1, 40), st.integers(1, 17), st.integers(0, 100_000), st.floats(0.05, 2.0))
def test_once_per_pair_product_equals_dense(n, block, seed, spread):
    """The i < j loop (used from N = 256) with every block split, overlaps included."""
    from flagwrap.hydrodynamics._kernels import _rpy_apply_sym

    rng = np.random.default_rng(seed)
    x = spread * rng.standard_normal((n, 3))
    F = rng.standard_normal((n, 3))
    mob = RPYMobility(0.3)
    out = np.empty_like(F)
    _rpy_apply_sym(x, 0.3, F, out, block)
    ref = (mob.matrix(x) @ F.ravel()).reshape(-1, 3)
    np.testing.assert_allclose(out, ref, rtol=1e-10, atol=1e-12 * np.abs(ref).max())


def test_large_n_product_uses_the_pair_loop_and_equals_the_gather_loop():
    from flagwrap.hydrodynamics import _kernels as K

    x, a, F = _chain(K.SYMMETRIC_BLOCK + 300)  # two column blocks
    ref = np.empty_like(F)
    K._rpy_apply_serial(x, a, F, ref)
    out = RPYMobility(a).apply(x, F)
    sym = np.empty_like(F)
    K._rpy_apply_sym(x, a, F, sym, K.SYMMETRIC_BLOCK)
    np.testing.assert_array_equal(out, sym)  # the dispatch really takes the pair loop
    # same pair terms summed in another order: rounding only, ~2300 terms x 1e-16
    np.testing.assert_allclose(out, ref, rtol=0, atol=1e-13 * np.abs(ref).max())


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


def _chain(n, seed=3):
    """A helical bead chain with overlapping neighbours (b = 1.6 a) and a few random kicks."""
    rng = np.random.default_rng(seed)
    t = np.linspace(0.0, 6 * 2 * math.pi, n)
    x = np.stack([np.cos(t), np.sin(t), 0.15 * t], axis=1)
    a = np.linalg.norm(x[1] - x[0]) / 1.6
    x += 0.05 * a * rng.standard_normal(x.shape)
    return x, a, rng.standard_normal((n, 3))


def test_single_precision_product_is_accurate_to_float32_rounding():
    """``apply_single`` (float32 pair loop, for GCR's operator products) against the dense
    float64 product. Bound: a separation carries float32 rounding (6e-8) x (distance from the
    centre / separation); this chain is ~110 bonds wide, so ~7e-6 per near pair at worst; the
    norm-wise error must stay below 2e-5, and must be nonzero (the float32 path is taken)."""
    from flagwrap.hydrodynamics import _kernels as K

    x, a, F = _chain(K.SYMMETRIC_MIN_N + 500)
    mob = RPYMobility(a)
    ref = (mob.matrix(x) @ F.ravel()).reshape(-1, 3)
    out = mob.apply_single(x, F)
    err = np.linalg.norm(out - ref) / np.linalg.norm(ref)
    assert 1e-12 < err < 2e-5
    assert np.max(np.abs(out - ref)) < 2e-5 * np.max(np.abs(ref))
    # where the float64 product is not the pair loop, the single product is the exact one
    xs, as_, Fs = _chain(K.SYMMETRIC_MIN_N - 1)
    np.testing.assert_array_equal(RPYMobility(as_).apply_single(xs, Fs),
                                  RPYMobility(as_).apply(xs, Fs))
    np.testing.assert_array_equal(RPYMobility(a, threads=2).apply_single(x, F),
                                  RPYMobility(a, threads=2).apply(x, F))


def test_threaded_direct_product_agrees_to_rounding():
    from flagwrap.hydrodynamics.mobility import RPYMobility

    x, a, F = _chain(700)
    # same pair sums per row; the vectoriser may group them differently in the threaded
    # build (fast-math reassociation), so rounding-level differences only: 700 terms x 1e-16
    ref = RPYMobility(a).apply(x, F)
    np.testing.assert_allclose(RPYMobility(a, threads=2).apply(x, F), ref, rtol=0,
                               atol=1e-13 * np.abs(ref).max())


@pytest.mark.parametrize("eps", [1e-4, 1e-8, 1e-12])
def test_fmm_backend_meets_its_requested_precision(eps):
    pytest.importorskip("fmm3dpy")
    from flagwrap.hydrodynamics.mobility import FMMMobility

    x, a, F = _chain(1500)
    ref = (RPYMobility(a).matrix(x) @ F.ravel()).reshape(-1, 3)
    got = FMMMobility(a, eps=eps).apply(x, F)
    err = np.linalg.norm(got - ref) / np.linalg.norm(ref)
    # FMM3D's eps bounds the relative l2 error of each kernel sum; 1e-10 floor = round-off of
    # the overlap corrections; 10x margin for the sum of the two FMMs
    assert err <= max(10 * eps, 1e-10), err


def test_jax_backend_agrees_with_dense():
    pytest.importorskip("jax")
    from flagwrap.hydrodynamics.mobility import JAXMobility

    for n, block in ((1, 4), (37, 8), (300, 128)):
        x, a, F = _chain(max(n, 2))
        x, F = x[:n], F[:n]
        ref = (RPYMobility(a).matrix(x) @ F.ravel()).reshape(-1, 3)
        got = JAXMobility(a, block=block).apply(x, F)
        np.testing.assert_allclose(got, ref, rtol=1e-10, atol=1e-10 * np.abs(ref).max())


def test_jax_single_precision_product_is_accurate_to_float32_rounding():
    """JAX's float32 product (GCR's operator products on a GPU) against the dense float64
    product, same bound and reasoning as the numba float32 test above: nonzero (float32 is
    really used) and below 2e-5 (float32 rounding x ~110 bonds of extent); TF32 matrix
    products (jax's GPU default, 2.9e-4 on a float32 matmul on an H200) would miss it ~15x."""
    pytest.importorskip("jax")
    from flagwrap.hydrodynamics.mobility import JAXMobility

    x, a, F = _chain(756)
    # also at the bead radius of benchmarks/scaling.py's long chains (2e-4 at N = 1000, 1.4e-5
    # at 16000, core units), where a floor on the self pair's r^2 of 1e-32 a^2 underflows in
    # float32 (NaN rows, seen at N = 250)
    for scale in (1.0, 1e-4 / a):
        xs, as_ = scale * x, scale * a
        ref = (RPYMobility(as_).matrix(xs) @ F.ravel()).reshape(-1, 3)
        out = JAXMobility(as_, block=256).apply_single(xs, F)
        assert out.dtype == np.float64
        err = np.linalg.norm(out - ref) / np.linalg.norm(ref)
        assert 1e-12 < err < 2e-5
        assert np.max(np.abs(out - ref)) < 2e-5 * np.max(np.abs(ref))


def test_gpu_backend_agrees_with_dense_when_a_gpu_is_present():
    from flagwrap.hydrodynamics.mobility import JAXMobility, jax_gpu_available

    if not jax_gpu_available():
        pytest.skip("no GPU visible to jax: the GPU backend is not used here")
    x, a, F = _chain(4000)
    ref = RPYMobility(a).apply(x, F)
    got = JAXMobility(a).apply(x, F)
    np.testing.assert_allclose(got, ref, rtol=1e-10, atol=1e-10 * np.abs(ref).max())


def test_auto_backend_is_direct_without_gpu_and_names_missing_packages():
    from flagwrap.hydrodynamics import mobility as mob

    if not mob.jax_gpu_available():
        assert mob.make_mobility(True, 0.1, "auto", n=10**5).backend == "direct"
    assert mob.make_mobility(True, 0.1, "auto", n=10).backend == "direct"
    assert isinstance(mob.make_mobility(False, 0.1, "fmm"), LocalMobility)
    assert mob.backend_missing("direct") is None
    import importlib.util

    real = importlib.util.find_spec
    for name, module in (("fmm", "fmm3dpy"), ("jax", "jax")):
        # the package absent, then present (find_spec answering as it would)
        importlib.util.find_spec = lambda m, *a, _mod=module: None if m == _mod else real(m, *a)
        try:
            assert mob.backend_missing(name) == f"needs the {module} package (pip install {module})"
            importlib.util.find_spec = lambda m, *a, _mod=module: (object() if m == _mod
                                                                   else real(m, *a))
            assert mob.backend_missing(name) is None
        finally:
            importlib.util.find_spec = real
    with pytest.raises(ValueError, match="mobility backend"):
        mob.make_mobility(True, 0.1, "gpu")
