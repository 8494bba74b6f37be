"""Steric contact of the filament's beads with a plane wall (``[[wall]]``; docs/confinement.md).

``U = sum_i u(d_i)``, ``d_i = (x_i - p) . n`` the height of bead ``i``'s centre above the plane
through ``p`` with unit normal ``n`` (into the fluid), and ``u`` the cell body's contact law
(:func:`flagwrap.body._kernels.wca_law`: WCA with cut-off ``a (1 + contact.range)``, energy
``contact.strength``), so that the filament meets a wall as it meets the body. The gradient is
``u'(d) n``; the Hessian ``u''(d) n n^T`` (a plane has no curvature). The joints' beads feel
none (the motor holds them).

The stage solver's ``W`` takes the Hessian with the law's stiffness *looked ahead*
(:meth:`_BoundaryContact.stage_law`): a bead within :data:`STAGE_LOOKAHEAD` of the repulsive
shell's width outside the cut-off, or anywhere inside it, gets at least the stiffness it would
have that far inside. The C2 law's stiffness is zero at the cut-off, so a bead resting there
carries none into ``W``, and a stage that moves it into the wall is then integrated
explicitly against a stiffness of ~1e6 (core units): measured on the constricted tube's
stall (docs/confinement.md, "C. insecticola into a constriction"), the exact ``W`` advanced
the run 0.004 of a period in 238 s, the lookahead 1-6 nm 0.031-0.036 in 200-240 s. The forces
are unchanged, and a W-method keeps its order for any ``W``; the exact Hessian
(:meth:`hessian_coo`) is what the stability tools take.
"""

from __future__ import annotations

import numpy as np

from flagwrap.body import _kernels as BK

#: the stage solver's lookahead into the contact, a fraction of the repulsive shell's width
#: ``cutoff - sigma`` (0.11 of the cut-off): half of it, 1.1 nm for a 10 nm bead at
#: ``contact.range = 1``, within the 1-6 nm measured to work alike (module docstring)
STAGE_LOOKAHEAD = 0.5


def contact_law(config, bond: float) -> tuple[float, float, float]:
    """``(cutoff, strength, c2)`` of ``[contact]``'s law in core units (``bond``: the
    filament's bond ``b/L``): what the filament's beads and a free body's blobs meet a wall
    with, as the beads meet the body."""
    fil, c = config.filament, config.contact
    return (fil.cross_section_radius * (1.0 + c.range) / fil.length, c.strength / bond,
            1.0 if c.potential == "wca-c2" else 0.0)


class _BoundaryContact:
    """The contact law's part shared by a plane and a tube: beads ``active`` meet a fixed
    boundary by ``u(d)`` on their distance ``d`` to it."""

    nonlocal_hessian = False
    rotation_invariant = False

    def __init__(self, cutoff: float, strength: float, active, c2: float = 1.0):
        self.cutoff = float(cutoff)
        self.sigma = self.cutoff / 2.0 ** (1.0 / 6.0)
        self.strength = float(strength)
        self.c2 = float(c2)
        self.active = np.asarray(active, bool)
        self.distance = None  # the last evaluation's distances
        self.energy = 0.0
        #: the stage solver's lookahead (module docstring) and the stiffness that far inside
        self.lookahead = STAGE_LOOKAHEAD * (self.cutoff - self.sigma)
        self._k_ahead = float(self.law([self.cutoff - self.lookahead])[2][0])

    def law(self, d):
        """``(u, u', u'')`` of the contact law at distances ``d``."""
        d = np.ascontiguousarray(d, dtype=np.float64)
        e, dU, d2U = np.empty(len(d)), np.empty(len(d)), np.empty(len(d))
        BK.wca_law(d, self.sigma, self.strength, self.c2, e, dU, d2U)
        return e, dU, d2U

    def stage_law(self, d):
        """:meth:`law` with ``u''`` raised to at least its value ``lookahead`` inside the
        cut-off wherever ``d < cutoff + lookahead`` (module docstring): for ``W`` only."""
        e, dU, d2U = self.law(d)
        near = np.asarray(d) < self.cutoff + self.lookahead
        d2U[near] = np.maximum(d2U[near], self._k_ahead)
        return e, dU, d2U

    def hessian_coo(self, x, theta):
        """``d^2U`` as COO triplets (:mod:`flagwrap.interactions.base`), exact."""
        return self._hessian(x, self.law)

    def stage_hessian_coo(self, x, theta):
        """The stage solver's ``d^2U``: the Hessian on :meth:`stage_law`."""
        return self._hessian(x, self.stage_law)


