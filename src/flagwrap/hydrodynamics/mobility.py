"""Mobility backends behind one small interface.

A mobility maps forces on the hydrodynamically active beads to their velocities,
``v = (1/eta) mu_hat(x) F``. The core divides by ``M`` instead of ``eta`` (see
:mod:`flagwrap.units`). Backends implement:

* ``apply(x, F) -> V``     matrix-free product, (n,3) -> (n,3)
* ``apply_single(x, F)``   the same product to float32 accuracy (where that is faster), for
  the operator products of an iterative solve; ``apply`` unless a backend has one
* ``matrix(x) -> (3n,3n)`` dense matrix (for direct linear solves at small n)

``make_mobility(hydrodynamics, radius, backend=...)`` picks the backend
(``numerics.mobility_backend``):

* ``"direct"``: numba O(n^2) product, vectorised (AVX2), O(n) memory, optionally threaded;
* ``"fmm"``: FMM3D (``pip install fmm3dpy``): Stokes FMM + Laplace dipole FMM, O(n) per
  product, plus exact overlap corrections (Liang, Gimbutas, Greengard, Huang & Jiang,
  J. Chem. Phys. 139, 134105 (2013), Eqs. 8-10);
* ``"jax"``: the direct sum in JAX (``pip install jax``; on a GPU when jax sees one);
* ``"auto"`` (default): ``direct``, except on a machine where jax sees a GPU and
  ``n >= GPU_AUTO_MIN_BEADS``. FMM is never chosen automatically: on this project's 2-core
  CPU it was slower than the vectorised direct sum at every N up to 16000
  (benchmarks/scaling.py prints both).

The integrators only see ``apply``/``matrix``/``near_field_blocks``, so a backend swaps without
touching them.
"""

from __future__ import annotations

import math

import numpy as np

from flagwrap.hydrodynamics import _kernels as K


