"""A free-swimming cell: a force- and torque-free no-slip body, its motor and its filament.

The equations are stepped in the frame of the body (``body.motion = "free"``). There the
body's blobs stand still, so their RPY matrix ``M_bb`` and its Cholesky factor are computed
once, and the motor's joint is the fixed rig's, turning at the motor's rate *relative to the
body*. The body moves with velocity ``U`` and angular velocity ``Omega`` (body axes, about
the body's reference point, the pole where the motor sits), and a point at ``x'`` in body
coordinates moves in the body frame at its lab velocity less the rigid motion:

    dx'/dt = v' - U - Omega x x',        dtheta'/dt = tau / zeta - Omega . t'

(the twist term as in :mod:`flagwrap.system.rotating`: a rigid rotation turns the material
frame about ``t`` at ``Omega . t`` against the transported reference frame).

**The mobility problem** (rigid multiblob, Usabiaga et al. 2016, Sec. 3, with the filament's
beads as free particles): bead forces ``F`` and twist torques ``tau`` are the generalized
forces ``G = -dU/dy`` of the free unknowns. The body (the cell, the rotor and the motor's
clamped beads, one rigid object with a motor inside) carries the load ``-S G``: the energy is
invariant under a rigid motion of everything, so what the free beads and bonds feel, the body
feels with the opposite sign (``S G = [sum F; sum x' x F + sum tau t]``). The blobs' forces
``lambda`` hold the surface to the rigid motion ``K V``, ``V = [U; Omega]``::

    M_bb lambda + M_bf F = K V,     K^T lambda = -S G      (force and torque balance)

so with ``E = K^T M_bb^-1 M_bf`` (6 x 3n) and ``N = (K^T M_bb^-1 K)^-1`` (the body's
mobility) ``V = N (E - S) G`` and the beads move at ``v' = (M_ff - M_fb M_bb^-1 M_bf) F +
E^T V``. The whole map ``G -> dy/dt`` is ``A G`` with

    A = A_fixed + (E - S)^T N (E - S),

``A_fixed`` the fixed no-slip body's mobility (:class:`~flagwrap.body.fixed_mobility.
FixedBodyMobility`) and the rank-6 term the body's motion: symmetric, positive
semidefinite, and the total force and torque on the fluid vanish (``K^T lambda + S G = 0``).
The twist torques act on the fluid locally (the bond's rotational drag), as in the rig.

The body's pose (lab position ``X`` of its reference point and unit quaternion ``q``, body to
lab) is carried in ``y`` after the filament's unknowns: ``dX/dt = R(q) U``, ``dq/dt =
q (0, Omega) / 2``. In free space nothing depends on the pose (no gravity on a free cell),
so the stage solver ``W`` is block lower triangular: the filament's ``I - gamma h A J``
(:class:`SwimmerW`), and the pose's rows ``-gamma h P J`` beside the identity, ``P`` the pose
rates per generalized force. Those rows matter: the pose is driven by the filament's stiff
modes, and without them its stages integrate those modes explicitly and the step controller
halves the step. Beside a wall or in a tube the contacts depend on the pose: ``W`` keeps the
body's blobs' contact stiffness in its pose block (:meth:`SwimmerSystem.pose_stiffness`)
and the beads' in the filament's block at the step's pose; how a bead's contact force
changes as the whole cell moves (the block above the pose's) is left out, so ``W`` stays
block lower triangular (the W-method keeps its order for any ``W``). Run
files are written in the lab frame (:meth:`record_view`) and carry the body's pose and
velocities (:meth:`body_record`).
"""

from __future__ import annotations

import math

import numpy as np
import scipy.linalg as sla

from flagwrap.body.multiblob import geometric_matrix
from flagwrap.body.solver import LaggedScreening
from flagwrap.geometry.frames import quaternion_matrix
from flagwrap.hydrodynamics.polydisperse import rpy_cross_block
from flagwrap.integrators.linear import KAPPA, KrylovW
from flagwrap.system.layout import DofLayout
from flagwrap.system.rod_system import RodSystem
from flagwrap.system.rotating import (AtReferenceAngle, RotatingFrame, check_rotating_frame,
                                      cross_matrix, subtract_rotation)


#: ``numerics.linear_solver = "auto"`` on a free cell: the matrix-free stage solver above
#: this many filament unknowns (speed motors). Measured per motor turn (benchmarks/bundle.py,
#: docs/bundle.md): 3 flagella, 958 unknowns, dense 43.4 s and Krylov 41.5 s; 4 flagella, 1275,
#: dense 167 s and Krylov 65 s: the crossover lies between.
AUTO_KRYLOV_NY = 1100


def quaternion_rate_matrix(q) -> np.ndarray:
    """``Q(q)`` (4, 3) with ``q (0, Omega) = Q(q) Omega``, so that :func:`quaternion_rate` is
    ``Q(q) Omega / 2``."""
    w, x, y, z = q
    return np.array([[-x, -y, -z], [w, -z, y], [z, w, -x], [-y, x, w]])


def quaternion_rate(q, omega_body) -> np.ndarray:
    """``dq/dt = q (0, Omega) / 2`` for the body-frame angular velocity ``Omega``."""
    w, x, y, z = q
    a, b, c = omega_body
    return 0.5 * np.array([-x * a - y * b - z * c, w * a + y * c - z * b,
                           w * b + z * a - x * c, w * c + x * b - y * a])


