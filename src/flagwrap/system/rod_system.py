"""The assembled physical system in core units: forces, mobilities, motor, state packing.

:class:`RodSystem` is built once from a :class:`flagwrap.params.Config` and is then a set of
pure functions of the state vector ``y``:

* ``y = [x_free (3 n_b), theta_free (n_e), phi (n_f)]``: positions of the free beads (those
  the joints do not hold: 2..N-1 of one clamped filament), twist angles of the free bonds
  (1..N-2) and the motor angles, every filament's blocks one after the other
  (:mod:`flagwrap.system.parts`; one filament is the paper's rig);
* generalized forces ``G(y) = -dU/dy`` (elastic + contact + gravity), ``G_phi = 0``;
* equation of motion (paper, Methods, Stokesian dynamics): ``dy/dt = Mob(y) G(y) + omega(t) e_phi``
  with ``Mob = (1/M) blockdiag(mu_hat_RPY, 1/(8 pi a^3 w_j), 0)`` (a torque motor's angle
  follows its own torque balance instead: :mod:`flagwrap.motor.drive`).

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
from flagwrap.body.cell_body import BodyContact, NoBody, ShapeContact, body_mobility
from flagwrap.elasticity.rod import Frames
from flagwrap.hydrodynamics.mobility import make_mobility
from flagwrap.hydrodynamics.tube import TubeMobility
from flagwrap.hydrodynamics.wall import WallMobility, config_wall
from flagwrap.motor.drive import make_drive
from flagwrap.motor.protocol import motor_schedule
from flagwrap.system.layout import DofLayout
from flagwrap.system.parts import build_parts, config_tube


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
    #: the polymorph state's own energy (P3) (docs/polymorph.md), 0 without one
    polymorph_energy: float = 0.0


def motor_omega(omega, k: int) -> float:
    """Motor ``k``'s speed from the schedule's ``omega``: one value for every motor, or one
    per motor (:class:`~flagwrap.motor.protocol.MotorSchedules`)."""
    return omega if np.ndim(omega) == 0 else float(omega[k])


class MixedDrives:
    """Motors of different laws (``[[flagellum]] kind``): ``free`` when any angle is an
    unknown; the system asks ``drives[k]`` for each motor's rate, torque and mobility."""

    kind = "mixed"

    def __init__(self, drives):
        self.drives = tuple(drives)
        self.free = any(d.free for d in self.drives)

    def __getitem__(self, k):
        return self.drives[k]


class SeveralFilaments(TypeError):
    """A single-filament attribute (``joint``, ``rest``, ``nc`` ...) asked of a system of
    several filaments: ask ``system.parts[k]`` instead."""


def _one_filament(name: str):
    """A property that is the only filament's ``name`` (settable, e.g. by tests that swap
    a joint) and refuses by name on a system of several."""

    def get(self):
        if len(self.parts) != 1:
            raise SeveralFilaments(
                f"RodSystem.{name}: this system has {len(self.parts)} filaments; read "
                f"system.parts[k].{name} for filament k")
        return getattr(self.parts[0], name)

    def put(self, value):
        if len(self.parts) != 1:
            raise SeveralFilaments(f"RodSystem.{name}: set it on system.parts[k]")
        setattr(self.parts[0], name, value)

    return property(get, put)


