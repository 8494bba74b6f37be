"""Quasi-static uniaxial stretching of a helix with the bead model (issue 6(b), main text Fig. 3(b)).

The experiment (main text "Elasticity of helices"; SI "Uniaxial stretching test of a helix")
pulls the top end of a helix vertically at 0.1 mm/s in glycerin, the bottom end held in
place, both ends free to rotate (moment-free). At that speed viscous forces are negligible,
so the stretching is a sequence of static equilibria: at each prescribed end-to-end distance
``z`` the discrete elastic energy (:mod:`flagwrap.elasticity._kernels`, Bergou et al. 2008,
the equivalent of the paper's Chirico-Langowski / Wada-Netz bead model) is minimised over
every free degree of freedom, and the pulling force is

    F = dE/dz,

the axial component of the reaction on the pulled bead.

Geometry and boundary conditions
--------------------------------
* Stress-free shape: a uniform helix of radius ``R``, pitch ``P``, ``N`` beads at an exact
  chord ``b = L/(N-1)`` (discrete contour length ``L``). It is rotated so that its
  end-to-end vector lies along ``+z`` with bead 0 at the origin: ``z`` is the distance
  between the two end beads, as in the experiment (the ends are pulled; a helix's end points
  are not on its own axis, so the end-to-end line, not the helix axis, is the pulling axis).
  At rest ``z0 = |x_{N-1} - x_0|`` (``z0/L = 0.3397`` for the SI helix with ``N = 201``,
  against ``cos psi0 = 0.3393``: the end points' offset from the axis and the chords).
* Bead 0 is fixed at the origin, bead ``N-1`` at ``(0, 0, z)``. Every other bead position,
  every twist angle (the end bonds included) and so the directions of the end bonds are free:
  no moment acts at either end. Energy invariance under rotations about the origin then makes
  the end reaction purely axial (its transverse part is checked to vanish).
* Rotation about the ``z`` axis is a zero mode; it is removed by holding the middle bead in
  the half-plane ``y = 0`` (the helix is turned about ``z`` so that it starts there), which
  changes no equilibrium.

Stiffnesses
-----------
The bead model is isotropic. It is given the bending stiffness ``A2`` (the stiffness in the
plane of the spontaneous curvature), the twist stiffness ``C`` and the axial stiffness
``pi E a b`` of :class:`flagwrap.theory.stretching.StretchedHelix`; the bond springs are
``k_s = pi E a b / b_0`` (``b_0``: rest bond length), the real rod's axial stiffness, so
that the axial-stretch term ``F/(pi E a b)`` of the law is represented, not excluded. For a
round section these are ``A = pi E a^4/4``, ``C = A/(1+nu)``, ``pi E a^2`` (main text Eq. 1).
For an elliptic section the derived uniform-helix law does not contain ``A1`` (its minimiser
puts the spontaneous curvature in the bending plane), so this isotropic rod has exactly the
SI elliptic law; its end regions, which are not uniform, differ from the real elliptic rod.

Solver
------
Damped Newton on the energy in the units ``L = 1``, ``A2 = 1``: exact gradient from the
numba kernel, banded Hessian by central differences of the gradient (graph colouring with a
stride of 5 nodes; 40 gradient evaluations), Cholesky of the banded matrix (with a Levenberg
shift, increased until it succeeds, where the Hessian is not positive definite), backtracking line search on the energy. The reference
frames are re-based on the current configuration after every Newton iteration (the transport
is exact only near its base; re-basing at the current configuration leaves the energy
unchanged). Converged when the largest free gradient component is below ``gtol`` times the
force scale ``A2 kappa0^2``. A step in ``z`` starts from the linear extrapolation of the two
previous equilibria (from an affine stretch of the rest shape for the first).

All inputs and outputs are SI ([m], [N], [J]).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from flagwrap.errors import UserInputError
from flagwrap.theory.stretching import StretchedHelix

__all__ = ["StretchingRun", "stretched_helix_positions", "stretch_helix", "law_force_at_extension"]


@dataclass(frozen=True)
class StretchingRun:
    """Result of :func:`stretch_helix`.

    Attributes
    ----------
    z_over_L : (M,) ndarray
        end-to-end distance over arclength (dimensionless), increasing; ``z_over_L[0]`` is the rest value.
    force : (M,) ndarray
        pulling force ``dE/dz`` [N] (reaction on the pulled bead, axial component).
    energy : (M,) ndarray
        elastic energy at equilibrium [J].
    force_fixed_end : (M,) ndarray
        axial reaction on the fixed bead, with sign flipped [N] (equals ``force`` by force balance).
    transverse : (M,) ndarray
        magnitude of the transverse reaction on the pulled bead [N] (zero for moment-free ends).
    newton_iterations : (M,) ndarray of int
    positions : (N, 3) ndarray
        bead positions at the last extension [m].
    n_beads : int
    force_scale : float
        ``A2 kappa0^2`` [N].
    """

    z_over_L: np.ndarray
    force: np.ndarray
    energy: np.ndarray
    force_fixed_end: np.ndarray
    transverse: np.ndarray
    newton_iterations: np.ndarray
    positions: np.ndarray
    n_beads: int
    force_scale: float


def stretched_helix_positions(length: float, radius: float, pitch: float, n_beads: int) -> np.ndarray:
    """Uniform helix at exact chord ``L/(N-1)``, end-to-end vector along ``+z``, bead 0 at the origin.

    Left-handed: ``(R cos phi, -R sin phi, p phi)`` with ``p = P/2pi`` (the force law does not
    depend on the handedness), then rotated by the rotation taking the end-to-end vector to ``+z``.

    Returns
    -------
    (N, 3) ndarray
        positions [same length unit as the inputs].
    """
    from flagwrap.geometry.helix import _chord_angle

    N = int(n_beads)
    if N < 4:
        raise UserInputError(f"n_beads must be >= 4, got {N}")
    b = length / (N - 1)
    p = pitch / (2.0 * math.pi)
    phi = _chord_angle(radius, p, b) * np.arange(N)
    x = np.stack([radius * np.cos(phi), -radius * np.sin(phi), p * phi], axis=1)
    x -= x[0]
    d = x[-1] / np.linalg.norm(x[-1])
    ez = np.array([0.0, 0.0, 1.0])
    v = np.cross(d, ez)
    s, c = np.linalg.norm(v), float(d @ ez)
    if s > 1e-15:
        k = v / s
        Kx = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
        Rm = np.eye(3) + s * Kx + (1 - c) * (Kx @ Kx)
        x = x @ Rm.T
    x[-1, :2] = 0.0
    m = N // 2  # turn about z so that the middle bead lies in the half-plane y = 0, x > 0
    ang = math.atan2(x[m, 1], x[m, 0])
    cz, sz = math.cos(ang), math.sin(ang)
    x[:, 0], x[:, 1] = cz * x[:, 0] + sz * x[:, 1], -sz * x[:, 0] + cz * x[:, 1]
    x[m, 1] = 0.0
    return x


class _Energy:
    """Energy and gradient of the node array ``q`` (N, 4) = (x, y, z, theta_k) in core units."""

    def __init__(self, x0: np.ndarray, A: float, C: float, ks: float) -> None:
        from flagwrap.elasticity.rod import initial_frames, rest_state

        self.N = len(x0)
        self.base = initial_frames(x0)
        self.rest = rest_state(x0, self.base, np.zeros(self.N - 1), A, C, ks)
        self.gx = np.empty((self.N, 3))
        self.gth = np.empty(self.N - 1)
        self.d1 = np.empty((self.N - 1, 3))
        self.rt = np.empty(self.N)

    def __call__(self, q: np.ndarray, gout: np.ndarray | None = None) -> float:
        from flagwrap.elasticity import _kernels as K

        r, b = self.rest, self.base
        x = np.ascontiguousarray(q[:, :3])
        th = np.ascontiguousarray(q[:-1, 3])
        E = K.energy_grad(x, th, b.t, b.d1, b.rt, r.l0, r.cbend, r.ctwist, r.angle_law, r.kbar, r.mbar,
                          r.stretch, self.gx, self.gth, self.d1, self.rt)
        if gout is not None:
            gout[:, :3] = self.gx
            gout[:-1, 3] = self.gth
            gout[-1, 3] = 0.0
        return E

    def rebase(self, q: np.ndarray) -> None:
        """Make the frames at ``q`` the new base (energy unchanged)."""
        from flagwrap.elasticity.rod import Frames

        self(q)
        e = np.diff(q[:, :3], axis=0)
        t = e / np.linalg.norm(e, axis=1)[:, None]
        self.base = Frames(t, self.d1.copy(), self.rt.copy())


def _free_mask(N: int) -> np.ndarray:
    free = np.ones((N, 4), dtype=bool)
    free[0, :3] = False
    free[-1, :] = False  # pulled bead position prescribed; no bond N-1 -> no theta
    free[N // 2, 1] = False  # gauge: removes the zero mode of rotation about z
    return free


def _banded_hessian(fun: _Energy, q: np.ndarray, free: np.ndarray, h: float) -> np.ndarray:
    """Upper banded storage (for ``solveh_banded``) of the free-DOF Hessian, central differences.

    The gradient of node ``j`` depends on nodes ``j-2..j+2`` only, so all nodes ``k = c mod 5``
    are perturbed at once. Fixed DOFs get unit diagonal and no coupling.
    """
    N = len(q)
    n = 4 * N
    u = 11  # bandwidth: 2 nodes x 4 + 3
    ab = np.zeros((u + 1, n))
    full = np.zeros((N, 4, 5, 4))  # dG[j, e] / dq[j+m, d]  for offset m in -2..2
    gp = np.empty((N, 4))
    gm = np.empty((N, 4))
    qq = q.copy()
    for c in range(5):
        ks = np.arange(c, N, 5)
        for d in range(4):
            qq[ks, d] += h
            fun(qq, gp)
            qq[ks, d] -= 2 * h
            fun(qq, gm)
            qq[ks, d] += h
            dg = (gp - gm) / (2 * h)
            for m in range(-2, 3):
                j = ks - m
                ok = (j >= 0) & (j < N)
                full[j[ok], :, m + 2, d] = dg[j[ok]]
    # assemble symmetric part into upper band: row i = 4j+e, column col = 4(j+m)+d
    for m in range(-2, 3):
        for e in range(4):
            for d in range(4):
                j = np.arange(N)
                k = j + m
                ok = (k >= 0) & (k < N)
                i = 4 * j[ok] + e
                col = 4 * k[ok] + d
                upper = col >= i
                vals = full[j[ok], e, m + 2, d][upper]
                ab[u + i[upper] - col[upper], col[upper]] += 0.5 * vals
                # the transposed entry (col, i) with col <= i lands in the same upper slot
                lower = col <= i
                vals2 = full[j[ok], e, m + 2, d][lower]
                ab[u + col[lower] - i[lower], i[lower]] += 0.5 * vals2
    fixed = ~free.ravel()
    # zero rows/cols of fixed DOFs, unit diagonal
    for off in range(u + 1):
        colidx = np.arange(n)
        rowidx = colidx - (u - off)
        valid = rowidx >= 0
        kill = np.zeros(n, dtype=bool)
        kill[valid] = fixed[rowidx[valid]] | fixed[colidx[valid]]
        ab[off, kill] = 0.0
    ab[u, fixed] = 1.0
    return ab


def _newton(fun: _Energy, q: np.ndarray, free: np.ndarray, gtol: float, h: float,
            max_iter: int = 100) -> tuple[np.ndarray, int]:
    from scipy.linalg import LinAlgError, solveh_banded

    g = np.empty_like(q)
    for it in range(1, max_iter + 1):
        fun.rebase(q)
        E = fun(q, g)
        g[~free] = 0.0
        if np.max(np.abs(g)) < gtol:
            return q, it - 1
        ab = _banded_hessian(fun, q, free, h)
        diag = ab[-1].copy()
        mu = 0.0
        while True:
            ab[-1] = diag + mu
            try:
                s = solveh_banded(ab, -g.ravel(), lower=False, check_finite=False).reshape(q.shape)
                break
            except LinAlgError:
                mu = max(mu * 100.0, 1e-12 * float(np.max(np.abs(diag))))
        s[~free] = 0.0
        slope = float(np.sum(s * g))
        alpha = 1.0
        while alpha > 1e-12:
            qn = q + alpha * s
            En = fun(qn)
            # the second test accepts a full Newton step whose energy change is below rounding
            if En <= E + 1e-4 * alpha * slope or (alpha == 1.0 and En - E <= 1e-11 * max(abs(E), 1.0)):
                break
            alpha *= 0.5
        q = qn
    raise RuntimeError(f"Newton did not converge in {max_iter} iterations (max |grad| {np.max(np.abs(g)):.3g})")


def stretch_helix(helix: StretchedHelix, n_beads: int = 151, z_over_L_max: float = 0.95,
                  n_steps: int = 60, *, z_over_L: ArrayLike | None = None,
                  gtol: float = 1e-9) -> StretchingRun:
    """Quasi-static stretching of ``helix`` with the bead model, moment-free ends.

    The end-to-end distance goes from its rest value ``z0`` to ``z_over_L_max * L`` in
    ``n_steps`` equal steps (or through the given ``z_over_L``); at each the energy is
    minimised (module docstring). The rest state is always the first entry.

    Parameters
    ----------
    helix : StretchedHelix
        geometry ``R, P, L`` [m] and stiffnesses ``A2, C`` [N m^2], ``pi E a b`` [N].
    n_beads : int
        ``N`` (bond length ``L/(N-1)``).
    z_over_L_max : float
        last extension, in ``(z0/L, 1)``.
    n_steps : int
        number of steps after the rest state.
    z_over_L : array_like, optional
        increasing extensions after the rest state, all in ``(z0/L, 1)``; overrides
        ``z_over_L_max`` and ``n_steps``.
    gtol : float
        convergence: max free gradient component below ``gtol * A2 kappa0^2``.

    Returns
    -------
    StretchingRun
    """
    L = helix.length
    x0 = stretched_helix_positions(1.0, helix.radius / L, helix.pitch / L, n_beads)
    N = len(x0)
    z0 = float(x0[-1, 2])
    if z_over_L is None:
        if not (z0 < z_over_L_max < 1.0):
            raise UserInputError(f"z_over_L_max must lie in ({z0:.4f}, 1), got {z_over_L_max!r}")
        if int(n_steps) < 1:
            raise UserInputError(f"n_steps must be >= 1, got {n_steps!r}")
        zs = np.linspace(z0, z_over_L_max, int(n_steps) + 1)
    else:
        zl = np.atleast_1d(np.asarray(z_over_L, dtype=float))
        if zl.size == 0 or not (np.all(np.diff(zl) > 0) and zl[0] > z0 and zl[-1] < 1.0):
            raise UserInputError(f"z_over_L must increase within ({z0:.4f}, 1)")
        zs = np.concatenate([[z0], zl])
    b0 = 1.0 / (N - 1)
    # core units: length L, force A2/L^2, so a stiffness is in A2/L^3: the real bond spring
    # pi E a b / (b0 L) [N/m] (b0 in units of L) is pi E a b L^2 / (A2 b0) in core units
    ks = L ** 2 / (helix.stretch_compliance * helix.A2) / b0
    fun = _Energy(x0, 1.0, helix.C / helix.A2, ks)
    free = _free_mask(N)
    fscale_core = (helix.kappa0 * L) ** 2
    tol = gtol * fscale_core
    h = 1e-6 * b0

    q = np.zeros((N, 4))
    q[:, :3] = x0
    out = {k: np.empty(len(zs)) for k in ("F", "F0", "E", "T")}
    iters = np.zeros(len(zs), dtype=int)
    prev = None
    g = np.empty_like(q)
    for i, z in enumerate(zs):
        if i > 0:
            guess = q + (q - prev) * (z - zs[i - 1]) / (zs[i - 1] - zs[i - 2]) if prev is not None else q.copy()
            if prev is None:
                guess[:, 2] *= z / zs[i - 1]
            guess[-1, :3] = (0.0, 0.0, z)
            prev = q
            q, iters[i] = _newton(fun, guess, free, tol, h)
        fun.rebase(q)
        E = fun(q, g)
        out["E"][i] = E
        out["F"][i] = g[-1, 2]
        out["F0"][i] = -g[0, 2]
        out["T"][i] = math.hypot(g[-1, 0], g[-1, 1])
    fconv = helix.A2 / L**2
    return StretchingRun(
        z_over_L=zs,
        force=out["F"] * fconv,
        energy=out["E"] * helix.A2 / L,
        force_fixed_end=out["F0"] * fconv,
        transverse=out["T"] * fconv,
        newton_iterations=iters,
        positions=q[:, :3] * L,
        n_beads=N,
        force_scale=helix.force_scale,
    )


def law_force_at_extension(helix: StretchedHelix, z_over_L, *, axial_stretch: bool = True) -> np.ndarray:
    """Force [N] of the uniform-helix law (main text Eq. 1 form) at given extensions ``z/L``.

    Solves ``z/L = cos psi + F(psi)/(pi E a b)`` for ``psi`` (Brent; the right side decreases
    monotonically in ``psi`` on ``(0, pi/2]``), then returns ``F(psi)``.
    """
    from scipy.optimize import brentq

    zl = np.atleast_1d(np.asarray(z_over_L, dtype=float))
    out = np.empty_like(zl)
    for k, target in enumerate(zl):
        def resid(p: float) -> float:
            return float(helix.extension(p, axial_stretch=axial_stretch)) - target

        out[k] = helix.force(brentq(resid, 1e-6, 0.5 * math.pi, xtol=1e-14))
    return out.reshape(np.shape(z_over_L))

