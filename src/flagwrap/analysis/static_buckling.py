"""Static stability of a filament under its buoyant weight, the motor at rest.

A filament hanging below the clamp and lighter than the fluid is pushed toward its clamp by a
distributed load ``q = (rho_f - rho) g pi a^2`` per length: a heavy column loaded toward its
support. In the units of the model this is the gravity number ``G = q L^3 / A``
(:func:`flagwrap.units.gravity_number`). A straight clamped-free column buckles at

    G_c = 7.837          (Greenhill 1881; Timoshenko & Gere, *Theory of Elastic Stability*,
                          2nd ed. 1961, section 2.13: (q l^3 / EI)_cr = 7.837)

This module finds the static equilibrium of the discrete rod (Newton on ``G(y) = 0``, the
motor angle held) and the spectrum of its stiffness matrix ``K = -dG/dy`` (the Hessian of the
discrete energy at fixed reference frames, from :meth:`RodSystem.force_jacobian`). The
equilibrium is stable while the lowest eigenvalue of ``K`` is positive. The overdamped
dynamics ``dy/dt = Mob G`` with a positive definite mobility has the same stable set
(``Mob K`` is similar to ``Mob^1/2 K Mob^1/2``, congruent to ``K``), so the static threshold
does not depend on the hydrodynamics; only the growth rate does.

Uses: the independent check of the gravity implementation against Greenhill's value
(:func:`straight_rod_system`, :func:`critical_gravity`; tests/validation/test_greenhill.py) and
the static (M -> 0) limit of the buoyant helix (docs/gravity.md).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from flagwrap import units
from flagwrap.errors import UserInputError

#: Greenhill's heavy-column value (q L^3 / A)_c for a clamped-free column loaded toward its clamp
GREENHILL_CLAMPED_FREE = 7.837


def with_gravity_number(config, G: float):
    """``config`` with the filament density that gives gravity number ``G`` (fluid unchanged).

    Raises :class:`UserInputError` if ``G`` needs a density <= 0 (``G`` above
    ``rho_f g pi a^2 L^3 / A``).
    """
    fil = config.filament
    per_density = units.gravity_number(1.0, fil.cross_section_radius, fil.length, fil.bending_modulus)
    rho = config.fluid.density - float(G) / per_density
    if not (math.isfinite(rho) and rho > 0):
        raise UserInputError(f"gravity number G = {G!r} needs a filament density {rho:g} kg/m^3 "
                             f"<= 0 (the fluid's is {config.fluid.density:g})")
    return dataclasses.replace(config, filament=fil.with_density(rho))


def straight_positions(n_beads: int) -> np.ndarray:
    """A straight filament of unit length hanging from the clamp at the origin along -z."""
    z = -np.linspace(0.0, 1.0, n_beads)
    return np.column_stack([np.zeros(n_beads), np.zeros(n_beads), z])


def straight_rod_system(config):
    """:class:`~flagwrap.system.rod_system.RodSystem` of ``config`` with a straight stress-free rest shape
    (and straight initial state) instead of its helix: the clamped bond and the whole rod on
    the body axis, below the body."""
    from flagwrap.system.rod_system import RodSystem

    return RodSystem(config, x0=straight_positions(config.filament.n_beads))


@dataclass
class Equilibrium:
    """A static equilibrium ``G(y) = 0`` (motor angle held) and its stiffness spectrum.

    Attributes
    ----------
    y : ndarray
        state vector (core units).
    base : Frames
        reference frames at ``y``.
    residual : float
        ``max |G|`` over the free degrees of freedom (core force units).
    iterations : int
        Newton iterations used.
    eigenvalues : ndarray
        the lowest eigenvalues of the stiffness ``K = -dG/dy`` (ascending; core units).
    modes : ndarray
        their eigenvectors (columns), over the free degrees of freedom.
    """

    y: np.ndarray
    base: object
    residual: float
    iterations: int
    eigenvalues: np.ndarray
    modes: np.ndarray

    @property
    def stable(self) -> bool:
        return bool(self.eigenvalues[0] > 0)


def _system_at(config, G: float, straight: bool):
    """The system of ``config`` at gravity number ``G``: straight rest shape or its own helix."""
    from flagwrap.system.rod_system import RodSystem

    cfg = with_gravity_number(config, G)
    return straight_rod_system(cfg) if straight else RodSystem(cfg)


def _stiffness(system, y, base):
    free = system.layout.free()  # the motor angle is held
    K = -system.force_jacobian(y, base)[np.ix_(free, free)]
    return 0.5 * (K + K.T)  # symmetric up to the finite-difference error


def _potential(system, info) -> float:
    """Elastic + contact energy + the potential of the (constant) gravity force, core units."""
    return (info.elastic_energy + info.contact_energy + info.interaction_energy
            - float(np.sum(system.gravity * info.x)))


def equilibrium(system, y0=None, base=None, tol: float = 1e-8, xtol: float = 1e-11,
                max_iter: int = 50, n_modes: int = 4) -> Equilibrium:
    """Newton iteration for ``G(y) = 0`` over the free beads and twist angles, from ``y0``
    (default: the rest state), with backtracking on the potential energy; then the lowest
    ``n_modes`` eigenvalues of the stiffness. ``tol`` is on ``max |G|`` in core force units
    ``A/L^2`` (the bead loads are ``G b/L ~ 0.1``; the stiff bonds' round-off floor is
    ~``1e-16 k_s L ~ 1e-8`` at N = 61), so the iteration also stops once a Newton step moves
    no coordinate by more than ``xtol`` (core length ``L``, or radians).

    Raises
    ------
    RuntimeError
        no convergence to ``tol`` in ``max_iter`` iterations (past a static limit point
        there is no nearby equilibrium).
    """
    n = system.layout.free()
    y = system.initial_y() if y0 is None else np.array(y0, float)
    base = system.frames0.copy() if base is None else base
    info = system.forces(y, base)
    base = info.frames
    res = float(np.max(np.abs(info.G[n])))
    it = 0
    dx = np.inf
    while res > tol and dx > xtol:
        if it >= max_iter:
            raise RuntimeError(f"static equilibrium: no convergence in {max_iter} Newton "
                               f"iterations (residual {res:.3g})")
        it += 1
        K = _stiffness(system, y, base)
        dy = np.linalg.solve(K, info.G[n])
        step = 1.0
        U0 = _potential(system, info)
        while True:  # backtracking on the potential energy, which Newton's step decreases
            y_try = y.copy()  # while K > 0 (the residual may grow: the stiff bonds' curvature)
            y_try[n] += step * dy
            info_try = system.forces(y_try, base)
            res_try = float(np.max(np.abs(info_try.G[n])))
            if _potential(system, info_try) <= U0 + 1e-12 or res_try < res or step < 1e-4:
                break
            step *= 0.5
        dx = float(np.max(np.abs(step * dy)))
        y, info, res = y_try, info_try, res_try
        base = info.frames
    K = _stiffness(system, y, base)
    w, v = np.linalg.eigh(K)
    return Equilibrium(y, base, res, it, w[:n_modes], v[:, :n_modes])


def critical_gravity(config, G_lo: float, G_hi: float, rtol: float = 1e-4, straight: bool = True,
                     max_iter: int = 60):
    """Static buckling threshold ``G_c`` by bisection in ``G`` on the sign of the lowest
    stiffness eigenvalue at the equilibrium, between a stable ``G_lo`` and an unstable
    ``G_hi``.

    ``straight``: the straight rest shape (:func:`straight_rod_system`, Greenhill's column);
    otherwise the config's own filament (its helix), continued from the stable side.
    Returns ``(G_c, G_lo, G_hi)`` with ``G_hi - G_lo <= rtol G_c``.

    Raises
    ------
    ValueError
        ``G_lo`` is not stable or ``G_hi`` not unstable.
    """
    def solve(G, start=None):
        y0, base = (None, None) if start is None else (start.y, start.base)
        return equilibrium(_system_at(config, G, straight), y0, base)

    lo = solve(G_lo)
    if not lo.stable:
        raise ValueError(f"G_lo = {G_lo} is not stable (lowest eigenvalue {lo.eigenvalues[0]:.3g})")
    try:
        hi_ok = not solve(G_hi, lo).stable
    except RuntimeError:  # no equilibrium near the stable branch: beyond a limit point
        hi_ok = True
    if not hi_ok:
        raise ValueError(f"G_hi = {G_hi} is stable")
    for _ in range(max_iter):
        if G_hi - G_lo <= rtol * 0.5 * (G_lo + G_hi):
            break
        G = 0.5 * (G_lo + G_hi)
        try:
            e = solve(G, lo)
            stable = e.stable
        except RuntimeError:
            stable = False
        if stable:
            G_lo, lo = G, e
        else:
            G_hi = G
    return 0.5 * (G_lo + G_hi), G_lo, G_hi


@dataclass
class StaticBranch:
    """Equilibria of a filament along increasing ``G`` (:func:`static_branch`).

    ``G``, ``tip_height`` (free end's z minus its z at G = 0, in L: the quantity the buckling
    criterion of docs/analysis.md thresholds at 0.15), ``tip_z``, ``tip_offset`` (distance from
    the body axis, L) and ``lowest_eigenvalue`` (core units) per point; the branch ends early
    where Newton finds no equilibrium near the previous one (``message``).
    """

    G: np.ndarray
    tip_z: np.ndarray
    tip_height: np.ndarray
    tip_offset: np.ndarray
    lowest_eigenvalue: np.ndarray
    message: str = ""

    def crossing(self, rise: float = 0.15) -> float:
        """The ``G`` at which the static rise of the free end first reaches ``rise`` (linear
        interpolation); nan if it does not within the branch."""
        h = self.tip_height
        above = np.nonzero(h >= rise)[0]
        if not len(above) or above[0] == 0:
            return math.nan
        i = above[0]
        return float(self.G[i - 1] + (rise - h[i - 1]) * (self.G[i] - self.G[i - 1]) / (h[i] - h[i - 1]))


def static_branch(config, G_values, straight: bool = False, max_iter: int = 200) -> StaticBranch:
    """Continue the static equilibrium of ``config``'s filament (motor at rest) through the
    increasing gravity numbers ``G_values`` (each solve starts from the previous one)."""
    G_values = np.asarray(sorted(float(g) for g in G_values))
    out = {k: [] for k in ("G", "tip_z", "tip_offset", "lowest")}
    prev, z0, msg = None, None, ""
    for G in G_values:
        s = _system_at(config, G, straight)
        try:
            e = equilibrium(s, *((prev.y, prev.base) if prev is not None else (None, None)),
                            max_iter=max_iter)
        except RuntimeError as exc:
            msg = f"G = {G:g}: {exc}"
            break
        x, _, _ = s.unpack(e.y)
        if z0 is None:
            z0 = s.x0[-1, 2]
        out["G"].append(G)
        out["tip_z"].append(x[-1, 2])
        out["tip_offset"].append(math.hypot(x[-1, 0], x[-1, 1]))
        out["lowest"].append(e.eigenvalues[0])
        prev = e
    tip_z = np.array(out["tip_z"])
    return StaticBranch(np.array(out["G"]), tip_z, tip_z - (z0 if z0 is not None else 0.0),
                        np.array(out["tip_offset"]), np.array(out["lowest"]), msg)