class Mobility:
    """Interface; ``radius`` is the hydrodynamic bead radius in core length units."""

    radius: float
    long_range: bool

    def apply(self, x: np.ndarray, F: np.ndarray) -> np.ndarray:  # pragma: no cover
        raise NotImplementedError

    def matrix(self, x: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:  # pragma: no cover
        """Dense ``mu_hat`` (3n, 3n); written into ``out`` when given (no fresh array: the
        time loop reuses one buffer per step instead of a new ~0.3 MB array)."""
        raise NotImplementedError

    def apply_single(self, x: np.ndarray, F: np.ndarray) -> np.ndarray:
        """``apply`` to single-precision accuracy, for the products inside an iterative solve
        that stops far above it (GCR: relative residual 1e-3). The relative error is ~float32
        epsilon x (chain extent / bead separation): measured 7e-7 at N = 1000, 3e-6 at 4000,
        1.2e-5 at 16000 (benchmarks/scaling.py's chain). Exact (``apply``) unless a backend
        has a faster reduced-precision product."""
        return self.apply(x, F)

    def near_field_blocks(self, x: np.ndarray, width: int) -> np.ndarray:
        """Mobility between beads at most ``width`` apart along the chain, as dense 3x3
        blocks ``out[i, width + k] = mu_hat_{i, i+k}``, shape (n, 2 width + 1, 3, 3), for
        banded preconditioners; a local mobility has only its self blocks."""
        width = int(width) if self.long_range else 0
        out = np.empty((len(x), 2 * width + 1, 3, 3))
        if self.long_range:
            K.rpy_band_blocks(np.ascontiguousarray(x, dtype=np.float64), self.radius, width, out)
        else:
            out[:] = 0.0
            out[:, 0] = np.eye(3) * self.self_mobility
        return out


def _matrix_out(out, m: int) -> np.ndarray:
    if out is None:
        return np.empty((m, m))
    if out.shape != (m, m) or out.dtype != np.float64 or not out.flags.c_contiguous:
        raise ValueError(f"matrix out must be a C-contiguous float64 ({m}, {m}) array")
    return out


class RPYMobility(Mobility):
    """Full Rotne-Prager-Yamakawa mobility (paper, Methods), numba O(n^2) direct sum."""

    long_range = True
    backend = "direct"

    def __init__(self, radius: float, threads: int = 1):
        self.radius = float(radius)
        self.self_mobility = 1.0 / (6.0 * math.pi * self.radius)
        self.threads = int(threads)

    def apply(self, x, F):
        x = np.ascontiguousarray(x, dtype=np.float64)
        F = np.ascontiguousarray(F, dtype=np.float64)
        out = np.empty_like(F)
        K.rpy_apply(x, self.radius, F, out, self.threads)
        return out

    def apply_single(self, x, F):
        """The once-per-pair loop in float32 (:func:`~flagwrap.hydrodynamics._kernels.rpy_apply_single`,
        ~1.9x faster) where the serial float64 product uses that loop (n >=
        ``SYMMETRIC_MIN_N``); the float64 product otherwise (short chains: gather loop;
        threads: the threaded rows)."""
        if self.threads > 1 or len(x) < K.SYMMETRIC_MIN_N:
            return self.apply(x, F)
        x = np.ascontiguousarray(x, dtype=np.float64)
        F = np.ascontiguousarray(F, dtype=np.float64)
        out = np.empty_like(F)
        K.rpy_apply_single(x, self.radius, F, out, K.SYMMETRIC_BLOCK)
        return out

    def matrix(self, x, out=None):
        x = np.ascontiguousarray(x, dtype=np.float64)
        n = len(x)
        out = _matrix_out(out, 3 * n)
        K.rpy_matrix(x, self.radius, out)
        return out


class FMMMobility(RPYMobility):
    """RPY product by the fast multipole method (FMM3D), O(n) per product.

    For ``r >= 2a`` the RPY tensor is the Oseen tensor plus a potential dipole,
    ``mu_hat = (I + rr)/(8 pi r) + a^2/(12 pi) (I/r^3 - 3 rr/r^5)`` (Liang et al. 2013,
    Eq. 8): one Stokeslet FMM (FMM3D's Stokeslet is already ``(I/r + rr/r^3)/(8 pi)``) and
    one Laplace FMM of dipoles ``F`` whose gradient, times ``4 pi a^2/(12 pi) = a^2/3``,
    gives the second term (FMM3D's Laplace kernel carries ``1/(4 pi)``). Pairs closer than
    ``2a`` (found with a k-d tree) are corrected to the overlap form exactly. ``eps`` is
    FMM3D's requested relative precision.
    """

    backend = "fmm"

    def __init__(self, radius: float, eps: float = 1e-10, threads: int = 1):
        super().__init__(radius, threads)
        import fmm3dpy  # noqa: F401  (fail at construction, not mid-run)

        self.eps = float(eps)

    def apply(self, x, F):
        import fmm3dpy
        from scipy.spatial import cKDTree

        x = np.ascontiguousarray(x, dtype=np.float64)
        F = np.ascontiguousarray(F, dtype=np.float64)
        n = len(x)
        src = np.ascontiguousarray(x.T)
        ft = np.ascontiguousarray(F.T)
        st = fmm3dpy.stfmm3d(eps=self.eps, sources=src, stoklet=ft, ifppreg=1)
        lp = fmm3dpy.lfmm3d(eps=self.eps, sources=src, dipvec=ft, pg=2)
        out = st.pot.reshape(3, n).T + (self.radius ** 2 / 3.0) * lp.grad.reshape(3, n).T
        out += self.self_mobility * F
        pairs = cKDTree(x).query_pairs(2.0 * self.radius, output_type="ndarray")
        if len(pairs):
            K.rpy_overlap_correction(x, self.radius, pairs.astype(np.int64), F, out)
        return np.ascontiguousarray(out)

    apply_single = Mobility.apply_single  # the FMM, not the direct float32 sum


class JAXMobility(RPYMobility):
    """The RPY direct sum in JAX, jitted; runs on a GPU when jax has one.

    Rows are processed in blocks of ``block`` so memory stays O(block * n), not O(n^2).
    ``apply`` is float64; ``apply_single`` (the products inside GCR) is float32 on centred
    positions, matrix products at full float32 precision: jax's default on a GPU is TF32
    (measured on an H200: 2.9e-4 relative against 2.1e-7 at full precision), too coarse
    for the operator of a solve stopped at 1e-3. Measured there (benchmarks/gpu.py): faster
    than the numba sum from N = 1000, 46x (float64) / 59x (float32) at N = 64000.
    """

    backend = "jax"

    def __init__(self, radius: float, block: int = 1024, threads: int = 1):
        super().__init__(radius, threads)
        self.block = int(block)
        # one jitted function; jax traces it once per argument dtype (float64, float32)
        self._fn = _jax_rpy(float(radius), self.block)

    def apply(self, x, F):
        return np.asarray(self._fn(np.asarray(x, dtype=np.float64),
                                   np.asarray(F, dtype=np.float64)), dtype=np.float64)

    def apply_single(self, x, F):
        x = np.asarray(x, dtype=np.float64)
        xc = (x - x.mean(axis=0)).astype(np.float32)  # centred: float32 resolves the bonds
        return np.asarray(self._fn(xc, np.asarray(F, dtype=np.float32)), dtype=np.float64)


def _jax_rpy(a: float, block: int):
    import jax

    jax.config.update("jax_enable_x64", True)
    import jax.numpy as jnp

    hi = jax.lax.Precision.HIGHEST
    s = 1.0 / (6.0 * math.pi * a)

    def rows(xb, x, F):
        d = xb[:, None, :] - x[None, :, :]
        r2 = jnp.sum(d * d, axis=-1)
        # coincident beads (the self pair) get 1/r = 0: the near-field form is then exactly
        # the self mobility in any precision (a floor on r2 underflows in float32)
        pos = r2 > 0
        ir = jnp.where(pos, 1.0 / jnp.sqrt(jnp.where(pos, r2, 1.0)), 0.0)
        q = a * a * ir * ir
        far = r2 >= 4.0 * a * a
        f = jnp.where(far, ir / (8 * math.pi) * (1 + 2 * q / 3), s * (1 - 9 * r2 * ir / (32 * a)))
        g = jnp.where(far, ir ** 3 / (8 * math.pi) * (1 - 2 * q), s * 3 * ir / (32 * a))
        dF = jnp.einsum("ijk,jk->ij", d, F, precision=hi)
        return jnp.matmul(f, F, precision=hi) + jnp.einsum("ij,ijk->ik", g * dF, d,
                                                           precision=hi)

    @jax.jit
    def apply(x, F):
        n = x.shape[0]
        nb_ = -(-n // block)
        pad = nb_ * block - n
        xp = jnp.pad(x, ((0, pad), (0, 0)))
        out = jax.lax.map(lambda xb: rows(xb, x, F), xp.reshape(nb_, block, 3))
        return out.reshape(-1, 3)[:n]

    return apply


def jax_gpu_available() -> bool:
    """True when jax is installed and sees a GPU (never raises)."""
    try:
        import jax

        return any(d.platform == "gpu" for d in jax.devices())
    except Exception:  # noqa: BLE001 - any failure means "no GPU backend here"
        return False


BACKENDS = ("auto", "direct", "fmm", "jax")
# benchmarks/gpu.py on an H200 (docs/numerics.md, "GPU"), a ROS34PW2 + GCR step with jax
# against the numba sum: 0.98-1.12x the time at N = 1000 (the CPU work dominates), 0.70x at
# 1250, 0.63-0.92x at 1500, 0.42x at 4000: jax from the first N it won in every run
GPU_AUTO_MIN_BEADS = 1250


def backend_missing(name: str) -> str | None:
    """Why backend ``name`` cannot run here (missing package), or None if it can."""
    import importlib.util

    need = {"fmm": "fmm3dpy", "jax": "jax"}.get(name)
    if need and importlib.util.find_spec(need) is None:
        return f"needs the {need} package (pip install {need})"
    return None


class LocalMobility(Mobility):
    """Self mobility only, ``1/(6 pi a)``: the paper's "without HIs" runs."""

    long_range = False

    def __init__(self, radius: float):
        self.radius = float(radius)
        self.self_mobility = 1.0 / (6.0 * math.pi * self.radius)

    def apply(self, x, F):
        return self.self_mobility * np.asarray(F, dtype=np.float64)

    def matrix(self, x, out=None):
        out = _matrix_out(out, 3 * len(x))
        out[:] = 0.0
        np.fill_diagonal(out, self.self_mobility)
        return out


def make_mobility(hydrodynamics: bool, radius: float, backend: str = "auto", n: int = 0,
                  threads: int = 1, fmm_eps: float = 1e-10) -> Mobility:
    """The mobility for ``n`` active beads (``backend`` as in the module docstring)."""
    if not hydrodynamics:
        return LocalMobility(radius)
    if backend not in BACKENDS:
        raise ValueError(f"mobility backend must be one of {BACKENDS}, got {backend!r}")
    if backend == "auto":
        backend = "jax" if n >= GPU_AUTO_MIN_BEADS and jax_gpu_available() else "direct"
    if backend == "fmm":
        return FMMMobility(radius, eps=fmm_eps, threads=threads)
    if backend == "jax":
        return JAXMobility(radius, threads=threads)
    return RPYMobility(radius, threads=threads)