class RodSystem:
    """Forces, mobility and bookkeeping of one run (core units): one or several filaments
    (:class:`~flagwrap.system.parts.FilamentPart`), each on its motor, a body and one mobility
    over all their free beads."""

    joint = clamp = _one_filament("joint")
    rest = _one_filament("rest")
    nc = _one_filament("nc")
    ec = _one_filament("ec")

    def __init__(self, config, x0=None, theta0=None, body=None, clamp=None, mobility=None,
                 joint=None, interactions=(), placements=None, drive=None):
        """``joint`` (or its old name ``clamp``): a built joint for the shape ``x0`` (default:
        :func:`flagwrap.joints.make_joint` from ``config.joint``); ``interactions``: extra
        energy terms (:mod:`flagwrap.interactions.base`) after those the config asks for;
        ``placements``: one :class:`~flagwrap.system.parts.Placement` per filament (default:
        the config's ``[[flagellum]]`` tables, or one filament at the origin), each a copy
        of the config's filament and joint on its own motor of ``config.motor``'s law and
        protocol (speed motors turn together; torque motors each at its own load);
        ``drive``: a motor law object (:mod:`flagwrap.motor.drive`'s interface), every
        motor's (default: :func:`~flagwrap.motor.drive.make_drive` of ``config.motor``, or of
        each ``[[flagellum]]`` table's own ``kind``: ``drives[k]``)."""
        self.config = config
        fil = config.filament
        L = fil.length
        self.scales = config.scales
        self.machin = config.machin
        b = fil.bond_length / L
        self.bond = b
        # Step of the coloured finite-difference Jacobian, a fixed fraction of the bond: bending
        # and twist forces depend on displacements through angles ~ dx / b, so this keeps the
        # relative accuracy of J the same at every N (measured: docs/numerics.md, "Cost").
        self.fd_step = 6e-6 * b
        self.radius = fil.bead_radius / L  # hydrodynamics (radius in core units)
        parts = self.parts = build_parts(config, placements, x0, theta0, joint or clamp)
        # the motor laws, one per motor (a [[flagellum]] table may set its own): the angles
        # are unknowns (layout kind "angle") when any law is free
        if drive is not None:
            self.drives = (drive,) * len(parts)
        else:
            laws = [f.motor(config.motor) for f in config.flagella]
            if len(laws) != len(parts) or all(m == config.motor for m in laws):
                laws = [config.motor] * len(parts)  # one law for every motor
            self.drives = tuple(make_drive(config if m is config.motor else
                                           config.replace(motor=m), zeta=self.machin * p.rot_drag[0])
                                for m, p in zip(laws, parts))
        self.drive = (self.drives[0] if len({type(d) for d in self.drives}) == 1
                      and all(vars(d) == vars(self.drives[0]) for d in self.drives)
                      else MixedDrives(self.drives))
        self._assemble(config)
        num = config.numerics
        #: the no-slip plane (``[[wall]]``) in core units, or None
        self.wall = config_wall(config)
        #: the no-slip tube (``[[tube]]``, :class:`flagwrap.confinement.tube.Tube`) in core
        #: units, or None
        self.tube = config_tube(config)
        if mobility is None:
            mobility = body_mobility(config, self.radius, self.wall)
        if mobility is None:
            mobility = make_mobility(num.hydrodynamics, self.radius, backend=num.mobility_backend,
                                     n=self.N, threads=num.threads, fmm_eps=num.mobility_tol)
            if self.wall is not None and num.hydrodynamics:
                mobility = WallMobility(mobility, self.wall)
        self.mobility = mobility
        if fil.hydrodynamic_model == "tube" and not isinstance(self.mobility, TubeMobility):
            # each filament's free beads, in the mobility's order (flagwrap.hydrodynamics.tube)
            ends = np.cumsum([0] + [p.nb for p in parts])
            self.mobility = TubeMobility(self.mobility, np.stack([ends[:-1], ends[1:]], 1),
                                         fil.tube_kappa)
        # cell body: its shape (flagwrap.body.shapes) and contact
        if config.body.enabled:
            from flagwrap.body.shapes import config_shape

            self.body = body or BodyContact(
                config_shape(config),
                cutoff=fil.cross_section_radius * (1.0 + config.contact.range) / L,
                strength=config.contact.strength / b,
                first_bead=parts[0].nc,
                potential=config.contact.potential,
            )
        else:
            self.body = body or NoBody()
        # the fused kernel evaluates the shapes it knows; any other is an interaction
        self._has_body = bool(self.body.fused)
        self._shape_contact = None
        if not self.body.fused and self.body.body_shape is not None:
            active = np.ones(self.N, bool)
            for p in parts:
                active[p.bead0:p.bead0 + p.nc] = False
            self._shape_contact = ShapeContact(self.body, active)
        self.schedule = motor_schedule(config)
        n_own = np.size(self.schedule.segments[0].omega)
        if n_own > 1 and n_own != len(parts):
            raise ValueError(f"RodSystem: {n_own} [[flagellum]] protocols for {len(parts)} "
                             "filaments (placements given apart from the config's tables?)")
        self.interactions = self._config_interactions() + list(interactions)
        if self._shape_contact is not None:
            self.interactions.insert(0, self._shape_contact)

    def _assemble(self, config) -> None:
        """Offsets of every part's beads, bonds and unknowns; the system's layout and its
        concatenated rest shape, frames, drags and gravity (module docstring of
        :mod:`flagwrap.system.parts`)."""
        parts = self.parts
        single = len(parts) == 1
        self.n_filaments = len(parts)
        self.N = sum(p.N for p in parts)
        self.nb = sum(p.nb for p in parts)  # free beads
        self.ne = sum(p.ne for p in parts)  # free bonds
        motor = "angle" if self.drive.free else "prescribed"
        self.layout = DofLayout.clamped_filament(self.nb, self.ne, motor, n_motors=len(parts))
        self.ny = self.layout.size
        #: the filaments' unknowns ``[x, theta, phi]``, the first ``n_rod`` of ``y``; a system
        #: with more parts after them (a free body's pose: :mod:`flagwrap.system.swimmer`)
        #: has ``ny > n_rod``
        self.n_rod = self.ny
        self.sl_x = self.layout["x"]
        self.sl_th = self.layout["theta"]
        self.sl_phi = self.layout["phi"]
        self.i_phi = self.sl_phi.start  # the (first) motor angle's index in y
        # the fused kernels and the dense/banded W assemblies take y in this block order
        assert [b.name for b in self.layout.blocks] == ["x", "theta", "phi"], self.layout
        bead0 = bond0 = fb0 = fe0 = 0
        for k, p in enumerate(parts):
            p.assign_offsets(bead0, bond0, fb0, fe0, self.sl_th.start, self.i_phi + k, single)
            bead0, bond0, fb0, fe0 = bead0 + p.N, bond0 + p.N - 1, fb0 + p.nb, fe0 + p.ne
        cat = np.concatenate
        if single:
            p = parts[0]
            self.free_beads, self.free_bonds = slice(p.nc, None), slice(p.ec, None)
            self.x0, self.theta0, self.frames0 = p.x0, p.theta0, p.frames0
            self.rot_drag, self.gravity, self.l0 = p.rot_drag, p.gravity, p.rest.l0
        else:
            self.free_beads = cat([np.arange(p.bead0 + p.nc, p.bead0 + p.N) for p in parts])
            self.free_bonds = cat([np.arange(p.bond0 + p.ec, p.bond0 + p.N - 1) for p in parts])
            self.x0 = cat([p.x0 for p in parts])
            self.theta0 = cat([p.theta0 for p in parts])
            self.frames0 = Frames(cat([p.frames0.t for p in parts]),
                                  cat([p.frames0.d1 for p in parts]),
                                  cat([p.frames0.rt for p in parts]))
            self.rot_drag = cat([p.rot_drag for p in parts])
            self.gravity = cat([p.gravity for p in parts])
            self.l0 = cat([p.rest.l0 for p in parts])
        #: the system's bead and bond numbers of the free unknowns, in y's order
        self.free_bead_ids = np.arange(self.N)[self.free_beads]
        self.free_bond_ids = np.arange(self.N - len(parts))[self.free_bonds]
        #: bond j joins beads bond_first[j] and bond_first[j] + 1
        self.bond_first = cat([p.bead0 + np.arange(p.N - 1) for p in parts])
        self._rot_drag_free = self.rot_drag[self.free_bonds]  # once: no indexing per product
        self.twist_mobility = 1.0 / (self.machin * self._rot_drag_free)  # core
        # y index of every bead coordinate (3 i + c) and bond twist (3 N + j); -1 if held
        coord = np.full(3 * self.N + self.N - len(parts), -1, np.int64)
        coord[(3 * self.free_bead_ids[:, None] + np.arange(3)).ravel()] = np.arange(3 * self.nb)
        coord[3 * self.N + self.free_bond_ids] = self.sl_th.start + np.arange(self.ne)
        self._coord_y = coord

    def _config_interactions(self) -> list:
        c = self.config.contact
        out = []
        if self.wall is not None or self.tube is not None:
            from flagwrap.interactions.wall import TubeContact, WallContact, contact_law

            active = np.ones(self.N, bool)  # the joints' beads: the motor holds them
            for p in self.parts:
                active[p.bead0:p.bead0 + p.nc] = False
            cutoff, strength, c2 = contact_law(self.config, self.bond)
            for cls, boundary in ((WallContact, self.wall), (TubeContact, self.tube)):
                if boundary is not None:
                    out.append(cls(boundary, cutoff, strength, active, c2=c2))
        if not c.self_contact:
            return out
        from flagwrap.interactions.self_contact import SelfContact, SelfContactInteraction

        sc = SelfContact(self.config.filament.cross_section_radius / self.config.filament.length,
                         self.bond, range=c.resolved_self_range,
                         strength=c.resolved_self_strength / self.bond,
                         c2=1.0 if c.potential == "wca-c2" else 0.0, rest_lengths=self.l0,
                         chains=None if len(self.parts) == 1 else [p.N for p in self.parts])
        return out + [SelfContactInteraction(sc)]

    # packing -------------------------------------------------------------------------------
    def initial_y(self) -> np.ndarray:
        """The initial state: the rest shape, displaced by ``config.initial`` if it asks
        (the clamp's beads are not free unknowns, so they stay where the clamp holds them;
        filament ``k`` takes the displacement of seed ``initial.seed + k``)."""
        ini = self.config.initial
        if ini.perturbation == 0.0:
            self._check_outside_body(self.x0)
            return self.pack(self.x0, self.theta0, 0.0)
        from flagwrap.geometry.perturbation import displacement

        dx = np.zeros_like(self.x0)
        for k, p in enumerate(self.parts):
            d = displacement(p.N, ini.perturbation / self.config.filament.length, ini.mode,
                             ini.seed + k)
            d[:p.nc] = 0.0  # the clamp's beads are where the clamp holds them
            dx[p.beads] = d
        self._check_outside_body(self.x0 + dx)
        return self.pack(self.x0 + dx, self.theta0, 0.0)

    def _check_outside_body(self, x) -> None:
        """Refuse a start with a free bead's centre inside the cell body (one line, exit 2)."""
        d = self.body.distance(x[self.free_beads])
        if d.size and d.min() <= 0.0:
            from flagwrap.errors import UserInputError

            i = int(np.argmin(d))
            L = self.config.filament.length
            raise UserInputError(
                f"body overlaps the filament at the start: bead {self.free_bead_ids[i]} is "
                f"{-d[i] * L:.3g} m inside the cell body (initial.perturbation = "
                f"{self.config.initial.perturbation:g} m, filament.n_beads = "
                f"{self.config.filament.n_beads}); "
                "use a smaller initial.perturbation, another initial.seed, or more beads")

    def pack(self, x, theta, phi) -> np.ndarray:
        """``y`` from all beads ``x`` (N, 3), all twist angles and the motor angle(s)."""
        y = np.empty(self.ny)
        y[self.sl_x] = x[self.free_beads].ravel()
        y[self.sl_th] = theta[self.free_bonds]
        y[self.sl_phi] = phi
        return y

    def unpack(self, y):
        """``(x (N, 3), theta (N - n_filaments,), phi)``: every filament's beads and bonds in
        order, each joint's beads at its own motor's angle; ``phi`` the first motor's angle."""
        x = np.empty((self.N, 3))
        theta = np.empty(self.N - len(self.parts))
        for k, p in enumerate(self.parts):
            phik = y[self.i_phi + k]
            x[p.bead0:p.bead0 + p.nc] = p.joint.positions(phik)
            theta[p.bond0:p.bond0 + p.ec] = p.joint.theta(phik)
        x[self.free_beads] = y[self.sl_x].reshape(-1, 3)
        theta[self.free_bonds] = y[self.sl_th]
        return x, theta, y[self.i_phi]

    def free_positions(self, y) -> np.ndarray:
        """The free beads' positions (nb, 3), every filament's in order: ``y``'s own, a view
        (what the mobilities act on; no unpacking of the held beads)."""
        return y[self.sl_x].reshape(-1, 3)

    def bond_lengths(self, x) -> np.ndarray:
        """Every bond's length, (N - n_filaments,), in the order of ``l0``."""
        if len(self.parts) == 1:
            return np.linalg.norm(np.diff(x, axis=0), axis=1)
        return np.linalg.norm(x[self.bond_first + 1] - x[self.bond_first], axis=1)

    # forces --------------------------------------------------------------------------------
    def _fused(self, y: np.ndarray, base: Frames):
        """The fused kernel alone, part by part: ``(G, x, theta, gx, gth, d1, rt, dist, E, Ec)``."""
        N = self.N
        G = np.empty(self.ny)
        G[self.n_rod:] = 0.0  # nothing depends on a free body's pose
        x = np.empty((N, 3))
        theta = np.empty(N - len(self.parts))
        gx = np.empty((N, 3))
        gth = np.empty(N - len(self.parts))
        d1 = np.empty_like(base.d1)
        rt = np.empty_like(base.rt)
        dist = np.empty(N)
        y = np.ascontiguousarray(y)
        E = Ec = 0.0
        for p in self.parts:
            v, e = p.beads, p.bonds
            yk, Gk = ((y[:self.n_rod], G[:self.n_rod]) if p.ymap is None
                      else (y[p.ymap], np.empty(p.ny)))
            Ek, Eck = SK.generalized_forces(
                yk, *p.kernel_args(base, self.body, self._has_body), Gk, x[v], theta[e], gx[v],
                gth[e], d1[e], rt[v], dist[v], self.body.shape_code)
            if p.ymap is not None:
                G[p.ymap] = Gk
            E += Ek
            Ec += Eck
        return G, x, theta, gx, gth, d1, rt, dist, E, Ec

    def forces(self, y: np.ndarray, base: Frames) -> ForceInfo:
        """Generalized forces ``G = -dU/dy`` and everything computed with them."""
        N = self.N
        G, x, theta, gx, gth, d1, rt, dist, E, Ec = self._fused(y, base)
        Ei = 0.0
        if self.interactions:
            gxe = np.zeros((N, 3))
            gthe = np.zeros(len(theta))
            for it in self.interactions:
                Ei += it.energy_grad(x, theta, gxe, gthe)
            sc = self._shape_contact
            if sc is not None:  # the body's contact, reported as the fused kernel's would be
                Ei -= sc.energy
                Ec += sc.energy
                dist = sc.distance
            G[self.sl_x] -= gxe[self.free_beads].ravel()
            G[self.sl_th] -= gthe[self.free_bonds]
            gx += gxe
            gth += gthe
        t = np.empty((len(theta), 3))
        for p in self.parts:
            SK.unit_tangents(x[p.beads], t[p.bonds])
        return ForceInfo(G, x, theta, Frames(t, d1, rt), E, Ec, gx, gth, dist, Ei)

    def interaction_jacobian_coo(self, y, which: str = "all", stage: bool = False):
        """``-d^2U/dy^2`` of the interactions as triplets over the unknowns; ``which``: "all",
        "local" or "nonlocal" (by ``nonlocal_hessian``). Held coordinates are dropped.
        ``stage``: for the stage solver's ``W``: an interaction's ``stage_hessian_coo`` where
        it has one (:mod:`flagwrap.interactions.base`), its exact Hessian otherwise."""
        parts = []
        if not self.interactions:
            return parts
        x, theta, _ = self.unpack(y)
        for it in self.interactions:
            nl = bool(getattr(it, "nonlocal_hessian", False))
            if (which == "local" and nl) or (which == "nonlocal" and not nl):
                continue
            if stage and hasattr(it, "stage_hessian_coo"):
                h = it.stage_hessian_coo(x, theta)
            else:
                h = it.hessian_coo(x, theta) if hasattr(it, "hessian_coo") else None
            if h is None:
                continue
            r, c, v = (np.asarray(a) for a in h)
            yr, yc = self._coord_y[r], self._coord_y[c]
            keep = (yr >= 0) & (yc >= 0)
            parts.append((yr[keep].astype(np.int64), yc[keep].astype(np.int64),
                          -np.asarray(v, float)[keep]))
        return parts

    def apply_mobility(self, y: np.ndarray, G: np.ndarray, single: bool = False) -> np.ndarray:
        """``Mob(y) G`` without the motor term; ``single``: to float32 accuracy
        (:meth:`Mobility.apply_single`), for the products inside an iterative solve."""
        out = np.empty_like(G)
        Fx = G[self.sl_x].reshape(-1, 3)
        apply = self.mobility.apply_single if single else self.mobility.apply
        out[self.sl_x] = apply(self.free_positions(y), Fx).ravel() / self.machin
        out[self.sl_th] = G[self.sl_th] / (self.machin * self._rot_drag_free)
        out[self.sl_phi] = 0.0
        return out

    def velocity(self, y, info: ForceInfo, omega: float) -> np.ndarray:
        """``dy/dt`` at ``y`` from the forces ``info`` already computed there."""
        f = self.apply_mobility(y, info.G)
        f[self.sl_phi] = self.motor_rate(y, info, omega)
        return f

    def motor_rate(self, y, info: ForceInfo, omega: float):
        """``dphi/dt``: the protocol's ``omega`` for a speed motor, the rotor's torque balance
        for a torque motor (:mod:`flagwrap.motor.drive`); with several torque motors an
        array, each at its own load."""
        if not self.drive.free:
            return omega
        if len(self.parts) == 1:
            return self.drive.rate(motor_omega(omega, 0), self.motor_force(y, info))
        return np.array([d.rate(motor_omega(omega, k), self.motor_force(y, info, k)) if d.free
                         else motor_omega(omega, k) for k, d in enumerate(self.drives)])

    def motor_force(self, y, info: ForceInfo, motor: int = 0) -> float:
        """``G_phi = -dE/dphi`` of motor ``motor``, its filament's elastic torque on the rotor
        [A/L]."""
        if len(self.parts) == 1:
            return -self.clamp.generalized_force(y[self.i_phi], info.grad_x, info.grad_theta)
        p = self.parts[motor]
        return -p.joint.generalized_force(y[self.i_phi + motor], info.grad_x[p.beads],
                                          info.grad_theta[p.bonds])

    def motor_jacobian(self, y, base, omega: float):
        """For torque motors: each motor's row of ``Mob J`` (n_motors, ny), ``m dG_phi/dy`` by
        central differences over the unknowns its rotor couples to (its clamp's neighbours),
        ``m`` the drive's mobility; ``None`` for speed motors, whose angles are prescribed.
        (The force Jacobian's motor-angle columns are the kernel's own: ``force_jacobian_coo``.)"""
        if not self.drive.free:
            return None
        h = self.fd_step
        rows = np.zeros((len(self.parts), len(y)))
        yp = np.array(y, float)
        for motor, p in enumerate(self.parts):
            if not self.drives[motor].free:  # a speed motor's row: dphi/dt = omega, zero
                continue
            m = self.drives[motor].mobility(motor_omega(omega, motor))
            near = [3 * k + c for k in range(min(3, p.nb)) for c in range(3)]
            near += [3 * p.nb + j for j in range(min(3, p.ne))] + [p.ny - 1]  # its own order
            if p.ymap is not None:
                near = p.ymap[near]
            for k in near:
                yp[k] = y[k] + h
                gp = self.motor_force(yp, self.forces(yp, base), motor)
                yp[k] = y[k] - h
                gm = self.motor_force(yp, self.forces(yp, base), motor)
                yp[k] = y[k]
                rows[motor, k] = m * (gp - gm) / (2 * h)
        return rows

    def rhs(self, y, base, omega):
        info = self.forces(y, base)
        return self.velocity(y, info, omega), info

    def record_view(self, y, info: ForceInfo) -> ForceInfo:
        """The forces and geometry at ``y`` as the run file records them (the lab frame;
        here ``info`` itself)."""
        return info

    def joint_observables(self, info: ForceInfo, m1, m2) -> tuple[float, float, float]:
        """The first filament's joint angle and torques (:meth:`Joint.observables`) from the
        lab-frame ``info`` and its material frames ``m1``, ``m2`` (all bonds)."""
        p = self.parts[0]
        v, e = p.beads, p.bonds
        frames = info.frames if len(self.parts) == 1 else Frames(
            info.frames.t[e], info.frames.d1[e], info.frames.rt[v])
        return p.joint.observables(info.x[v], info.theta[e], m1[e], m2[e], frames, p.rest)

    def local_mobility_diagonal(self) -> np.ndarray:
        """Diagonal of the self (no-HI) mobility in core units, (ny,); 0 for the motor angle."""
        d = np.zeros(self.ny)
        d[self.sl_x] = 1.0 / (6.0 * math.pi * self.radius * self.machin)
        d[self.sl_th] = self.twist_mobility
        return d

    def near_field_blocks(self, y: np.ndarray, width: int):
        """Near-field ``Mob`` (core units) for banded solvers: translational 3x3 blocks
        ``(nb, 2 width + 1, 3, 3)`` between free beads at most ``width`` apart in y's order
        (along the chain; only the self blocks for a local mobility) and the twist diagonal
        ``(ne,)``."""
        if not self.mobility.long_range:  # constant: computed once (HI off, every step)
            Mb = self.__dict__.get("_local_blocks")
            if Mb is None:
                Mb = self._local_blocks = (
                    self.mobility.near_field_blocks(np.zeros((self.nb, 3)), 0) / self.machin)
            return Mb, self.twist_mobility
        Mb = self.mobility.near_field_blocks(self.free_positions(y), width)
        Mb /= self.machin
        return Mb, self.twist_mobility

    def mobility_blocks(self, y: np.ndarray, reuse: bool = False, stage: bool = False):
        """``Mob`` as its two non-zero blocks: dense translational (3nb, 3nb), twist diagonal (ne,).

        ``reuse``: written into one buffer the system keeps (valid until the next such call):
        the time loop's dense W, which needs it once per step, then allocates nothing.
        ``stage``: the matrix the stage solver's ``W`` is built from, the mobility's
        ``stage_matrix`` where it has one (a W-method keeps its order for any ``W``), else
        the exact one."""
        out = None
        if reuse:
            out = self.__dict__.get("_mxx_buffer")
            if out is None:
                out = self._mxx_buffer = np.empty((3 * self.nb, 3 * self.nb))
        build = getattr(self.mobility, "stage_matrix", None) if stage else None
        Mxx = (build or self.mobility.matrix)(self.free_positions(y), out=out)
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
        Mob = np.zeros((self.ny, self.ny))
        n3 = 3 * self.nb
        Mob[:n3, :n3] = self.mobility.matrix(self.free_positions(y)) / self.machin
        idx = np.arange(n3, n3 + self.ne)
        Mob[idx, idx] = self.twist_mobility
        return Mob

    # Jacobian by coloured finite differences ------------------------------------------------
    def force_jacobian_coo(self, y: np.ndarray, base: Frames, G0: np.ndarray | None = None,
                           delta: float | None = None, nonlocal_terms: bool = True,
                           stage: bool = False):
        """``dG/dy`` as COO triplets (rows, cols, vals; duplicates add), O(N) work and memory.

        ``delta``: difference step, default ``fd_step``. ``nonlocal_terms``: include the
        interactions whose Hessians couple beads far apart along the chain (the banded
        solvers pass False). Each filament's forces depend on its own unknowns only, so its
        block is the kernel's coloured differences on its unknowns
        (:meth:`FilamentPart.build_colors`); the interactions' terms are their own Hessians
        (:meth:`interaction_jacobian_coo`), appended; ``stage``: the stage solver's (exact
        otherwise, as :meth:`force_jacobian` and the stability tools take it).
        """
        if delta is None:
            delta = self.fd_step
        if self.interactions:  # the kernel differences its own forces: it needs its own G
            G0 = self._fused(y, base)[0]
        elif G0 is None:
            G0 = self.forces(y, base).G
        y = np.ascontiguousarray(y)
        trips = []
        for p in self.parts:
            colors = p.colors or p.build_colors()
            yk, Gk = ((y[:self.n_rod], G0[:self.n_rod]) if p.ymap is None
                      else (y[p.ymap], G0[p.ymap]))
            r, c, v = SK.fd_jacobian_coo(yk, Gk, delta, *colors, p.N,
                                         *p.kernel_args(base, self.body, self._has_body),
                                         self.body.shape_code)
            trips.append((r, c, v) if p.ymap is None else (p.ymap[r], p.ymap[c], v))
        trips += self.interaction_jacobian_coo(y, "all" if nonlocal_terms else "local", stage)
        if len(trips) == 1:
            return trips[0]
        return tuple(np.concatenate([t[k] for t in trips]) for k in range(3))

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
    def motor_torque(self, info: ForceInfo, phi: float, omega: float, y=None) -> float:
        """Axial torque the motor supplies [A/L], about the outward axis (positive = CCW);
        with several filaments, the sum over their motors (:meth:`motor_torques`; torque
        motors need the state ``y`` for their own angles).

        Torque balance on the driven DOF: ``N_m = dE/dphi + zeta_r0 omega`` with
        ``zeta_r0 = M 8 pi a^3 w_0`` the rotational drag of the clamped bond. A torque motor
        exerts its own torque (:mod:`flagwrap.motor.drive`) at the rate it turns.
        """
        if len(self.parts) > 1:
            return float(np.sum(self.motor_torques(info, phi, omega, y)))
        dEdphi = self.clamp.generalized_force(phi, info.grad_x, info.grad_theta)
        omega = motor_omega(omega, 0)
        if not self.drive.free:
            return dEdphi + self.machin * self.rot_drag[0] * omega
        return self.drive.torque(self.drive.rate(omega, -dEdphi), omega)

    def motor_torques(self, info: ForceInfo, phi: float, omega: float, y=None) -> np.ndarray:
        """Each motor's axial torque [A/L] about its own axis, (n_filaments,), each at its own
        angle in ``y`` (speed motors without ``y``: all at ``phi``) and its own speed in
        ``omega`` (:func:`motor_omega`)."""
        if len(self.parts) == 1:
            return np.array([self.motor_torque(info, phi, omega)])
        if self.drive.free and y is None:
            raise ValueError("motor_torques: torque motors need the state y")
        out = np.empty(len(self.parts))
        for k, (p, d) in enumerate(zip(self.parts, self.drives)):
            w = motor_omega(omega, k)
            if d.free:
                out[k] = d.torque(d.rate(w, self.motor_force(y, info, k)), w)
            else:
                out[k] = (p.joint.generalized_force(y[self.i_phi + k] if y is not None else phi,
                                                    info.grad_x[p.beads], info.grad_theta[p.bonds])
                          + self.machin * p.rot_drag[0] * w)
        return out
