"""The polymorphic filament as a transformation of the system: an order parameter ``phi``
per bead (docs/polymorph.md) appended to the state vector as the layout block ``"order"``.

``y = [x_free, theta_free, motor angle | order (N)]``: the filament's unknowns are the first
``n_rod`` (the fused kernel, the rod's stage solvers and everything that reads the rod see
them unchanged), the order parameters the last ``N`` (one per bead, clamped beads included:
they are material of the filament). Like :class:`~flagwrap.system.rotating.RotatingSystem`
and :class:`~flagwrap.system.swimmer.SwimmerSystem`, :class:`PolymorphSystem` is a
``RodSystem`` over the same data (it takes the system's attributes), with the methods that
differ overridden.

Dynamics of the block: the energy (P3) with Voronoi lengths ``v_i`` (half a bond at the
ends) and rest bond lengths ``l_j``,

    E = sum_i v_i W f(phi_i) + sum_j K / (2 l_j) (phi_{j+1} - phi_j)^2,                  (P3)

its generalized force ``G_i = -dE/dphi_i`` and the first-order (model A) kinetics

    dphi_i/dt = (Gamma / v_i) G_i,                                                        (P8)

whose continuum limit is ``phi_t = -Gamma (W f'(phi) - K phi_ss)``: a uniform well relaxes
at the rate ``2 Gamma W`` (``f''(+-1) = 2``), a wall of width ``w = sqrt(2 K / W)`` (P4) is
a fixed point. The block's Jacobian is ``-Hess E`` (tridiagonal,
:func:`~flagwrap.elasticity.polymorph.total_energy_hessian_bands`) and its mobility
``diag(Gamma / v_i)``.

**Not wired yet** (docs/polymorph.md, "Wiring"): the rod's rest curvature and twist do not
follow ``phi`` and the rod's elastic energy does not push on it (``elastic_phi_gradient``),
so the block relaxes on its own and the rod moves exactly as the fixed-shape rod; the stage
solver is the rod's own on the first ``n_rod`` unknowns plus a tridiagonal solve of the
block (``W`` is block diagonal while the two are uncoupled).
"""

from __future__ import annotations

import numpy as np
import scipy.linalg as sla

from flagwrap.elasticity.polymorph import (PolymorphModel, total_energy,
                                           total_energy_grad, total_energy_hessian_bands,
                                           wall_profile)
from flagwrap.system.layout import DofLayout
from flagwrap.system.rod_system import RodSystem


def voronoi_lengths(l0) -> np.ndarray:
    """Each bead's share of the contour: half of each adjacent bond (P3's ``v_i``)."""
    l0 = np.asarray(l0, float)
    v = np.empty(len(l0) + 1)
    v[0], v[-1] = 0.5 * l0[0], 0.5 * l0[-1]
    v[1:-1] = 0.5 * (l0[:-1] + l0[1:])
    return v


