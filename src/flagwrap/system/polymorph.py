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

**Coupling to the rod** (docs/polymorph.md, "Wiring"): each vertex's rest curvature and
twist follow its ``phi`` (:func:`~flagwrap.elasticity.polymorph.interpolate_rest` between
the two polymorphs' rest values on the rod's own chain, :func:`rest_pair`), rewritten into
the filament's rest arrays before every evaluation; the rod's elastic energy pushes on
``phi`` (``-dE_el/dphi``, :func:`~flagwrap.elasticity.polymorph.elastic_phi_gradient`), so the
axial moment tilts the double well (P2) through the rod's own twist. The stage solver's ``W``
keeps the rod's own block and the block's tridiagonal ``I + gamma h Mob (Hess E + diag
d2E_el/dphi2)``; the rod-state cross terms are left out, which a W-method allows (its order
holds for any ``W``; only the step-size control feels it).
"""

from __future__ import annotations

import numpy as np
import scipy.linalg as sla

from flagwrap.elasticity import _kernels as EK
from flagwrap.elasticity.polymorph import (PolymorphModel, total_energy,
                                           total_energy_grad, total_energy_hessian_bands,
                                           wall_profile)
from flagwrap.elasticity.rod import initial_frames, rest_state
from flagwrap.system.layout import DofLayout
from flagwrap.system.rod_system import RodSystem


def voronoi_lengths(l0) -> np.ndarray:
    """Each bead's share of the contour: half of each adjacent bond (P3's ``v_i``)."""
    l0 = np.asarray(l0, float)
    v = np.empty(len(l0) + 1)
    v[0], v[-1] = 0.5 * l0[0], 0.5 * l0[-1]
    v[1:-1] = 0.5 * (l0[:-1] + l0[1:])
    return v


def polymorph_geometry(config):
    """Polymorph B's helix ``(R_B, P_B, handedness_B)`` [m] for the configured filament, which
    is polymorph A: the library's ratios applied to the filament's own helix,
    ``R_B = R (R_b / R_a)``, ``P_B = P (P_b / P_a)``, the handedness flipped when the two
    library forms differ in it. A filament built with A's library geometry gets B's library
    geometry exactly; a scaled rig (e.g. the paper's macroscopic helix) keeps the ratios."""
    from flagwrap.params import _polymorph_library

    lib = _polymorph_library()  # parsed once per process
    pm, fil = config.polymorph, config.filament
    a, b = lib.polymorph(pm.polymorph_a), lib.polymorph(pm.polymorph_b)
    hand = fil.handedness
    if a.handedness.value != b.handedness.value:
        hand = "right" if hand == "left" else "left"
    return (fil.helix_radius * b.radius_um.value / a.radius_um.value,
            fil.pitch * b.pitch_um.value / a.pitch_um.value, hand)


def _angles(kbar):
    return np.arctan2(kbar[:, 1], kbar[:, 0])


def rest_pair(part, config):
    """The rest values ``(kbar_a, kbar_b, mbar_a, mbar_b, changes)`` of the filament ``part``
    in polymorph A (its own rest, the configured helix) and B (:func:`polymorph_geometry`),
    both in the material frame of A's chain: the material keeps the azimuth at which it
    bends. In the twist-free gauge the rod is built in, a uniform helix's rest curvature has
    the magnitude ``k`` and its angle advances by ``d`` per vertex (its discrete curvature and
    torsion on the chain's bond; medians over a helix's interior). B, carried in A's
    material frames with the curvature's angle kept, twists by ``c = d_B - d_A`` per vertex
    (B's rest twist is A's plus ``c``) and its rest curvature is A's times
    ``k_B cos(c/2) / k_A`` (the kernel measures the curvature in the average of the two
    bonds' material frames, which the twist turns ``c`` apart). The rod at ``phi = +1``
    relaxes to B's helix exactly (tested). ``changes`` (N,) bool: the vertices that transform, the
    filament's interior vertices on bonds of the nominal length, not a joint's (a hook is
    not flagellin) nor a lumped joint's angle-law vertex."""
    from flagwrap.geometry.helix import helix_positions

    rest = part.rest
    fil = config.filament
    L = fil.length
    b = fil.bond_length / L
    N = part.N
    changes = np.zeros(N, bool)
    nominal = np.abs(rest.l0 - b) < 1e-6 * b
    changes[1:-1] = nominal[:-1] & nominal[1:]
    changes &= ~rest.angle_law
    changes[:part.nc] = False  # the joint's held vertices
    mag_a = np.hypot(rest.kbar[:, 0], rest.kbar[:, 1])
    changes &= mag_a > 1e-12 * b
    kbar_a, mbar_a = rest.kbar.copy(), rest.mbar.copy()
    if not changes.any():
        return kbar_a, kbar_a.copy(), mbar_a, mbar_a.copy(), changes

    def uniform(R, P, hand):
        """A uniform helix's discrete rest ``(|kbar|, d alpha per vertex)`` on this bond."""
        n = max(9, min(N, 41))
        x = helix_positions(b * (n - 1), R / L, P / L, n, hand)
        r = rest_state(x, initial_frames(x), np.zeros(n - 1))
        k = r.kbar[2:-2]
        da = np.angle(np.exp(1j * np.diff(_angles(k))))
        return float(np.median(np.hypot(k[:, 0], k[:, 1]))), float(np.median(da))

    RB, PB, hand_b = polymorph_geometry(config)
    ka, da_a = uniform(fil.helix_radius, fil.pitch, fil.handedness)
    kb, da_b = uniform(RB, PB, hand_b)
    kbar_b, mbar_b = kbar_a.copy(), mbar_a.copy()
    # the twist c = da_b - da_a between a vertex's two bonds turns their material frames
    # apart, and the kernel's curvature, measured in their average, shrinks by cos(c/2)
    kbar_b[changes] *= kb * np.cos(0.5 * (da_b - da_a)) / ka
    mbar_b[changes] += da_b - da_a
    return kbar_a, kbar_b, mbar_a, mbar_b, changes


class PolymorphSystem(RodSystem):
    """``system`` (one filament: the lab-frame rig or a free swimmer) with the order block
    (module docstring), from ``system.config.polymorph`` or the core-unit ``barrier``,
    ``stiffness``, ``rate`` and initial profile ``order0`` (N,) given here.

    The block follows all of ``system``'s unknowns (``y = [system's y | order]``). Its
    methods add the block to ``system``'s own (``super()``): for a free swimmer
    (:class:`~flagwrap.system.swimmer.SwimmerSystem`) the instance is a
    :class:`PolymorphSwimmer`, whose next class is the swimmer's; in the turning frame a
    :class:`PolymorphRotating`. ``_rod`` is a view of
    ``system`` over its own unknowns, the stage solvers' system."""

    def __new__(cls, system, *args, **kwargs):
        from flagwrap.system.rotating import RotatingSystem
        from flagwrap.system.swimmer import SwimmerRotating, SwimmerSystem

        if cls is PolymorphSystem:
            if isinstance(system, SwimmerRotating):
                cls = PolymorphSwimmerRotating
            elif isinstance(system, SwimmerSystem):
                cls = PolymorphSwimmer
            elif isinstance(system, RotatingSystem):
                cls = PolymorphRotating
        return object.__new__(cls)

    def __init__(self, system, barrier=None, stiffness=None, rate=None, order0=None):
        if isinstance(system, PolymorphSystem):
            raise ValueError("PolymorphSystem: the system has an order block already")
        inner = next((c for c in type(self).__mro__[1:] if issubclass(c, RodSystem)
                      and not issubclass(c, PolymorphSystem)), RodSystem)
        if type(system) is not inner:
            raise ValueError(f"PolymorphSystem: a {type(system).__name__} is not supported "
                             "(the lab-frame rig, the turning frame or a free swimmer)")
        import copy
        import dataclasses

        rod = object.__new__(type(system))  # the system's own view over its own unknowns
        rod.__dict__.update(system.__dict__)
        self.__dict__.update(system.__dict__)  # the same buffers: a view
        self._rod = rod
        # every filament's rest arrays are rewritten from phi at every evaluation: views of
        # one buffer over all beads (so one vectorised write sets them all), owned here, so
        # the system it was made from keeps its fixed rest shapes
        pairs = [rest_pair(p, system.config) for p in system.parts]
        cat = np.concatenate
        self.kbar_a, self.kbar_b = cat([q[0] for q in pairs]), cat([q[1] for q in pairs])
        self.mbar_a, self.mbar_b = cat([q[2] for q in pairs]), cat([q[3] for q in pairs])
        #: (N,) bool over every filament's beads: the vertices that transform
        self.order_changes = cat([q[4] for q in pairs])
        self._kbar_now, self._mbar_now = self.kbar_a.copy(), self.mbar_a.copy()
        parts = []
        for p in system.parts:
            q = copy.copy(p)
            v = p.beads
            q.rest = dataclasses.replace(p.rest, kbar=self._kbar_now[v], mbar=self._mbar_now[v])
            parts.append(q)
        self.parts = rod.parts = parts
        #: ``d kbar/dphi``, ``d mbar/dphi`` (:func:`~flagwrap.elasticity.polymorph.rest_derivative`)
        self._kbar_ba, self._mbar_ba = self.kbar_b - self.kbar_a, self.mbar_b - self.mbar_a
        self.dkbar, self.dmbar = 0.5 * self._kbar_ba, 0.5 * self._mbar_ba
        self._cbend = cat([p.rest.cbend for p in parts])
        self._ctwist = cat([p.rest.ctwist for p in parts])
        # d2 E_el / dphi2 at each vertex, constant: the energy is quadratic in the rest values
        self.order_elastic_curvature = (self._cbend * np.sum(self.dkbar**2, axis=1)
                                        + self._ctwist * self.dmbar**2)
        n, nbond = self.N, self.N - len(parts)
        self._m1, self._m2 = np.empty((nbond, 3)), np.empty((nbond, 3))
        self._kb, self._kappa = np.zeros((n, 3)), np.zeros((n, 2))
        self._twist = np.zeros(n)
        pm = system.config.polymorph
        #: its ``Delta`` [1/L]: B's rest twist density minus A's on the transforming
        #: vertices (0 where nothing transforms); the tilt of (P2) at zero load
        #: ``-N_M Delta / 2`` is the wells' intrinsic difference, the load's part comes from
        #: the rod's own twist energy
        c = (self.mbar_b - self.mbar_a)[self.order_changes]  # every filament's the same
        delta = float(c[0] / self.bond) if c.size else 0.0
        W, K, G, NM = (pm.landscape(system.scales, delta) if pm.enabled
                       else (None, None, None, 0.0))
        W = W if barrier is None else float(barrier)
        K = K if stiffness is None else float(stiffness)
        G = (5.0 / W if G is None else G) if rate is None else float(rate)
        if pm.enabled and pm.rate is not None and rate is None \
                and G > pm.MAX_RATE_FACTOR * 5.0 / W:
            from flagwrap.errors import UserInputError

            most = pm.MAX_RATE_FACTOR * 5.0 / W * system.scales.omega / system.scales.force
            raise UserInputError(f"polymorph.rate must be in (0, {most:.3g}] 1/(N s) (1e6 times "
                                 f"the default 5 omega / W), got {pm.rate!r}")
        self.model = PolymorphModel(barrier=W, stiffness=K, delta_twist=delta, maxwell_torque=NM)
        self.order_rate = G
        #: each filament's Voronoi lengths and rest bonds, one after the other: (P3) on each
        #: filament's chain, no gradient energy between two filaments
        self.order_vor = cat([voronoi_lengths(p.rest.l0) for p in parts])
        self.order_bonds = cat([np.asarray(p.rest.l0, float) for p in parts])
        n = len(self.order_vor)
        self.layout = DofLayout([(b.name, b.kind, b.size) for b in system.layout.blocks]
                                + [("order", "order", n)])
        self.ny = self.layout.size
        self.sl_order = self.layout["order"]
        #: the integrators combine stage increments of the rod's unknowns apart from the
        #: block's (:func:`flagwrap.integrators.rosenbrock._combine`): with the block
        #: uncoupled, the rod then steps bit for bit as the fixed-shape rod
        self.stage_split = rod.ny
        self.n_inner = rod.ny
        #: the block's mobility ``Gamma / v_i`` (P8)
        self.order_mobility = G / self.order_vor
        if order0 is None:
            order0 = self.initial_order(pm) if pm.enabled else -np.ones(n)
        self.order0 = np.array(order0, float)
        if self.order0.shape != (n,):
            raise ValueError(f"PolymorphSystem: order0 must have {n} values")

    def initial_order(self, pm) -> np.ndarray:
        """``config.polymorph.initial``: uniform A (-1), uniform B (+1), or the wall (P4)
        centred at ``wall_position`` of each filament's rest contour, A at its motor."""
        n = len(self.order_vor)
        if pm.initial == "a":
            return -np.ones(n)
        if pm.initial == "b":
            return np.ones(n)
        out = np.empty(n)
        for p in self.parts:
            s = np.concatenate([[0.0], np.cumsum(p.rest.l0)])
            out[p.beads] = wall_profile(s, pm.wall_position * s[-1], self.model.wall_width)
        return out

    def _chains(self):
        """Each filament's ``(beads, bonds)`` slices in the block and in ``order_bonds``."""
        return [(p.beads, p.bonds) for p in self.parts]

    def order_energy(self, phi) -> float:
        """(P3) summed over the filaments."""
        return sum(total_energy(phi[v], self.model, 0.0, self.order_vor[v], self.order_bonds[e])
                   for v, e in self._chains())

    def order_energy_grad(self, phi) -> np.ndarray:
        """The gradient of :meth:`order_energy`."""
        out = np.empty(len(phi))
        for v, e in self._chains():
            out[v] = total_energy_grad(phi[v], self.model, 0.0, self.order_vor[v],
                                       self.order_bonds[e])
        return out

    # state ---------------------------------------------------------------------------------
    def pack(self, x, theta, phi, *pose, order=None, **kw) -> np.ndarray:
        """``y`` from the system's own packing (the rod's ``x``, ``theta``, motor angle, a
        swimmer's pose) and the order parameters (default: the initial profile)."""
        y = np.empty(self.ny)
        y[:self.n_inner] = self._rod.pack(x, theta, phi, *pose, **kw)
        y[self.sl_order] = self.order0 if order is None else order
        return y

    def order(self, y) -> np.ndarray:
        """The order parameters (N,), a view of ``y``."""
        return y[self.sl_order]

    def order_record(self, y) -> np.ndarray:
        """What a trajectory frame keeps of the block: a copy of the order parameters."""
        return y[self.sl_order].copy()

    # forces and mobility ----------------------------------------------------------------------
    def set_rest(self, y) -> None:
        """Write the rest curvature and twist at ``y``'s order parameters into the
        filament's rest arrays (``a + (phi + 1)/2 (b - a)``, bit for bit ``a`` where the two
        polymorphs coincide): every evaluation of the rod at ``y`` starts here. The
        filaments' rest arrays are views of the two buffers written here."""
        t = 0.5 * (y[self.sl_order] + 1.0)
        np.multiply(t[:, None], self._kbar_ba, out=self._kbar_now)
        np.add(self._kbar_now, self.kbar_a, out=self._kbar_now)
        np.multiply(t, self._mbar_ba, out=self._mbar_now)
        np.add(self._mbar_now, self.mbar_a, out=self._mbar_now)

    def elastic_order_gradient(self, info) -> np.ndarray:
        """``dE_el/dphi_i`` at the state of ``info`` (rest set at its ``phi``):
        ``-cbend_i (kappa_i - kbar_i).dkbar_i - ctwist_i (m_i - mbar_i) dmbar_i``
        (:func:`~flagwrap.elasticity.polymorph.elastic_phi_gradient`), with the material
        curvatures and twists the kernel measures (:mod:`flagwrap.elasticity._kernels`)."""
        fr, th = info.frames, info.theta
        for v, e in self._chains():  # each filament's own chain of bonds and vertices
            EK.material_frames(fr.t[e], fr.d1[e], th[e], self._m1[e], self._m2[e])
            EK.curvatures(fr.t[e], self._m1[e], self._m2[e], self._kb[v], self._kappa[v])
            m = self._twist[v]
            m[1:-1] = th[e][1:] - th[e][:-1] + fr.rt[v][1:-1]
        out = -self._cbend * np.sum((self._kappa - self._kbar_now) * self.dkbar, axis=1)
        out -= self._ctwist * (self._twist - self._mbar_now) * self.dmbar
        return out

    def forces(self, y, base):
        """The rod's forces at the rest shape of ``y``'s ``phi`` and the block's
        ``G = -dE/dphi`` of (P3) plus the rod's elastic energy."""
        self.set_rest(y)
        info = super().forces(y, base)
        phi = y[self.sl_order]
        info.G[self.sl_order] = -self.order_energy_grad(phi)
        info.G[self.sl_order] -= self.elastic_order_gradient(info)
        info.polymorph_energy = self.order_energy(phi)
        return info

    def apply_mobility(self, y, G, single: bool = False, **kw) -> np.ndarray:
        out = super().apply_mobility(y, G, single, **kw)
        np.multiply(self.order_mobility, G[self.sl_order], out=out[self.sl_order])
        return out

    def local_mobility_diagonal(self) -> np.ndarray:
        d = np.zeros(self.ny)
        inner = self._rod.local_mobility_diagonal()
        d[:len(inner)] = inner
        d[self.sl_order] = self.order_mobility
        return d

    def mobility_matrix(self, y) -> np.ndarray:
        Mob = np.zeros((self.ny, self.ny))
        inner = self._rod.mobility_matrix(y[:self.n_inner])
        Mob[:len(inner), :len(inner)] = inner
        i = np.arange(self.sl_order.start, self.sl_order.stop)
        Mob[i, i] = self.order_mobility
        return Mob

    # Jacobian and stage solves ---------------------------------------------------------
    def order_jacobian_coo(self, y):
        """``-Hess E`` of the block (P3) as triplets over ``y``."""
        main, off = self.order_hessian_bands(y)
        i0 = self.sl_order.start
        d = i0 + np.arange(len(main))
        o = d[:-1]
        rows = np.concatenate([d, o, o + 1])
        cols = np.concatenate([d, o + 1, o])
        return rows, cols, -np.concatenate([main, off, off])

    def order_hessian_bands(self, y):
        """The block's Hessian (tridiagonal): (P3)'s plus the rod's ``d2E_el/dphi_i2``; the
        off-diagonal is 0 between two filaments' chains."""
        phi = y[self.sl_order]
        main = np.empty(len(phi))
        off = np.zeros(len(phi) - 1)
        for v, e in self._chains():
            mv, ov = total_energy_hessian_bands(phi[v], self.model, self.order_vor[v],
                                                self.order_bonds[e])
            main[v] = mv
            off[v.start:v.stop - 1] = ov
        main += self.order_elastic_curvature
        return main, off

    def force_jacobian_coo(self, y, base, G0=None, delta=None, nonlocal_terms: bool = True,
                           stage: bool = False):
        """The rod's block (at the rest shape of ``y``'s ``phi``) and the order block; the
        cross terms are left out (module docstring)."""
        self.set_rest(y)
        r, c, v = self._rod.force_jacobian_coo(y[:self.n_rod], base,
                                               None if G0 is None else G0[:self.n_rod],
                                               delta, nonlocal_terms, stage)
        ro, co, vo = self.order_jacobian_coo(y)
        return np.concatenate([r, ro]), np.concatenate([c, co]), np.concatenate([v, vo])

    def make_w(self, kind, y, base, G0, gamma_h, err_scale=None, omega=None):
        """The system's own stage solver on its own unknowns (bit for bit the fixed
        rod's, at the rest shape of ``y``'s ``phi``) and the block's tridiagonal
        ``I + gamma_h diag(Gamma / v) Hess E``: ``W`` block diagonal, the cross terms left
        out (module docstring)."""
        from flagwrap.integrators.linear import make_w

        self.set_rest(y)
        n = self.n_inner
        rod_w = make_w(kind, self._rod, y[:n], base, G0[:n], gamma_h,
                       None if err_scale is None else err_scale[:n], omega)
        main, off = self.order_hessian_bands(y)
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


def _swimmer_class():
    from flagwrap.system.swimmer import SwimmerSystem

    class PolymorphSwimmer(PolymorphSystem, SwimmerSystem):
        """A free swimmer (:class:`~flagwrap.system.swimmer.SwimmerSystem`) whose filament
        carries the order block: ``y = [filament | pose | order]``; the swimmer's stage
        solver on its own unknowns and the block's tridiagonal solve (:meth:`make_w`).

        The swimmer keeps the last geometry and the last pose's body solve in caches whose
        arrays are shared buffers (``M_fb`` is built into one): both views must read one
        cache, else one view's rebuild overwrites what the other's cache still claims.
        Both go through the stage solver's view ``_rod``."""

        def _geometry(self, y):
            return self._rod._geometry(y[:self.n_inner])

        def _body(self, y):
            return self._rod._body(y[:self.n_inner])

        def mobility_matrix(self, y, *args, **kwargs):
            raise NotImplementedError(
                "PolymorphSwimmer.mobility_matrix: the swimmer's own matrix covers the "
                "filament's unknowns only (its stage solver, SwimmerW, builds the pose rows)")

    return PolymorphSwimmer


PolymorphSwimmer = _swimmer_class()


def _swimmer_rotating_class():
    from flagwrap.system.swimmer import SwimmerRotating

    class PolymorphSwimmerRotating(PolymorphSystem, SwimmerRotating):
        """A free swimmer in its motor's frame (:class:`~flagwrap.system.swimmer.
        SwimmerRotating`) with the order block: ``y = [filament | pose | order]``, the
        block as on :class:`PolymorphSwimmer` (its caches read through the stage solver's
        view). The order parameters are scalars carried by the material: the frame adds no
        term to their rate."""

        _geometry = PolymorphSwimmer._geometry
        _body = PolymorphSwimmer._body
        mobility_matrix = PolymorphSwimmer.mobility_matrix

    return PolymorphSwimmerRotating


PolymorphSwimmerRotating = _swimmer_rotating_class()


def _rotating_class():
    from flagwrap.system.rotating import RotatingSystem

    class PolymorphRotating(PolymorphSystem, RotatingSystem):
        """The rig in the frame turning with its motor (:class:`~flagwrap.system.rotating.
        RotatingSystem`) with the order block. The order parameters are scalars carried by
        the material, so the frame adds no term to their rate; the forces on them read
        curvatures and twists, which the rotation leaves unchanged."""

    return PolymorphRotating


PolymorphRotating = _rotating_class()


class PolymorphFrame:
    """A polymorphic filament (:class:`PolymorphSystem` over the lab-frame ``RodSystem`` or
    a free :class:`~flagwrap.system.swimmer.SwimmerSystem`) in the frame turning with its
    motor at ``omega``, for linear stability (:mod:`flagwrap.stability`): the interface of
    :class:`~flagwrap.system.rotating.RotatingFrame`, with the order parameters among the
    unknowns.

    ``z = [z_rod, order]``: ``z_rod`` the unknowns of the system's own turning frame (the
    rig's :class:`~flagwrap.system.rotating.RotatingFrame`: the lab state without the motor
    angle; a free swimmer's :class:`~flagwrap.system.swimmer.SwimmerFrame`: the filament's
    in body axes, the pose not an unknown), then the order block. The order parameters get
    no rotation term (scalars carried by the material), and they load no part of the fluid
    (their forces move ``phi`` only), so the swimmer's body motion does not see them
    directly. Their kinetics scales with the Machin number as the mobilities do: ``Gamma``
    fixed in SI, so its core value goes as ``1/M`` along a continuation in ``M`` (the steady
    states do not depend on ``Gamma``, only the order's eigenvalues do).

    The Jacobian is exact, cross terms included, as linear stability needs (the time
    stepper's ``W`` leaves them out). The rod's block is the system's own turning-frame
    Jacobian at the order parameters held fixed (its frame's ``jacobian`` on the system's
    rod view). The other blocks are central differences of the generalized forces over the
    order columns (times the rod frame's mobility, :meth:`RotatingFrame.mobility_product`)
    and of the order's forces over the rod's columns (times the block's mobility); no
    mobility depends on ``phi``.
    """

    def __init__(self, system, omega: float, blob_body: bool = False):
        from flagwrap.system.rotating import RotatingFrame
        from flagwrap.system.swimmer import SwimmerFrame, SwimmerSystem

        rod = getattr(system, "_rod", None)
        if not isinstance(system, PolymorphSystem) or type(rod) not in (RodSystem,
                                                                        SwimmerSystem):
            raise ValueError("PolymorphFrame: a PolymorphSystem over the lab-frame RodSystem "
                             "or a SwimmerSystem")
        self.system = system
        self.rod_frame = (SwimmerFrame(rod, omega) if isinstance(rod, SwimmerSystem)
                          else RotatingFrame(rod, omega, blob_body=blob_body))
        self.omega = self.rod_frame.omega
        self.axis = self.rod_frame.axis
        self.n_rod = self.rod_frame.n  # the rod's unknowns in z
        self.n = self.n_rod + (system.sl_order.stop - system.sl_order.start)
        self.n3 = 3 * system.nb

    def full(self, z) -> np.ndarray:
        """The state vector of the rod frame's :meth:`full` (``phi = 0``, where the frames
        coincide; a swimmer's pose at the origin) with the order block appended."""
        s, nr = self.system, self.n_rod
        z = np.asarray(z, float)
        y = np.empty(s.ny)
        y[:s.n_inner] = self.rod_frame.full(z[:nr])
        y[s.sl_order] = z[nr:]
        return y

    def reduce(self, y) -> np.ndarray:
        """The unknowns ``z`` of a state ``y`` (a copy): :meth:`full`'s inverse."""
        y = np.asarray(y, float)
        return np.concatenate([y[:self.n_rod], y[self.system.sl_order]])

    def initial_state(self, t_max: float = 5000.0, tol: float = 1e-9):
        """``(z, base)``: the filament at rest with its order parameters relaxed, the start of
        a branch. The configured initial state is not a fixed point where the wells are
        tilted (``maxwell_torque``) or the rod pushes on ``phi``: ``phi`` settles off +-1, the
        rest shape follows, and the rod moves by up to ~0.1 L (measured on the E. coli
        case), outside Newton's basin. So the system is first relaxed in time with the motor
        still (ROS34PW2 at tol 1e-8) until no unknown moves faster than ``tol`` per unit
        time, or ``t_max``."""
        from flagwrap.integrators import REGISTRY

        s = self.system
        integ = REGISTRY["ros34pw2"](1e-8)
        y = s.initial_y()
        info = s.forces(y, s.frames0.copy())
        t, h = 0.0, 1e-3
        while t < t_max and np.abs(s.velocity(y, info, 0.0)).max() > tol:
            r = integ.step(s, y, info.frames, info, h, 0.0)
            if r.accepted:
                t += h
                y, info = r.y, r.info
            h = min(r.h_next, t_max - t)
        return self.reduce(y), info.frames

    def scale(self, machin: float | None) -> float:
        return self.rod_frame.scale(machin)

    def velocity(self, z, base, machin: float | None = None):
        """``dz/dt`` (turning frame) and the :class:`ForceInfo` at ``z``."""
        from flagwrap.system.rotating import subtract_rotation

        s = self.system
        y = self.full(z)
        info = s.forces(y, base)
        f = s.apply_mobility(y, info.G)
        f *= self.scale(machin)
        subtract_rotation(f, s, info, self.omega, self.axis, self.rod_frame._A)
        return self.reduce(f), info

    def jacobian(self, z, base, machin: float | None = None, info=None) -> np.ndarray:
        """``d(dz/dt)/dz`` (n, n), dense (class docstring)."""
        s = self.system
        y = self.full(z)
        nr, n = self.n_rod, self.n
        so = s.sl_order
        h = s.fd_step
        # dG/dz by central differences over every unknown of z (the rod's come first, the
        # order block last): the cross blocks are read from it
        cols = np.concatenate([np.arange(nr), np.arange(so.start, so.stop)])
        dG = np.empty((s.ny, n))
        yp = y.copy()
        for j, k in enumerate(cols):
            yp[k] = y[k] + h
            gp = s.forces(yp, base).G
            yp[k] = y[k] - h
            gm = s.forces(yp, base).G
            yp[k] = y[k]
            dG[:, j] = (gp - gm) / (2.0 * h)
        dG_do, dGo_dr = dG[:, nr:], dG[so, :nr]  # d G / d order, d G_order / d rod
        info = s.forces(y, base)  # the rest at y's own order parameters, for the rod's block
        J = np.empty((n, n))
        J[:nr, :nr] = self.rod_frame.jacobian(z[:nr], base, machin, info)
        c = self.scale(machin)
        J[:nr, nr:] = c * self.rod_frame.mobility_product(y[:s.n_inner], dG_do[:nr])
        m = c * s.order_mobility[:, None]
        J[nr:, :nr] = m * dGo_dr
        J[nr:, nr:] = m * dG_do[so]
        return J