class WallContact(_BoundaryContact):
    """The interaction (:mod:`flagwrap.interactions.base`) of beads ``active`` with the plane
    ``wall`` (:class:`flagwrap.hydrodynamics.wall.PlaneWall`, core units)."""

    name = "wall contact"

    def __init__(self, wall, cutoff: float, strength: float, active, c2: float = 1.0):
        super().__init__(cutoff, strength, active, c2)
        self.wall = wall
        #: a plane square to the body axis is unchanged by turning about it
        self.rotation_invariant = wall.square_to_z

    def energy_grad(self, x, theta, grad_x, grad_theta) -> float:
        d = self.wall.heights(x)
        self.distance = d
        on = self.active
        e, dU, _ = self.law(d[on])
        grad_x[on] += dU[:, None] * self.wall.normal
        self.energy = float(e.sum())
        return self.energy

    def _hessian(self, x, law):
        d = self.wall.heights(x)
        _, _, d2U = law(np.where(self.active, d, np.inf))
        near = np.flatnonzero(d2U != 0.0)
        if near.size == 0:
            return None
        n = self.wall.normal
        H = d2U[near, None, None] * np.outer(n, n)[None]
        base = 3 * near[:, None, None]
        rows = np.broadcast_to(base + np.arange(3)[None, :, None], H.shape)
        cols = np.broadcast_to(base + np.arange(3)[None, None, :], H.shape)
        return rows.ravel(), cols.ravel(), H.ravel()


class TubeContact(_BoundaryContact):
    """The interaction of beads ``active`` with a tube's wall (``[[tube]]``,
    :class:`flagwrap.confinement.tube.Tube` in core units): the same law on each bead's gap
    ``g`` to the wall (:meth:`~flagwrap.confinement.tube.Tube.gap`); the gradient
    ``u'(g) grad g``, exact; the Hessian ``u'' grad g grad g^T + u' H_g`` with the straight
    tube's ``H_g = -(I - a a^T - r r^T) / r`` (the constriction's further terms are left to the
    W-method, which keeps its order for any W)."""

    name = "tube contact"

    def __init__(self, tube, cutoff: float, strength: float, active, c2: float = 1.0):
        super().__init__(cutoff, strength, active, c2)
        self.tube = tube
        self.rotation_invariant = tube.about_z  # a gap to an axisymmetric wall about z

    def energy_grad(self, x, theta, grad_x, grad_theta) -> float:
        g, dg, _, _ = self.tube.gap_gradient(x)
        self.distance = g
        on = self.active
        e, dU, _ = self.law(g[on])
        grad_x[on] += dU[:, None] * dg[on]
        self.energy = float(e.sum())
        return self.energy

    def _hessian(self, x, law):
        ids = np.flatnonzero(self.active)
        g, dg, rhat, r = self.tube.gap_gradient(x[ids])
        _, dU, d2U = law(g)
        near = np.flatnonzero(d2U != 0.0)
        if near.size == 0:
            return None
        a = np.asarray(self.tube.axis)
        P = np.eye(3)[None] - a[None, :, None] * a[None, None, :] - \
            rhat[near, :, None] * rhat[near, None, :]
        H = d2U[near, None, None] * dg[near, :, None] * dg[near, None, :] - \
            (dU[near] / np.maximum(r[near], 1e-300))[:, None, None] * P
        base = 3 * ids[near][:, None, None]
        rows = np.broadcast_to(base + np.arange(3)[None, :, None], H.shape)
        cols = np.broadcast_to(base + np.arange(3)[None, None, :], H.shape)
        return rows.ravel(), cols.ravel(), H.ravel()
