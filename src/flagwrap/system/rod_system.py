"""The assembled physical system in core units: forces, mobilities, motor, state packing.

:class:`RodSystem` is built once from a :class:`flagwrap.params.Config` and is then a set of
pure functions of the state vector ``y``:

* ``y = [x_free (3 n_b), theta_free (n_e), phi]``: positions of the free beads (2..N-1),
  twist angles of the free bonds (1..N-2) and the motor angle ``phi``;
* generalized forces ``G(y) = -dU/dy`` (elastic + contact + gravity), ``G_phi = 0``;
* equation of motion (paper, Methods, Stokesian dynamics): ``dy/dt = Mob(y) G(y) + omega(t) e_phi``
  with ``Mob = (1/M) blockdiag(mu_hat_RPY, 1/(8 pi a^3 w_j), 0)``.

The reference frames (parallel transported in time) are carried outside ``y`` in a
:class:`~flagwrap.elasticity.rod.Frames` "base", updated after each accepted step.

Modelling choices (documented in docs/model.md): the two clamped beads belong to the motor and
are hydrodynamically inert (the body is transparent to the fluid, as in the paper); each bead's
rotational drag ``8 pi eta a^3`` is shared by its two bonds, so a bond carries
``w_j = 1`` (interior) or ``1.5`` (end bonds) bead drags and a rigidly twirled straight rod needs
``N * 8 pi eta a^3 omega``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from flagwrap.system import kernels as SK
from flagwrap.body.cell_body import CappedCylinder, NoBody, body_mobility
from flagwrap.elasticity.rod import Frames, RestState, initial_frames, rest_state
from flagwrap.geometry.helix import filament_positions
from flagwrap.hydrodynamics.mobility import make_mobility
from flagwrap.joints import make_joint
from flagwrap.motor.drive import make_drive
from flagwrap.motor.protocol import Schedule
from flagwrap.system.layout import DofLayout


@dataclass
class ForceInfo:
    """Everything computed with the generalized forces (kept for observables)."""

    G: np.ndarray
    x: np.ndarray
    theta: np.ndarray
    frames: Frames
    elastic_energy: float
    contact_energy: float
    grad_x: np.ndarray
    grad_theta: np.ndarray
    distance: np.ndarray
    interaction_energy: float = 0.0


class RodSystem:
    """Forces, mobility and bookkeeping of one run (core units)."""

    def __init__(self, config, x0=None, theta0=None, body=None, clamp=None, mobility=None,
                 joint=None, interactions=()):
        """``joint`` (or its old name ``clamp``): a built joint for the shape ``x0`` (default:
        :func:`flagwrap.joints.make_joint` from ``config.joint``); ``interactions``: extra
        energy terms (:mod:`flagwrap.interactions.base`) after those the config asks for."""
        self.config = config
        fil = config.filament
        L = fil.length
        self.scales = config.scales
        self.machin = config.machin
        x0 = filament_positions(fil, config.clamp) / L if x0 is None else np.asarray(x0, float)
        theta0 = np.zeros(len(x0) - 1) if theta0 is None else np.asarray(theta0, float)
        joint = joint or clamp
        if joint is None:  # the joint may add beads (a resolved hook): it returns the shape
            joint, x0, theta0 = make_joint(config, x0, theta0)
        N = len(x0)
        self.N = N
        frames = initial_frames(x0)
        b = fil.bond_length / L
        self.bond = b
        # Step of the coloured finite-difference Jacobian, a fixed fraction of the bond: bending
        # and twist forces depend on displacements through angles ~ dx / b, so this keeps the
        # relative accuracy of J the same at every N (measured: docs/numerics.md, "Cost").
        self.fd_step = 6e-6 * b
        self.joint = self.clamp = joint
        self.rest: RestState = joint.rest(rest_state(
            x0, frames, theta0,
            bending=1.0,
            twist=fil.twist_modulus / fil.bending_modulus,
            stretch=fil.stretch_stiffness / b**3,
        ))
        self.frames0 = frames
        self.x0 = x0
        self.theta0 = theta0
        nc, ec = joint.n_beads, joint.n_edges
        self.nc, self.ec = nc, ec
        self.nb = N - nc  # free beads
        self.ne = N - 1 - ec  # free bonds
        self.layout = DofLayout.clamped_filament(
            self.nb, self.ne, "prescribed" if config.motor.kind == "speed" else "angle")
        self.ny = self.layout.size
        self.sl_x = self.layout["x"]
        self.sl_th = self.layout["theta"]
        self.i_phi = self.layout.block("phi").start  # the motor angle's index in y
        # the fused kernels and the dense/banded W assemblies take y in this block order
        assert [b.name for b in self.layout.blocks] == ["x", "theta", "phi"], self.layout
        # hydrodynamics (radius in core units)
        self.radius = fil.bead_radius / L
        num = config.numerics
        self.mobility = mobility or body_mobility(config, self.radius) or make_mobility(
            num.hydrodynamics, self.radius, backend=num.mobility_backend,
            n=N, threads=num.threads, fmm_eps=num.mobility_tol)
        w = np.ones(N - 1)
        w[0] += 0.5
        w[-1] += 0.5
        self.rot_drag = 8.0 * math.pi * self.radius**3 * w  # geometric, times M gives core drag
        self.twist_mobility = 1.0 / (self.machin * self.rot_drag[self.ec:])  # free bonds, core
        # cell body
        if config.body.enabled:
            R = fil.helix_radius
            self.body = body or CappedCylinder(
                radius=config.body.resolved_radius(R) / L,
                length=config.body.resolved_length(R) / L,
                cutoff=fil.cross_section_radius * (1.0 + config.contact.range) / L,
                strength=config.contact.strength / b,
                first_bead=nc,
                potential=config.contact.potential,
                shape=config.body.shape,
            )
        else:
            self.body = body or NoBody()
        # gravity/buoyancy: force per bead (core units) along +z, G l / L for a bead carrying
        # contour l (half a bond at the ends): units.gravity_number
        self.gravity = np.zeros((N, 3))
        if fil.density is not None:
            # half of each adjacent bond's nominal length (b, or a hook's short bonds)
            lb = np.where(np.abs(self.rest.l0 - b) < 1e-9 * b, b, self.rest.l0)
            per_bead = np.empty(N)
            per_bead[0], per_bead[-1] = 0.5 * lb[0], 0.5 * lb[-1]
            per_bead[1:-1] = 0.5 * (lb[:-1] + lb[1:])
            self.gravity[:, 2] = config.gravity_number * per_bead
        self.schedule = Schedule(config.motor.protocol)
        self.drive = make_drive(config, zeta=self.machin * self.rot_drag[0])
        self._colors = None
        self.interactions = self._config_interactions() + list(interactions)

    def _config_interactions(self) -> list:
        c = self.config.contact
        if not c.self_contact:
            return []
        from flagwrap.interactions.self_contact import SelfContact, SelfContactInteraction

        sc = SelfContact(self.config.filament.cross_section_radius / self.config.filament.length,
                         self.bond, range=c.resolved_self_range,
                         strength=c.resolved_self_strength / self.bond,
                         c2=1.0 if c.potential == "wca-c2" else 0.0, rest_lengths=self.rest.l0)
        return [SelfContactInteraction(sc)]

    # packing -------------------------------------------------------------------------------
    def initial_y(self) -> np.ndarray:
        """The initial state: the rest shape, displaced by ``config.initial`` if it asks
        (the clamp's beads are not free unknowns, so they stay where the clamp holds them)."""
        ini = self.config.initial
        if ini.perturbation == 0.0:
            self._check_outside_body(self.x0)
            return self.pack(self.x0, self.theta0, 0.0)
        from flagwrap.geometry.perturbation import displacement

        dx = displacement(self.N, ini.perturbation / self.config.filament.length, ini.mode, ini.seed)
        dx[:self.nc] = 0.0  # the clamp's beads are where the clamp holds them
        self._check_outside_body(self.x0 + dx)
        return self.pack(self.x0 + dx, self.theta0, 0.0)

    def _check_outside_body(self, x) -> None:
        """Refuse a start with a free bead's centre inside the cell body (one line, exit 2)."""
        d = self.body.distance(x[self.nc:])
        if d.size and d.min() <= 0.0:
            from flagwrap.errors import UserInputError

            i = int(np.argmin(d))
            L = self.config.filament.length
            raise UserInputError(
                f"body overlaps the filament at the start: bead {i + self.nc} is "
                f"{-d[i] * L:.3g} m inside the cell body (initial.perturbation = "
                f"{self.config.initial.perturbation:g} m, filament.n_beads = "
                f"{self.config.filament.n_beads}); "
                "use a smaller initial.perturbation, another initial.seed, or more beads")

    def pack(self, x, theta, phi) -> np.ndarray:
        y = np.empty(self.ny)
        y[self.sl_x] = x[self.nc:].ravel()
        y[self.sl_th] = theta[self.ec:]
        y[self.i_phi] = phi
        return y

    def unpack(self, y):
        phi = y[self.i_phi]
        x = np.empty((self.N, 3))
        x[: self.nc] = self.clamp.positions(phi)
        x[self.nc:] = y[self.sl_x].reshape(-1, 3)
        theta = np.empty(self.N - 1)
        theta[: self.ec] = self.clamp.theta(phi)
        theta[self.ec:] = y[self.sl_th]
        return x, theta, phi

    # forces --------------------------------------------------------------------------------
    def _kernel_args(self, base: Frames):
        r, c, b = self.rest, self.clamp, self.body
        has_body = not isinstance(b, NoBody)
        return (self.nc, self.ec, c.x_ref, c.axis, c.theta_ref, c.twist_rate,
                base.t, base.d1, base.rt, r.l0, r.cbend, r.ctwist, r.angle_law, r.kbar, r.mbar,
                r.stretch, has_body, b.radius if has_body else 0.0,
                b.length if has_body else 0.0, b.sigma if has_body else 0.0,
                b.strength if has_body else 0.0, b.c2 if has_body else 0.0, self.gravity)

    def _fused(self, y: np.ndarray, base: Frames):
        """The fused kernel alone: ``(G, x, theta, gx, gth, d1, rt, dist, E, Ec)``."""
        N = self.N
        G = np.empty(self.ny)
        x = np.empty((N, 3))
        theta = np.empty(N - 1)
        gx = np.empty((N, 3))
        gth = np.empty(N - 1)
        d1 = np.empty_like(base.d1)
        rt = np.empty_like(base.rt)
        dist = np.empty(N)
        E, Ec = SK.generalized_forces(np.ascontiguousarray(y), *self._kernel_args(base),
                                      G, x, theta, gx, gth, d1, rt, dist, self.body.shape_code)
        return G, x, theta, gx, gth, d1, rt, dist, E, Ec

    def forces(self, y: np.ndarray, base: Frames) -> ForceInfo:
        """Generalized forces ``G = -dU/dy`` and everything computed with them."""
        N = self.N
        G, x, theta, gx, gth, d1, rt, dist, E, Ec = self._fused(y, base)
        Ei = 0.0
        if self.interactions:
            gxe = np.zeros((N, 3))
            gthe = np.zeros(N - 1)
            for it in self.interactions:
                Ei += it.energy_grad(x, theta, gxe, gthe)
            G[self.sl_x] -= gxe[self.nc:].ravel()
            G[self.sl_th] -= gthe[self.ec:]
            gx += gxe
            gth += gthe
        t = np.empty((N - 1, 3))
        SK.unit_tangents(x, t)
        return ForceInfo(G, x, theta, Frames(t, d1, rt), E, Ec, gx, gth, dist, Ei)

    def interaction_jacobian_coo(self, y, which: str = "all"):
        """``-d^2U/dy^2`` of the interactions as triplets over the unknowns; ``which``: "all",
        "local" or "nonlocal" (by ``nonlocal_hessian``). Clamped coordinates are dropped."""
        parts = []
        if not self.interactions:
            return parts
        x, theta, _ = self.unpack(y)
        N, nc, ec = self.N, self.nc, self.ec
        x0, t0 = self.sl_x.start, self.sl_th.start
        for it in self.interactions:
            nl = bool(getattr(it, "nonlocal_hessian", False))
            if (which == "local" and nl) or (which == "nonlocal" and not nl):
                continue
            h = it.hessian_coo(x, theta) if hasattr(it, "hessian_coo") else None
            if h is None:
                continue
            r, c, v = (np.asarray(a) for a in h)
            idx = []
            for f in (r, c):
                bead = f < 3 * N
                yi = np.where(bead, x0 + f - 3 * nc, t0 + (f - 3 * N) - ec)
                ok = np.where(bead, f // 3 >= nc, (f - 3 * N) >= ec)
                idx.append((yi, ok))
            keep = idx[0][1] & idx[1][1]
            parts.append((idx[0][0][keep].astype(np.int64), idx[1][0][keep].astype(np.int64),
                          -np.asarray(v, float)[keep]))
        return parts

    def apply_mobility(self, y: np.ndarray, G: np.ndarray, single: bool = False) -> np.ndarray:
        """``Mob(y) G`` without the motor term; ``single``: to float32 accuracy
        (:meth:`Mobility.apply_single`), for the products inside an iterative solve."""
        out = np.empty_like(G)
        x, _, _ = self.unpack(y)
        Fx = G[self.sl_x].reshape(-1, 3)
        apply = self.mobility.apply_single if single else self.mobility.apply
        out[self.sl_x] = apply(x[self.nc:], Fx).ravel() / self.machin
        out[self.sl_th] = G[self.sl_th] / (self.machin * self.rot_drag[self.ec:])
        out[self.i_phi] = 0.0
        return out

    def velocity(self, y, info: ForceInfo, omega: float) -> np.ndarray:
        """``dy/dt`` at ``y`` from the forces ``info`` already computed there."""
        f = self.apply_mobility(y, info.G)
        f[self.i_phi] = self.motor_rate(y, info, omega)
        return f

    def motor_rate(self, y, info: ForceInfo, omega: float) -> float:
        """``dphi/dt``: the protocol's ``omega`` for a speed motor, the rotor's torque balance
        for a torque motor (:mod:`flagwrap.motor.drive`)."""
        if not self.drive.free:
            return omega
        return self.drive.rate(omega, self.motor_force(y, info))

    def motor_force(self, y, info: ForceInfo) -> float:
        """``G_phi = -dE/dphi``, the filament's elastic torque on the rotor [A/L]."""
        return -self.clamp.generalized_force(y[self.i_phi], info.grad_x, info.grad_theta)

    def motor_jacobian(self, y, base, omega: float):
        """For a torque motor: the motor's row of ``Mob J``, ``m dG_phi/dy`` by central
        differences over the unknowns the rotor couples to (the clamp's neighbours), ``m`` the
        drive's mobility; ``None`` for a speed motor, whose angle is prescribed. (The force
        Jacobian's motor-angle column is the kernel's own: ``force_jacobian_coo``.)"""
        if not self.drive.free:
            return None
        h = self.fd_step
        m = self.drive.mobility(omega)
        row = np.zeros(self.ny)
        near = [3 * k + c for k in range(min(3, self.nb)) for c in range(3)]
        near += [self.sl_th.start + j for j in range(min(3, self.ne))] + [self.i_phi]
        yp = np.array(y, float)
        for k in near:
            yp[k] = y[k] + h
            gp = self.motor_force(yp, self.forces(yp, base))
            yp[k] = y[k] - h
            gm = self.motor_force(yp, self.forces(yp, base))
            yp[k] = y[k]
            row[k] = m * (gp - gm) / (2 * h)
        return row

    def rhs(self, y, base, omega):
        info = self.forces(y, base)
        return self.velocity(y, info, omega), info

    def record_view(self, y, info: ForceInfo) -> ForceInfo:
        """The forces and geometry at ``y`` as the run file records them (the lab frame;
        here ``info`` itself)."""
        return info

    def local_mobility_diagonal(self) -> np.ndarray:
        """Diagonal of the self (no-HI) mobility in core units, (ny,); 0 for the motor angle."""
        d = np.zeros(self.ny)
        d[self.sl_x] = 1.0 / (6.0 * math.pi * self.radius * self.machin)
        d[self.sl_th] = self.twist_mobility
        return d

    def near_field_blocks(self, y: np.ndarray, width: int):
        """Near-field ``Mob`` (core units) for banded solvers: translational 3x3 blocks
        ``(nb, 2 width + 1, 3, 3)`` between beads at most ``width`` apart along the chain
        (only the self blocks for a local mobility) and the twist diagonal ``(ne,)``."""
        if not self.mobility.long_range:  # constant: computed once (HI off, every step)
            Mb = self.__dict__.get("_local_blocks")
            if Mb is None:
                Mb = self._local_blocks = (
                    self.mobility.near_field_blocks(np.zeros((self.nb, 3)), 0) / self.machin)
            return Mb, self.twist_mobility
        x, _, _ = self.unpack(y)
        Mb = self.mobility.near_field_blocks(x[self.nc:], width)
        Mb /= self.machin
        return Mb, self.twist_mobility

    def mobility_blocks(self, y: np.ndarray, reuse: bool = False, stage: bool = False):
        """``Mob`` as its two non-zero blocks: dense translational (3nb, 3nb), twist diagonal (ne,).

        ``reuse``: written into one buffer the system keeps (valid until the next such call):
        the time loop's dense W, which needs it once per step, then allocates nothing.
        ``stage``: the matrix the stage solver's ``W`` is built from, the mobility's
        ``stage_matrix`` where it has one (a W-method keeps its order for any ``W``), else
        the exact one."""
        x, _, _ = self.unpack(y)
        out = None
        if reuse:
            out = self.__dict__.get("_mxx_buffer")
            if out is None:
                out = self._mxx_buffer = np.empty((3 * self.nb, 3 * self.nb))
        build = getattr(self.mobility, "stage_matrix", None) if stage else None
        Mxx = (build or self.mobility.matrix)(x[self.nc:], out=out)
        Mxx /= self.machin
        return Mxx, self.twist_mobility

    def solver_memory(self) -> np.ndarray:
        """What the stage solver carries from one step to the next (a fixed no-slip body's
        lagged screening: :meth:`~flagwrap.body.solver.LaggedScreening.memory`), flattened;
        empty where it carries nothing. Checkpoints keep it."""
        get = getattr(self.mobility, "solver_memory", None)
        return get() if get else np.zeros(0)

    def restore_solver_memory(self, memory) -> None:
        """Continue from :meth:`solver_memory` (empty: start afresh)."""
        restore = getattr(self.mobility, "restore_solver_memory", None)
        if restore:
            restore(memory)
        elif np.size(memory):
            raise ValueError("this system's stage solver carries no memory to restore")

    def mobility_matrix(self, y: np.ndarray) -> np.ndarray:
        """Dense ``Mob(y)`` (ny, ny)."""
        x, _, _ = self.unpack(y)
        Mob = np.zeros((self.ny, self.ny))
        n3 = 3 * self.nb
        Mob[:n3, :n3] = self.mobility.matrix(x[self.nc:]) / self.machin
        idx = np.arange(n3, n3 + self.ne)
        Mob[idx, idx] = self.twist_mobility
        return Mob

    # Jacobian by coloured finite differences ------------------------------------------------
    def _build_colors(self):
        """Groups of columns whose force stencils are disjoint (5 apart along the chain)."""
        nb, nc, ec = self.nb, self.nc, self.ec
        groups = []

        def stencil_rows(beads, bonds):  # the free unknowns among these beads and bonds
            rows = []
            for m in beads:
                if nc <= m < self.N:
                    rows += [3 * (m - nc) + c for c in range(3)]
            for j in bonds:
                if ec <= j < self.N - 1:
                    rows.append(3 * nb + (j - ec))
            return rows

        def bead_rows(k):  # k: full bead index; rows affected: beads k-2..k+2, bonds k-2..k+1
            return stencil_rows(range(k - 2, k + 3), range(k - 2, k + 2))

        def edge_rows(j):  # bond j: beads j-1..j+2, bonds j-1..j+1
            return stencil_rows(range(j - 1, j + 3), range(j - 1, j + 2))

        def group(members, column, rows_of):  # one colour: columns and their (row, col) pairs
            cols, rows_l, cols_l = [], [], []
            for k in members:
                col = column(k)
                cols.append(col)
                rr = rows_of(k)
                rows_l += rr
                cols_l += [col] * len(rr)
            if cols:
                groups.append((np.array(cols), np.array(rows_l), np.array(cols_l)))

        for start in range(5):
            for c in range(3):
                group(range(nc + start, self.N, 5), lambda k, c=c: 3 * (k - nc) + c, bead_rows)
        for start in range(5):
            group(range(ec + start, self.N - 1, 5), lambda j: 3 * nb + (j - ec), edge_rows)
        self._colors = groups
        g_ptr = np.cumsum([0] + [len(g[0]) for g in groups]).astype(np.int64)
        e_ptr = np.cumsum([0] + [len(g[1]) for g in groups]).astype(np.int64)
        self._colors_flat = (
            g_ptr, np.concatenate([g[0] for g in groups]).astype(np.int64),
            e_ptr, np.concatenate([g[1] for g in groups]).astype(np.int64),
            np.concatenate([g[2] for g in groups]).astype(np.int64),
        )

    def force_jacobian_coo(self, y: np.ndarray, base: Frames, G0: np.ndarray | None = None,
                           delta: float | None = None, nonlocal_terms: bool = True):
        """``dG/dy`` as COO triplets (rows, cols, vals; duplicates add), O(N) work and memory.

        ``delta``: difference step, default ``fd_step``. ``nonlocal_terms``: include the
        interactions whose Hessians couple beads far apart along the chain (the banded
        solvers pass False). The interactions' terms are their own Hessians
        (:meth:`interaction_jacobian_coo`), appended to the kernel's coloured differences.
        """
        if delta is None:
            delta = self.fd_step
        if self._colors is None:
            self._build_colors()
        if self.interactions:  # the kernel differences its own forces: it needs its own G
            G0 = self._fused(y, base)[0]
        elif G0 is None:
            G0 = self.forces(y, base).G
        g_ptr, g_cols, e_ptr, e_rows, e_cols = self._colors_flat
        trip = SK.fd_jacobian_coo(np.ascontiguousarray(y), G0, delta, g_ptr, g_cols, e_ptr,
                                  e_rows, e_cols, self.N, *self._kernel_args(base),
                                  self.body.shape_code)
        extra = self.interaction_jacobian_coo(y, "all" if nonlocal_terms else "local")
        if not extra:
            return trip
        return tuple(np.concatenate([trip[k]] + [e[k] for e in extra]) for k in range(3))

    def force_jacobian(self, y: np.ndarray, base: Frames, G0: np.ndarray | None = None,
                       delta: float | None = None) -> np.ndarray:
        """``dG/dy`` (ny, ny), dense: analytic stretching + coloured differences (~21 force calls)."""
        rows, cols, vals = self.force_jacobian_coo(y, base, G0, delta)
        J = np.empty((self.ny, self.ny))
        SK.scatter_dense(rows, cols, vals, J)
        return J

    def force_jacobian_sparse(self, y, base, G0=None, delta: float | None = None):
        """``dG/dy`` as a scipy CSR matrix, from :meth:`force_jacobian_coo` (the stage solvers
        take the triplets themselves; this is the API's sparse view of them)."""
        import scipy.sparse as sp

        rows, cols, vals = self.force_jacobian_coo(y, base, G0, delta)
        return sp.csr_matrix((vals, (rows, cols)), shape=(self.ny, self.ny))

    # observables ---------------------------------------------------------------------------
    def motor_torque(self, info: ForceInfo, phi: float, omega: float) -> float:
        """Axial torque the motor supplies [A/L], about the outward axis (positive = CCW).

        Torque balance on the driven DOF: ``N_m = dE/dphi + zeta_r0 omega`` with
        ``zeta_r0 = M 8 pi a^3 w_0`` the rotational drag of the clamped bond. A torque motor
        exerts its own torque (:mod:`flagwrap.motor.drive`) at the rate it turns.
        """
        dEdphi = self.clamp.generalized_force(phi, info.grad_x, info.grad_theta)
        if not self.drive.free:
            return dEdphi + self.machin * self.rot_drag[0] * omega
        return self.drive.torque(self.drive.rate(omega, -dEdphi), omega)