class SwimmerSystem(RodSystem):
    """A :class:`~flagwrap.system.rod_system.RodSystem` (in the body frame, free-space bead
    mobility) with a force- and torque-free no-slip body (module docstring).

    ``SwimmerSystem(system, blobs, blob_radii)`` is a transformation of ``system``, not a
    wrapper: the same parts, mobility and interactions (shared, not copied) with one more
    part, the free body, whose pose ``[X (3), q (4)]`` follows the filaments' unknowns in the
    layout (``n_rod`` of them, ``ny = n_rod + 7``), and the equations of the body's frame.
    What differs from the fixed rig (the mobility, the stage solver, packing with a pose,
    the lab view) is overridden here; everything else is ``RodSystem``'s own method on this
    layout. ``blobs``, ``blob_radii``: the body's surface in body coordinates (core units).
    """

    def __init__(self, system, blobs, blob_radii, solver: str = "direct", boundary=None,
                 contact=None):
        from flagwrap.body.solver import make_blob_solver

        if not system.mobility.long_range or getattr(system.mobility, "backend", "") != "direct":
            raise ValueError("SwimmerSystem needs the filament's free-space direct RPY mobility")
        if np.any(system.gravity):
            raise ValueError("SwimmerSystem: gravity on a free cell is not modelled")
        if system.ny != system.n_rod:
            raise ValueError("SwimmerSystem: the system has a free body already")
        self.__dict__.update(system.__dict__)  # the same parts and buffers: a view
        self.blobs = np.ascontiguousarray(blobs, dtype=np.float64)
        self.blob_radii = np.ascontiguousarray(np.broadcast_to(blob_radii, (len(self.blobs),)),
                                               dtype=np.float64)
        self._solver = make_blob_solver(solver, self.blobs, self.blob_radii)
        self.K = geometric_matrix(self.blobs)
        self._MinvK = self._solver.solve(self.K)  # (3 n_blob, 6)
        #: the body's own mobility (K^T M_bb^-1 K)^-1, viscosity 1, about the reference point
        R = self.K.T @ self._MinvK
        self.body_mobility = np.linalg.inv(0.5 * (R + R.T))
        s = system
        #: the filaments' unknowns (``n_rod``), before the pose
        self.n_in = s.n_rod
        self.layout = DofLayout([(b.name, b.kind, b.size) for b in s.layout.blocks]
                                + [("body_x", "position", 3), ("body_q", "angle", 4)])
        self.ny = self.layout.size
        self.sl_X = self.layout["body_x"]
        self.sl_q = self.layout["body_q"]
        self._cross = np.empty((3 * s.nb, 3 * len(self.blobs)))
        # its own M_fb builder: the lagged screening must not overwrite the kept geometry's
        self._lagged = LaggedScreening(
            self._solver, self.blobs,
            lambda xf: rpy_cross_block(xf, system.radius, self.blobs, self.blob_radii))
        self._geometry_y = None
        self._a_buffers = None
        #: a fixed no-slip boundary, a plane or a tube, as the body sees it
        #: (:mod:`flagwrap.body.boundaries`), or None: the blobs move against it, so the
        #: body's blob matrix, its mobility and every cross block depend on the pose and are
        #: rebuilt per pose (:meth:`_body`); ``contact`` the steric law the beads and the
        #: body's blobs meet it with (a :class:`~flagwrap.interactions.wall._BoundaryContact`)
        self.boundary = boundary
        self._boundary_contact = contact
        #: the lab-frame plane (``[[wall]]``), or None
        self.wall = boundary.wall if boundary is not None and boundary.kind == "wall" else None
        self._body_cache = (None, None)
        #: the filament's own contact with the boundary (the inner system's interaction):
        #: placed at each state's pose before its forces (:meth:`forces`)
        self._bead_contacts = [it for it in self.interactions
                               if getattr(it, "name", "") in ("wall contact", "tube contact")]

    # state ---------------------------------------------------------------------------------
    def pack(self, x, theta, phi, X=(0.0, 0.0, 0.0), q=(1.0, 0.0, 0.0, 0.0)) -> np.ndarray:
        """``y`` from the beads ``x`` and twist angles in the body frame, the motor angle(s)
        and the body's pose (lab position ``X`` of its reference point, unit quaternion ``q``
        body -> lab; default: at the origin, unturned)."""
        y = np.empty(self.ny)
        y[:self.n_in] = RodSystem.pack(self, x, theta, phi)[:self.n_in]
        y[self.sl_X] = X
        y[self.sl_q] = q
        return y

    def pose(self, y) -> tuple[np.ndarray, np.ndarray]:
        """``(X, R)``: the body's reference point in the lab and its rotation (body -> lab)."""
        return np.array(y[self.sl_X]), quaternion_matrix(y[self.sl_q])

    # forces --------------------------------------------------------------------------------
    def forces(self, y, base):
        """RodSystem's, in the body frame, with the filament's contact with a boundary placed
        at ``y``'s pose (the only force that depends on the pose)."""
        if len(y) == self.ny:
            self.place_contacts(y)
        return RodSystem.forces(self, y, base)

    def _contact_rotation(self, y) -> np.ndarray:
        """Lab axes of the frame the forces are evaluated in (the body's here)."""
        return self.pose(y)[1]

    def place_contacts(self, y) -> None:
        """Place the filament's contact with a boundary at the pose of ``y`` (a full state):
        what :meth:`forces` does first, and the stage solver before it differences the
        forces (the last evaluation may have been a rejected step's stage, at another
        pose). Nothing without a boundary."""
        if not self._bead_contacts:
            return
        X, _ = self.pose(y)
        geometry = self.boundary.at(X, self._contact_rotation(y)).geometry
        for it in self._bead_contacts:
            if it.name == "wall contact":
                it.wall = geometry
            else:
                it.tube = geometry

    # the boundary, seen from the body -------------------------------------------------------
    def _view(self, y):
        """The boundary at the pose of ``y`` in body coordinates (:mod:`flagwrap.body.
        boundaries`), kept with the pose's blob solve (:meth:`_body`), or None."""
        if self.boundary is None:
            return None
        return self._body(y)[3]

    def _body(self, y):
        """``(blob solver, M_bb^-1 K, N, view)`` at the pose of ``y``: the constant ones without
        a boundary; with one, the solve with ``M_bb + Delta_bb`` at this pose (the boundary's
        :meth:`blob_solver`: factorised afresh beside a wall, conjugate gradients from a
        reference factor in a tube), kept for the last pose (a step's stages revisit it)."""
        if self.boundary is None:
            return self._solver, self._MinvK, self.body_mobility, None
        key = np.array(y[self.n_in:self.n_in + 7])
        if self._body_cache[0] is not None and np.array_equal(key, self._body_cache[0]):
            return self._body_cache[1]
        X, R = self.pose(y)
        view = self.boundary.at(X, R)
        sol = self.boundary.blob_solver(view, self.blobs, self.blob_radii, key)
        MinvK = sol.solve(self.K)
        Rm = self.K.T @ MinvK
        out = (sol, MinvK, np.linalg.inv(0.5 * (Rm + Rm.T)), view)
        self._body_cache = (key, out)
        return out

    def external_load(self, y) -> np.ndarray:
        """``[F; T]`` (6,) the boundary pushes the whole swimmer with (body axes, about the
        reference point): its contact law on each blob's gap (centre's gap less its radius)
        and on each free bead's gap (the same forces :meth:`forces` puts in ``G``); zero
        without a boundary. Unlike the filament's internal forces, the body does not carry
        these back: they move the cell."""
        out = self.wall_load(y)
        if self.boundary is None:
            return out
        view = self._view(y)
        for it in self._bead_contacts:
            x, _, _ = SwimmerSystem.unpack(self, y)
            on = it.active
            g, dg = view.gap_gradient(x[on])
            _, dU, _ = it.law(g)
            fb = -dU[:, None] * dg
            out[:3] += fb.sum(axis=0)
            out[3:] += np.cross(x[on], fb).sum(axis=0)
        return out

    def _blob_gaps(self, y) -> tuple[np.ndarray, np.ndarray]:
        """The body's blobs' surface gaps to the boundary at the pose of ``y`` (centre's gap
        less radius) and their gradients (body axes): what their contact law acts on."""
        g, dg = self._view(y).gap_gradient(self.blobs)
        return g - self.blob_radii, dg

    def wall_load(self, y) -> np.ndarray:
        """The body's own share of :meth:`external_load` (its blobs' contact), zero without a
        boundary."""
        if self.boundary is None or self._boundary_contact is None:
            return np.zeros(6)
        g, dg = self._blob_gaps(y)
        _, dU, _ = self._boundary_contact.law(g)
        f = -dU[:, None] * dg  # the force on each blob, body axes
        return np.concatenate([f.sum(axis=0), np.cross(self.blobs, f).sum(axis=0)])

    def contact_stiffness(self, y) -> np.ndarray | None:
        """``d[F; T]/dxi`` (6, 6) of the body's blobs' contact load (:meth:`wall_load`, body
        axes) under a rigid displacement ``xi = [dx; dalpha]`` (body axes) on the contact's
        stage law (:meth:`~flagwrap.interactions.wall._BoundaryContact.stage_law`, stiffness
        looked ahead of the cut-off), or None where no blob is within its reach (and without
        a boundary). For the stage solver's ``W``.

        ``[F; T] = -sum u'(g_i) c_i``, ``c_i = [n_i; b_i x n_i]`` blob ``i``'s gap gradient
        under ``xi``, so ``K = -sum u''(g_i) c_i c_i^T``; the terms in ``u'`` times the
        boundary's curvature and the turning of ``n_i`` with ``dalpha`` are left out (the
        W-method keeps its order for any ``W``): exact for a translation beside a plane."""
        c = self._boundary_contact
        if self.boundary is None or c is None:
            return None
        g, dg = self._blob_gaps(y)
        near = np.flatnonzero(g < c.cutoff + c.lookahead)
        if near.size == 0:
            return None
        _, _, d2U = c.stage_law(g[near])
        C = np.concatenate([dg[near], np.cross(self.blobs[near], dg[near])], axis=1)
        return -(C.T * d2U) @ C

    def pose_stiffness(self, y) -> np.ndarray | None:
        """``d(dpose/dt)/d(pose)`` (7, 7) through :meth:`contact_stiffness`, or None: the
        body's velocity changes by ``N K xi / machin``, and the pose ``[X; q]`` relates to
        ``xi`` by ``dX = R dx``, ``dq = Q(q) dalpha / 2`` (:func:`quaternion_rate_matrix`,
        whose columns are orthonormal for a unit ``q``)."""
        K = self.contact_stiffness(y)
        if K is None:
            return None
        q = y[self.sl_q] / np.linalg.norm(y[self.sl_q])
        R, Q = quaternion_matrix(q), quaternion_rate_matrix(q)
        P, Pinv = np.zeros((7, 6)), np.zeros((6, 7))
        P[:3, :3], P[3:, 3:] = R, 0.5 * Q
        Pinv[:3, :3], Pinv[3:, 3:] = R.T, 2.0 * Q.T
        return P @ (self._body(y)[2] / self.machin) @ K @ Pinv

    # mobility ------------------------------------------------------------------------------
    def _geometry(self, y):
        """Free beads' body-frame positions (nb, 3), free bonds' tangents (ne, 3), ``M_fb``.

        The last state's are kept: a step's stage solver and its first velocity ask at the same
        ``y``, and ``M_fb`` (beads x blobs) is the costliest thing built per call."""
        s = self
        yin = y[:self.n_in]  # the boundary's Delta is applied apart (_solve)
        if self._geometry_y is not None and np.array_equal(yin, self._geometry_y):
            return self._geometry_out
        from flagwrap.hydrodynamics.polydisperse import rpy_cross_radii

        x, _, _ = s.unpack(yin)
        xf = np.array(x[s.free_beads])  # a copy: kept with the cache, never a view of y
        if s.n_filaments == 1:
            e = x[s.ec + 1:] - x[s.ec:-1]
        else:  # every filament's free bonds
            bf = s.bond_first[s.free_bonds]
            e = x[bf + 1] - x[bf]
        t = e / np.linalg.norm(e, axis=1)[:, None]
        rpy_cross_radii(xf, s.radius, self.blobs, self.blob_radii, self._cross)
        self._geometry_y = np.array(yin)
        self._geometry_out = (xf, t, self._cross)
        return self._geometry_out

    def solver_memory(self) -> np.ndarray:
        """What the stage solver carries from step to step: the lagged screening's
        (:meth:`~flagwrap.body.solver.LaggedScreening.memory`); with a boundary, then its own
        (a tube's reference pose) and that part's length."""
        m = self._lagged.memory()
        if self.boundary is None:
            return m
        b = self.boundary.memory()
        return np.concatenate([m, b, [float(len(b))]])

    def restore_solver_memory(self, memory) -> None:
        memory = np.asarray(memory, float)
        if self.boundary is not None:
            k = int(memory[-1]) if memory.size else 0
            self.boundary.restore(memory[len(memory) - 1 - k:-1] if memory.size else memory,
                                  self.blobs, self.blob_radii)
            self._body_cache = (None, None)
            memory = memory[:len(memory) - 1 - k] if memory.size else memory
        self._lagged.restore(memory)

    def _load(self, xf, t, F, tau) -> np.ndarray:
        """``S G = [sum F; sum x x F + sum tau t]`` (6,)."""
        XF = xf.T @ F  # sum x x F is its antisymmetric part (np.cross costs more than this)
        torque = np.array([XF[1, 2] - XF[2, 1], XF[2, 0] - XF[0, 2], XF[0, 1] - XF[1, 0]])
        return np.concatenate([F.sum(axis=0), torque + tau @ t])

    def body_velocity(self, y, G) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(V, v_beads, lambda)``: the body's ``[U; Omega]`` (body axes, core units), the free
        beads' lab-frame velocities in body axes, and the blob forces (core units) for the
        generalized forces ``G`` (filament unknowns) at ``y``: the forces of ``y`` (a
        boundary's push, :meth:`external_load`, taken as external)."""
        return self._solve(y, G, external=True)[:3]

    def _solve(self, y, G, external: bool = False):
        """:meth:`body_velocity` and the geometry it used: ``(V, v, lambda, x_free, t)``.

        ``external``: ``G`` is the force of ``y`` itself, whose boundary contact
        (:meth:`external_load`) the body does not carry back (so the velocity is exact);
        otherwise ``G`` is any vector and the map linear (``A G``, the stage solver's)."""
        s = self
        xf, t, C = self._geometry(y)
        solver, MinvK, N, view = self._body(y)
        F = np.asarray(G[s.sl_x]).reshape(-1, 3)
        tau = np.asarray(G[s.sl_th])
        Ff = F.ravel()
        b, rb = self.blobs, self.blob_radii
        u = C.T @ Ff  # M_bf F, and beside a boundary its Delta_bf F
        if view is not None:
            u += view.apply(b, rb, [(xf, s.radius, Ff)])
        w = solver.solve(u)
        load = self._load(xf, t, F, tau)
        if external and view is not None:
            load = load - self.external_load(y)
        V = N @ (self.K.T @ w - load)
        lam = MinvK @ V - w
        v = s.mobility.apply(xf, F) + (C @ lam).reshape(-1, 3)
        if view is not None:  # Delta_fb lambda + Delta_ff F
            v += view.apply(xf, s.radius, [(b, rb, lam), (xf, s.radius, Ff)]).reshape(-1, 3)
        return V / s.machin, v / s.machin, lam, xf, t

    def apply_mobility(self, y, G, single: bool = False, external: bool = False) -> np.ndarray:
        """``A G`` (module docstring) over the whole state: filament rows in the body frame,
        pose rows ``dX/dt = R U``, ``dq/dt = q (0, Omega) / 2``; the motor angle's row 0.
        ``external``: ``G`` is ``y``'s own force (:meth:`_solve`)."""
        s = self
        V, v, _, xf, t = self._solve(y, G, external)
        U, Om = V[:3], V[3:]
        out = np.zeros(self.ny)
        out[s.sl_x] = (v - U - xf @ cross_matrix(Om).T).ravel()
        out[s.sl_th] = s.twist_mobility * G[s.sl_th] - t @ Om
        q = y[self.sl_q] / np.linalg.norm(y[self.sl_q])
        out[self.sl_X] = quaternion_matrix(q) @ U
        out[self.sl_q] = quaternion_rate(q, Om)
        return out

    def velocity(self, y, info, omega: float) -> np.ndarray:
        f = self.apply_mobility(y, info.G, external=True)
        f[self.sl_phi] = self.motor_rate(y, info, omega)
        return f

    def mobility_matrix(self, y, screening=True, reuse: bool = False) -> np.ndarray:
        """Dense ``A`` over the filament's unknowns (n_in, n_in; motor-angle row and column 0):
        ``A_fixed + D^T N D``, ``D = E - S``.

        ``screening``: ``True``, the fixed surface's screening ``M_fb M_bb^-1 M_bf`` exact;
        ``False`` without it; ``"lagged"`` as last computed, recomputed when the beads have
        moved (:class:`~flagwrap.body.solver.LaggedScreening`: the stage solver's ``W``).
        ``reuse=True`` (the stage solver, once a step): built in buffers the system keeps, so
        the result is valid until the next reusing call, and the body's rows ``N D`` kept
        for the pose rows of ``W``."""
        s = self
        xf, t, C = self._geometry(y)
        n3 = 3 * s.nb
        if reuse:
            if self._a_buffers is None:
                self._a_buffers = (np.empty((self.n_in, self.n_in)),
                                   np.empty((self.n_in, self.n_in)), np.empty((n3, n3)))
            A, tmp, Mff = self._a_buffers
            A.fill(0.0)
        else:
            A, tmp, Mff = np.zeros((self.n_in, self.n_in)), None, None
        solver, MinvK, N, view = self._body(y)
        A[:n3, :n3] = s.mobility.matrix(xf, out=Mff)
        if view is not None:
            A[:n3, :n3] += view.correction_matrix(xf, s.radius)
        if screening == "lagged":
            S = self._lagged(xf)
            if S is not None:  # None: a Krylov blob solver, W goes without
                A[:n3, :n3] -= S
        elif screening:  # with the pose's own blob matrix beside a boundary
            from flagwrap.body.solver import screening_matrix

            Ct = C if view is None else C + view.correction_matrix(xf, s.radius, self.blobs,
                                                                   self.blob_radii)
            A[:n3, :n3] -= screening_matrix(solver, Ct)
        idx = np.arange(n3, n3 + s.ne)
        A[idx, idx] = s.twist_mobility * s.machin
        D = self._rigid_rows(xf, t, C, MinvK, view)
        ND = N @ D
        A += np.matmul(D.T, ND, out=tmp)
        A /= s.machin
        if reuse:  # the body's velocity per generalized force: V = (N D / machin) G
            self._body_rows = ND / s.machin
        return A

    def _rigid_rows(self, xf, t, C, MinvK, view) -> np.ndarray:
        """``D = E - S`` (6, n_in): ``-S`` the beads' rigid-motion matrix transposed, ``[I;
        [x]_x]`` per bead and ``[0; t]`` per bond, ``E = K^T M_bb^-1 M_bf`` the body's
        screening of them (with the boundary's part, ``view``, where there is one)."""
        n3 = 3 * self.nb
        D = np.zeros((6, self.n_in))
        CK = C @ MinvK
        if view is not None:  # (M_fb + Delta_fb) M~_bb^-1 K
            CK += view.apply(xf, self.radius, [(self.blobs, self.blob_radii, MinvK)])
        D[:, :n3] = CK.T - geometric_matrix(xf).T
        D[3:, n3:n3 + self.ne] -= t.T
        return D

    def rigid_rows(self, y) -> tuple[np.ndarray, np.ndarray]:
        """``(D, N)`` at ``y``: the rows through which generalized forces move the body,
        ``V = N D G / machin`` (:meth:`mobility_matrix`), and the body's 6 x 6 mobility."""
        xf, t, C = self._geometry(y)
        _, MinvK, N, view = self._body(y)
        return self._rigid_rows(xf, t, C, MinvK, view), N

    def frame_rows(self, WT, y) -> None:
        """What a moving frame adds to ``W^T`` (written in place) once the torque motor's row
        is in ``WT``: nothing in the body frame."""

    def make_w(self, kind, y, base, G0, gamma_h, err_scale=None, omega=None):
        """The stage solver: matrix-free (:class:`SwimmerKrylovW`) for ``"krylov"``, and for
        ``"auto"`` with speed motors above :data:`AUTO_KRYLOV_NY` filament unknowns; dense
        (:class:`SwimmerW`) otherwise."""
        if kind == "krylov" or (kind == "auto" and not self.drive.free
                                and self.n_in > AUTO_KRYLOV_NY):
            return SwimmerKrylovW(self, y, base, G0, gamma_h, err_scale)
        return SwimmerW(self, y, base, G0, gamma_h, omega)

    # output --------------------------------------------------------------------------------
    def record_view(self, y, info):
        """``info`` with positions, gradients and reference frames in the lab frame."""
        import dataclasses

        from flagwrap.elasticity.rod import Frames

        X, R = self.pose(y)
        fr = info.frames
        return dataclasses.replace(info, x=info.x @ R.T + X, grad_x=info.grad_x @ R.T,
                                   frames=Frames(fr.t @ R.T, fr.d1 @ R.T, fr.rt))

    def body_record(self, y, info) -> np.ndarray:
        """``[X (3), q (4), U (3), Omega (3)]``: the body's lab position and orientation
        (unit quaternion, body -> lab), and its velocity and angular velocity in lab axes
        (core units)."""
        X, R = self.pose(y)
        V, _, _ = self.body_velocity(y, info.G)
        q = y[self.sl_q] / np.linalg.norm(y[self.sl_q])
        return np.concatenate([X, q, R @ V[:3], R @ V[3:]])


_NO_TWIST_BLOCK = np.empty(0)


class SwimmerW:
    """The swimmer's ``W = I - gamma h (dy/dt)/dy`` without the mobility's own change:

        W = [[I - gamma h A J, 0], [-gamma h P J, I]]

    over (filament, pose); ``A`` with the screening lagged (:meth:`SwimmerSystem.
    mobility_matrix`; without it while a bead touches the body), ``J`` the force Jacobian,
    ``P = [R(q) N_U; Q(q) N_Omega / 2] D / machin`` the pose rates per generalized force
    (:func:`quaternion_rate_matrix`); beside a boundary the pose block is ``I - gamma h
    K_pp`` where the body's blobs touch it (:meth:`SwimmerSystem.pose_stiffness`), the
    identity elsewhere. A solve is the filament's LU, then the pose rows forward.
    The filament block's LU is factorised in a buffer the system keeps (as
    :class:`~flagwrap.integrators.linear.DenseW` with ``reuse``): valid until the next
    ``SwimmerW`` of the same system, one per step."""

    def __init__(self, system, y, base, G0, gamma_h, omega=None):
        from flagwrap.integrators.linear import add_motor_rows, lu_of_transpose
        from flagwrap.system.kernels import left_product_coo, w_transpose_dense

        n = system.n_in
        system.place_contacts(y)
        rows, cols, vals = system.force_jacobian_coo(y[:n], base, G0[:n], stage=True)
        # the screening only while no bead touches the body: with a bead in contact the
        # screened W misses the stiff (dA/dx)[F_contact] of a mobility that falls steeply at
        # the wall, and the controller alternates accepted and rejected steps (measured:
        # 300 of 300 rejected from a wrapped C. insecticola state, 20 without the screening)
        touching = system.forces(y, base).contact_energy > 0.0
        A = system.mobility_matrix(y, screening=False if touching else "lagged", reuse=True)
        WT = system.__dict__.get("_wt_buffer")
        if WT is None:
            WT = system._wt_buffer = np.empty((n, n))
        w_transpose_dense(rows, cols, vals, A, _NO_TWIST_BLOCK, gamma_h, WT)  # Mob = A whole
        if system.drive.free:  # a torque motor's row, as the rig's DenseW
            add_motor_rows(WT, system, y[:n], base, gamma_h, omega)
            system.frame_rows(WT, y[:n])
        self.n = n
        self.lu = lu_of_transpose(WT)
        q = y[system.sl_q] / np.linalg.norm(y[system.sl_q])
        ND = system._body_rows
        P = np.concatenate([quaternion_matrix(q) @ ND[:3],
                            0.5 * quaternion_rate_matrix(q) @ ND[3:]])
        self.PJ = left_product_coo(P, rows, cols, vals, np.empty((7, n)))
        self.PJ *= gamma_h
        self.pose_lu = pose_block(system, y, gamma_h)

    def solve(self, rhs):
        out = np.array(rhs, float)
        u = out[:self.n] = sla.lu_solve(self.lu, rhs[:self.n], check_finite=False)
        out[self.n:] += self.PJ @ u
        if self.pose_lu is not None:
            out[self.n:] = sla.lu_solve(self.pose_lu, out[self.n:], check_finite=False)
        return out


def pose_block(system, y, gamma_h):
    """The LU of ``W``'s pose block ``I - gamma h K_pp`` (:meth:`SwimmerSystem.
    pose_stiffness`), or None where it is the identity."""
    K = system.pose_stiffness(y)
    if K is None:
        return None
    return sla.lu_factor(np.eye(7) - gamma_h * K, check_finite=False)


class SwimmerFrame(RotatingFrame):
    """The free swimmer in the frame turning with its motor relative to the body, for linear
    stability (:mod:`flagwrap.stability`): a
    :class:`~flagwrap.system.rotating.RotatingFrame` whose rotation terms and Jacobian
    assembly it inherits, with the swimmer's mobility.

    Unknowns ``z``: the filament's (positions and twists, no motor angle) in this frame. A
    steady state here is a filament turning rigidly with the motor while the body turns and
    swims steadily in body axes (a helical path in the lab). The blob shell, not quite
    symmetric about the axis, is held at one angle in this frame (as ``blob_body`` in the
    fixed case); the pose is not an unknown (nothing depends on it).
    """

    def __init__(self, swimmer, omega: float):
        check_rotating_frame(swimmer)
        self._setup(swimmer, omega, swimmer.n_in - 1)

    def full(self, z) -> np.ndarray:
        s = self.system
        y = np.zeros(s.ny)
        y[:self.n] = z
        y[s.sl_q.start] = 1.0
        return y

    def velocity(self, z, base, machin=None):
        s = self.system
        y = self.full(z)
        info = s.forces(y, base)
        f = s.apply_mobility(y, info.G)[:s.n_in]
        f *= self.scale(machin)
        subtract_rotation(f, s, info, self.omega, self.axis, self._A)
        return f[:self.n], info

    def mobility_product(self, y, X) -> np.ndarray:
        """``A X``: the swimmer's dense mobility over ``z`` (:meth:`SwimmerSystem.
        mobility_matrix`, the body's motion included) times ``X`` (n, k)."""
        n = self.n
        return self.system.mobility_matrix(y)[:n, :n] @ X[:n]

    def _mobility_jacobian(self, y, info, JG) -> np.ndarray:
        """``A (dG/dz) + (dA/dx)[G]``: ``A`` dense (:meth:`SwimmerSystem.mobility_matrix`),
        its change with the bead positions by central differences at fixed forces."""
        s, n, n3 = self.system, self.n, self.n3
        J = self.mobility_product(y, JG)
        h = 1e-4 * s.bond  # as RotatingFrame: the mobility varies on the bead radius
        yp = y.copy()
        for k in range(n3):
            yp[k] = y[k] + h
            vp = s.apply_mobility(yp, info.G)[:n]
            yp[k] = y[k] - h
            vm = s.apply_mobility(yp, info.G)[:n]
            yp[k] = y[k]
            J[:, k] += (vp - vm) / (2.0 * h)
        return J


def make_swimmer(config):
    """The free-swimming system of ``config`` (``body.motion = "free"``)."""
    from flagwrap.body.multiblob import cell_body_blobs
    from flagwrap.hydrodynamics.mobility import RPYMobility

    fil = config.filament
    inner = RodSystem(config, mobility=RPYMobility(fil.bead_radius / fil.length))
    blobs, radii = cell_body_blobs(config)
    boundary = contact = None
    if inner.wall is not None or inner.tube is not None:
        # the system's plane (config_wall) or tube (config_tube), seen by the body too
        from flagwrap.body.boundaries import TubeFromBody, WallFromBody
        from flagwrap.interactions.wall import _BoundaryContact, contact_law

        if inner.wall is not None:
            boundary = WallFromBody(inner.wall)
        else:
            from flagwrap.system.parts import tube_blobs

            boundary = TubeFromBody(inner.tube, *tube_blobs(config))
        cutoff, strength, c2 = contact_law(config, inner.bond)
        contact = _BoundaryContact(cutoff, strength, np.ones(len(blobs), bool), c2=c2)
    return SwimmerSystem(inner, blobs, radii, solver=config.body.solver, boundary=boundary,
                         contact=contact)


class SwimmerKrylovW(KrylovW):
    """The swimmer's ``W`` (:class:`SwimmerW`'s block lower triangular form) solved
    matrix-free: the filaments' block by the rig's preconditioned GCR with recycling
    (:class:`~flagwrap.integrators.linear.KrylovW`, whose loop and stopping rule this
    inherits), each product ``v - gamma h A (J v)`` with the swimmer's own mobility product
    (the body's blobs, its motion and every filament's hydrodynamics, exact:
    :meth:`SwimmerSystem.apply_mobility`), then the pose rows forward from one more product,
    ``gamma h P J u`` being that product's pose rates (and beside a boundary the pose block
    of :class:`SwimmerW`).

    Preconditioner: each filament's own dense ``I - gamma h M_k J_kk``, ``M_k`` the
    free-space RPY among its free beads and its twists' local drag (no other filament), and
    the body's rigid motion under every filament's forces, ``D^T N D`` (rank 6, ``D`` the
    beads' rigid-motion rows with the body's screening of them, ``N`` the body's 6 x 6
    mobility: :meth:`SwimmerSystem.mobility_matrix`), by the Sherman-Morrison-Woodbury
    formula: ``n_f`` LUs of one filament's size and a 6 x 6 one, so the cost per step grows
    as the products do. The iterations carry what it leaves out (the body's screening of
    each filament, the filaments' mutual flow). The rank-6 term is what couples the
    filaments most: measured (``studies/bundle_preconditioner.py``, P. putida, 40 steps from
    rest) it takes the GCR iterations per step from 10.0 / 10.0 / 12.3 to 6.2 / 7.0 / 10.0
    for 1 / 3 / 8 flagella, where the filaments' whole mutual free-space flow in one dense
    block instead takes them to 10.0 / 10.1 / 11.0 only. Speed motors only (a torque motor's
    row couples the whole ``W``: refused by ``numerics.linear_solver`` before any work).
    """

    def __init__(self, system, y, base, G0, gamma_h, err_scale=None, rtol=1e-3, maxiter=200,
                 kappa=KAPPA):
        import scipy.sparse as sp

        n = system.n_in
        self.system, self.y, self.gh, self.n = system, y, gamma_h, n
        self._gcr_setup(n, rtol, maxiter, None if err_scale is None else err_scale[:n], kappa)
        system.place_contacts(y)
        rows, cols, vals = system.force_jacobian_coo(y[:n], base, G0[:n], stage=True)
        self.J = sp.csr_matrix((vals, (rows, cols)), shape=(n, n))
        x, _, _ = system.unpack(y)
        x_free = x[system.free_beads]
        mt = np.broadcast_to(system.twist_mobility, (system.ne,))
        blocks = []
        phi = np.arange(n)[system.sl_phi]
        for p in system.parts:
            idx = np.arange(p.ny) if p.ymap is None else p.ymap
            pos, tw = idx[:3 * p.nb], idx[3 * p.nb:3 * p.nb + p.ne]
            I = np.concatenate([pos, tw])
            xf = np.ascontiguousarray(x_free[pos[::3] // 3])
            M = np.zeros((len(I), len(I)))
            M[:len(pos), :len(pos)] = system.mobility.matrix(xf) / system.machin
            k = np.arange(len(pos), len(I))
            M[k, k] = mt[tw - system.sl_th.start]
            JI = self.J[I]
            W = np.eye(len(I)) - gamma_h * (M @ JI[:, I].toarray())
            # the motor angles' rows are the identity's; their columns (the clamps turn with
            # them) enter each block's right-hand side: W is block lower triangular
            blocks.append((I, sla.lu_factor(W, check_finite=False),
                           gamma_h * (M @ JI[:, phi].toarray())))
        D, N = system.rigid_rows(y)
        # W_P = W_blocks - U V, U = gamma h D^T N / machin (n, 6), V = D J (6, n)
        self.P = _FilamentBlocks(blocks, gamma_h * (D.T @ N) / system.machin,
                                 np.asarray((self.J.T @ D.T).T), phi)
        self.pose_lu = pose_block(system, y, gamma_h)

    def _product(self, v):
        """``A (J v)`` over the whole state (filaments and pose rows)."""
        G = np.zeros(self.system.ny)
        G[:self.n] = self.J @ v
        return self.system.apply_mobility(self.y, G)

    def matvec(self, v):
        return v - self.gh * self._product(v)[:self.n]

    def solve(self, rhs):
        u = super().solve(np.asarray(rhs[:self.n], float))
        out = np.array(rhs, float)
        out[:self.n] = u
        out[self.n:] += self.gh * self._product(u)[self.n:]
        if self.pose_lu is not None:
            out[self.n:] = sla.lu_solve(self.pose_lu, out[self.n:], check_finite=False)
        return out


class _FilamentBlocks:
    """:class:`SwimmerKrylovW`'s preconditioner: each filament's LU on its own unknowns, the
    identity on the motor angles (``phi``), whose columns ``G`` of a block move its
    right-hand side; with ``U`` (n, k) and ``V`` (k, n), the inverse of
    ``B - U V`` (``B`` the blocks) by the Sherman-Morrison-Woodbury formula,
    ``B^-1 + B^-1 U (I - V B^-1 U)^-1 V B^-1``: ``k`` block solves once, a k x k LU."""

    def __init__(self, blocks, U=None, V=None, phi=None):
        self.blocks, self.phi = blocks, phi
        self.BU = self.V = None
        if U is not None:
            self.BU = self._blocks(U)
            self.V = V
            self.cap = sla.lu_factor(np.eye(U.shape[1]) - V @ self.BU, check_finite=False)

    def _blocks(self, r):
        z = np.array(r, float)
        for I, lu, G in self.blocks:
            rI = r[I] if G is None else r[I] + G @ r[self.phi]
            z[I] = sla.lu_solve(lu, rI, check_finite=False)
        return z

    def solve(self, r):
        z = self._blocks(r)
        if self.BU is not None:
            z += self.BU @ sla.lu_solve(self.cap, self.V @ z, check_finite=False)
        return z


class SwimmerRotating(AtReferenceAngle, SwimmerSystem):
    """The free swimmer stepped in the frame turning with its motor relative to the body
    (``numerics.frame = "rotating"`` with ``body.motion = "free"``): the filament's
    positions ``x''`` are the body-frame ones turned back by the motor angle ``phi`` about
    the motor axis, ``x' = R(phi) x''``. A cell swimming steadily is then nearly a fixed
    point of the filament's unknowns, as the rig's whirl is of
    :class:`~flagwrap.system.rotating.RotatingSystem`, so the step follows the slow dynamics.

    The body's blobs are not symmetric about the axis, so they are not held still in this
    frame: each mobility product is the body frame's (:class:`SwimmerSystem`) at the turned
    positions, by the rotation covariance of the mobility, ``A''(x'') = R^T A'(R x'') R``
    (``R`` on each bead's block; twists are scalars). That is exact: the blob shell turns at
    ``-dphi/dt`` under the filament. The forces are evaluated with the clamp at ``phi = 0``
    (the energy is invariant under a rotation of everything), and the velocity gains the
    frame's terms ``-w a x x''`` and ``-w a . t`` (twist), ``w = dphi/dt`` the motor's rate
    relative to the body (a torque motor's too). The pose is the body's, as in
    :class:`SwimmerSystem`.

    The stage solver's ``W`` is the body frame's at ``phi = 0``: the blob shell held at one
    angle (its ripple left to the W-method, whose order holds for any ``W``), so the lagged
    screening follows the filament in this frame and is rebuilt only when it has moved
    here. Run files are written in the lab frame (:meth:`record_view`, :meth:`body_record`).
    """

    def __init__(self, swimmer):
        from flagwrap.system.rotating import check_rotating_frame

        if type(swimmer) is not SwimmerSystem:
            raise ValueError("SwimmerRotating: a SwimmerSystem")
        check_rotating_frame(swimmer, blob_body=True, placed=swimmer._bead_contacts)
        self.__dict__.update(swimmer.__dict__)  # the same parts and buffers: a view
        self.axis = np.asarray(swimmer.joint.axis, float)
        self._A = cross_matrix(self.axis)

    # the frame (_turn, pack, unpack, record_view: AtReferenceAngle) ------------------------
    def _to_body(self, y, G, R):
        """``(y', G')``: the state and generalized forces turned into the body frame (the
        free beads' positions and forces by ``R``; twists, motor angle and pose as they
        are)."""
        sx = self.sl_x
        yb = np.array(y, float)
        yb[sx] = (y[sx].reshape(-1, 3) @ R.T).ravel()
        Gb = np.array(G, float)
        Gb[sx] = (G[sx].reshape(-1, 3) @ R.T).ravel()
        return yb, Gb

    def from_body_frame(self, y, base):
        """``(y'', base'')``: a state ``y`` of the body-frame :class:`SwimmerSystem` of the
        same config (with its reference frames ``base``) in this frame. Positions and
        reference frames turn back by ``R(phi)``; the clamp's material frame is at ``phi = 0``
        here, so every reference frame also turns by ``phi`` about its own tangent and every
        twist angle loses ``phi`` (``R^T m1`` kept for each bond's material vector ``m1``)."""
        from flagwrap.elasticity.rod import Frames

        x, theta, phi = SwimmerSystem.unpack(self, y)
        yr = self.pack(x, theta - phi, phi, y[self.sl_X], y[self.sl_q])
        R = self._turn(yr)
        t, d = base.t, base.d1
        # Rodrigues about each tangent (d is perpendicular to t)
        d1 = math.cos(phi) * d + math.sin(phi) * np.cross(t, d)
        return yr, Frames(t @ R, d1 @ R, base.rt)

    # forces at the clamp's reference angle (AtReferenceAngle) ---------------------------
    def forces(self, y, base):
        """The body frame's forces with the clamp at ``phi = 0``; a boundary's contact placed
        as this frame sees it (the body's pose, then turned back by ``phi``)."""
        if len(y) == self.ny:
            self.place_contacts(y)
        return RodSystem.forces(self, self._at_zero(y), base)

    def _contact_rotation(self, y) -> np.ndarray:
        return self.pose(y)[1] @ self._turn(y)

    def motor_rate(self, y, info, omega: float):
        return SwimmerSystem.motor_rate(self, self._at_zero(y), info, omega)

    def motor_jacobian(self, y, base, omega: float):
        rows = SwimmerSystem.motor_jacobian(self, self._at_zero(y), base, omega)
        if rows is not None:
            rows[:, self.i_phi] = 0.0  # no force depends on the motor angle here
        return rows

    def frame_rows(self, WT, y) -> None:
        """A torque motor's rate ``w(y)`` turns this frame, so every bead's and bond's rate
        (``-w a x x''``, ``-w a . t``) follows the motor's load: ``W`` gains ``gamma h c
        (dw/dy)``, ``c`` those directions, rank one. ``dw/dy`` is read off the motor's column
        of ``WT`` (``-gamma h dw/dy`` there, :func:`~flagwrap.integrators.linear.
        add_motor_rows`)."""
        i = self.i_phi
        col = np.array(WT[:, i])
        col[i] -= 1.0
        x, _, _ = self.unpack(y)
        c = np.empty(i)
        c[self.sl_x] = np.cross(self.axis, x[self.nc:]).ravel()
        e = x[self.ec + 1:] - x[self.ec:-1]
        c[self.sl_th] = (e @ self.axis) / np.linalg.norm(e, axis=1)
        WT[:, :i] -= np.outer(col, c)

    # mobility ------------------------------------------------------------------------------
    def apply_mobility(self, y, G, single: bool = False, external: bool = False) -> np.ndarray:
        """``R^T A'(R x'') R G``: the body frame's product at the turned positions, its bead
        rows turned back; the pose rows are the body's own."""
        R = self._turn(y)
        yb, Gb = self._to_body(y, G, R)
        out = SwimmerSystem.apply_mobility(self, yb, Gb, single, external)
        sx = self.sl_x
        out[sx] = (out[sx].reshape(-1, 3) @ R).ravel()
        return out

    def velocity(self, y, info, omega: float) -> np.ndarray:
        from flagwrap.system.rotating import subtract_rotation

        f = self.apply_mobility(y, info.G, external=True)
        w = self.motor_rate(y, info, omega)
        subtract_rotation(f, self, info, w, self.axis, self._A)
        f[self.sl_phi] = w
        return f

    def body_velocity(self, y, G):
        """The body frame's :meth:`SwimmerSystem.body_velocity` at the turned state: ``V``
        in body axes, the beads' velocities turned into this frame, the blob forces."""
        R = self._turn(y)
        yb, Gb = self._to_body(y, G, R)
        V, v, lam = SwimmerSystem.body_velocity(self, yb, Gb)
        return V, v @ R, lam

    def mobility_matrix(self, y, screening=True, reuse: bool = False) -> np.ndarray:
        """The body frame's ``A`` at ``phi = 0``: the shell held at one angle. The stage
        solver's (class docstring); not the exact mobility of this frame at other angles."""
        return SwimmerSystem.mobility_matrix(self, self._at_zero(y), screening, reuse)