class PolymorphSystem(RodSystem):
    """``system`` (one filament, lab frame) with the order block (module docstring), from
    ``system.config.polymorph`` or the core-unit ``barrier``, ``stiffness``, ``rate`` and
    initial profile ``order0`` (N,) given here."""

    def __init__(self, system, barrier=None, stiffness=None, rate=None, order0=None):
        if len(system.parts) != 1 or system.ny != system.n_rod:
            raise ValueError("PolymorphSystem: one filament without a free body")
        rod = object.__new__(RodSystem)  # the rod's own view: its stage solvers see n_rod
        rod.__dict__.update(system.__dict__)
        self.__dict__.update(system.__dict__)  # the same parts and buffers: a view
        self._rod = rod
        pm = system.config.polymorph
        W, K, G = pm.core(system.scales) if pm.enabled else (None, None, None)
        W = W if barrier is None else float(barrier)
        K = K if stiffness is None else float(stiffness)
        G = (5.0 / W if G is None else G) if rate is None else float(rate)
        self.model = PolymorphModel(barrier=W, stiffness=K, delta_twist=0.0)
        self.order_rate = G
        l0 = self.parts[0].rest.l0
        self.order_vor = voronoi_lengths(l0)
        self.order_bonds = np.asarray(l0, float)
        n = len(self.order_vor)
        self.layout = DofLayout([(b.name, b.kind, b.size) for b in system.layout.blocks]
                                + [("order", "order", n)])
        self.ny = self.layout.size
        self.sl_order = self.layout["order"]
        #: the integrators combine stage increments of the rod's unknowns apart from the
        #: block's (:func:`flagwrap.integrators.rosenbrock._combine`): with the block
        #: uncoupled, the rod then steps bit for bit as the fixed-shape rod
        self.stage_split = self.n_rod
        #: the block's mobility ``Gamma / v_i`` (P8)
        self.order_mobility = G / self.order_vor
        if order0 is None:
            order0 = self.initial_order(pm) if pm.enabled else -np.ones(n)
        self.order0 = np.array(order0, float)
        if self.order0.shape != (n,):
            raise ValueError(f"PolymorphSystem: order0 must have {n} values")

    def initial_order(self, pm) -> np.ndarray:
        """``config.polymorph.initial``: uniform A (-1), uniform B (+1), or the wall (P4)
        centred at ``wall_position`` of the rest contour, A at the motor."""
        n = len(self.order_vor)
        if pm.initial == "a":
            return -np.ones(n)
        if pm.initial == "b":
            return np.ones(n)
        s = np.concatenate([[0.0], np.cumsum(self.order_bonds)])
        return wall_profile(s, pm.wall_position * s[-1], self.model.wall_width)

    # state ---------------------------------------------------------------------------------
    def pack(self, x, theta, phi, order=None) -> np.ndarray:
        """``y`` from the rod's ``x``, ``theta``, motor angle and the order parameters
        (default: the initial profile)."""
        y = np.empty(self.ny)
        y[:self.n_rod] = RodSystem.pack(self._rod, x, theta, phi)
        y[self.sl_order] = self.order0 if order is None else order
        return y

    def order(self, y) -> np.ndarray:
        """The order parameters (N,), a view of ``y``."""
        return y[self.sl_order]

    # forces and mobility ----------------------------------------------------------------------
    def forces(self, y, base):
        """The rod's forces (its rows computed as the rod's, the block's zeroed by the
        fused evaluation) and the block's ``G = -dE/dphi`` (P3)."""
        info = RodSystem.forces(self, y, base)
        phi = y[self.sl_order]
        info.G[self.sl_order] = -total_energy_grad(phi, self.model, 0.0, self.order_vor,
                                                   self.order_bonds)
        info.polymorph_energy = total_energy(phi, self.model, 0.0, self.order_vor,
                                             self.order_bonds)
        return info

    def apply_mobility(self, y, G, single: bool = False) -> np.ndarray:
        out = RodSystem.apply_mobility(self, y, G, single)
        np.multiply(self.order_mobility, G[self.sl_order], out=out[self.sl_order])
        return out

    def local_mobility_diagonal(self) -> np.ndarray:
        d = np.zeros(self.ny)
        d[:self.n_rod] = RodSystem.local_mobility_diagonal(self._rod)
        d[self.sl_order] = self.order_mobility
        return d

    def mobility_matrix(self, y) -> np.ndarray:
        Mob = np.zeros((self.ny, self.ny))
        Mob[:self.n_rod, :self.n_rod] = RodSystem.mobility_matrix(self._rod, y[:self.n_rod])
        i = np.arange(self.sl_order.start, self.sl_order.stop)
        Mob[i, i] = self.order_mobility
        return Mob

    # Jacobian and stage solves ---------------------------------------------------------
    def order_jacobian_coo(self, y):
        """``-Hess E`` of the block (P3) as triplets over ``y``."""
        main, off = total_energy_hessian_bands(y[self.sl_order], self.model, self.order_vor,
                                               self.order_bonds)
        i0 = self.sl_order.start
        d = i0 + np.arange(len(main))
        o = d[:-1]
        rows = np.concatenate([d, o, o + 1])
        cols = np.concatenate([d, o + 1, o])
        return rows, cols, -np.concatenate([main, off, off])

    def force_jacobian_coo(self, y, base, G0=None, delta=None, nonlocal_terms: bool = True):
        r, c, v = RodSystem.force_jacobian_coo(self._rod, y[:self.n_rod], base,
                                               None if G0 is None else G0[:self.n_rod],
                                               delta, nonlocal_terms)
        ro, co, vo = self.order_jacobian_coo(y)
        return np.concatenate([r, ro]), np.concatenate([c, co]), np.concatenate([v, vo])

    def make_w(self, kind, y, base, G0, gamma_h, err_scale=None, omega=None):
        """The rod's own stage solver on the first ``n_rod`` unknowns (bit for bit the fixed
        rod's) and the block's tridiagonal ``I + gamma_h diag(Gamma / v) Hess E``: ``W`` is
        block diagonal while rod and state are uncoupled."""
        from flagwrap.integrators.linear import make_w

        n = self.n_rod
        rod_w = make_w(kind, self._rod, y[:n], base, G0[:n], gamma_h,
                       None if err_scale is None else err_scale[:n], omega)
        main, off = total_energy_hessian_bands(y[self.sl_order], self.model, self.order_vor,
                                               self.order_bonds)
        m = gamma_h * self.order_mobility
        ab = np.zeros((3, len(main)))
        ab[0, 1:] = m[:-1] * off  # row i, column i + 1
        ab[1] = 1.0 + m * main
        ab[2, :-1] = m[1:] * off  # row i + 1, column i
        return _BlockW(rod_w, ab, n)


class _BlockW:
    """``W = blockdiag(W_rod, W_order)``: the rod's solver and a tridiagonal solve."""

    def __init__(self, rod_w, ab, n):
        self.rod_w, self.ab, self.n = rod_w, ab, n

    def solve(self, rhs):
        out = np.empty(len(rhs))
        out[:self.n] = self.rod_w.solve(rhs[:self.n])
        out[self.n:] = sla.solve_banded((1, 1), self.ab, rhs[self.n:], check_finite=False)
        return out
