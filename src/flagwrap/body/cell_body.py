"""The cell body's contact: a shape (:mod:`flagwrap.body.shapes`) and the contact law."""

from __future__ import annotations

import numpy as np

from flagwrap.body import _kernels as K


class BodyContact:
    """The cell body's shape (:mod:`flagwrap.body.shapes`) and its contact law, in core
    units. The fluid passes through a transparent body (paper, Methods): it acts on the
    filament only by the WCA repulsion of range ``cutoff`` (bead centre to surface) and
    energy ``strength``.

    A shape the fused force kernel knows (``shape.kernel``) is evaluated there, in the same
    loop as the elasticity; any other shape's contact is an interaction of the system
    (:class:`ShapeContact`, through ``shape.signed_distance``).

    Parameters
    ----------
    shape : BodyShape
        the body's geometry (core units).
    cutoff : float
        distance from the surface below which beads are repelled (``a (1 + range)``).
    strength : float
        WCA energy ``eps`` (core energy units).
    first_bead : int
        beads with a smaller index (the clamp) feel no contact force.
    potential : {"wca-c2", "wca"}
        the contact law (:func:`flagwrap.body._kernels.wca_energy_grad`): WCA with its
        curvature at the cut-off removed (force derivative continuous, default) or plain WCA.
    """

    POTENTIALS = {"wca-c2": 1.0, "wca": 0.0}

    def __init__(self, shape, cutoff, strength, first_bead=2, potential="wca-c2"):
        if potential not in self.POTENTIALS:
            raise ValueError(f"contact potential must be one of {tuple(self.POTENTIALS)}, got {potential!r}")
        self.potential = potential
        self.c2 = self.POTENTIALS[potential]
        self.body_shape = shape
        self.cutoff = float(cutoff)
        self.sigma = self.cutoff / 2.0 ** (1.0 / 6.0)
        self.strength = float(strength)
        self.first_bead = int(first_bead)
        k = shape.kernel
        #: the fused kernel evaluates this body (a shape it knows)
        self.fused = k is not None
        self.shape_code, self.radius, self.length = k if self.fused else (0, 0.0, 0.0)

    @property
    def shape(self) -> str:
        return self.body_shape.name

    def energy_grad(self, x: np.ndarray, grad: np.ndarray, dist: np.ndarray) -> float:
        """Adds ``dU/dx`` into ``grad`` and writes signed distances into ``dist``."""
        if self.fused:
            return K.wca_energy_grad(x, self.first_bead, self.radius, self.length, self.sigma,
                                     self.strength, self.c2, grad, dist, self.shape_code)
        d, n = self.body_shape.signed_distance(x)
        dist[:] = d
        e, dU, _ = self.law(d[self.first_bead:])
        grad[self.first_bead:] += dU[:, None] * n[self.first_bead:]
        return float(e.sum())

    def law(self, d):
        """``(U, dU/dd, d^2U/dd^2)`` of the contact at distances ``d``."""
        d = np.ascontiguousarray(d, dtype=np.float64)
        e, dU, d2U = np.empty(len(d)), np.empty(len(d)), np.empty(len(d))
        K.wca_law(d, self.sigma, self.strength, self.c2, e, dU, d2U)
        return e, dU, d2U

    def distance(self, x: np.ndarray) -> np.ndarray:
        """Signed distance of each point to the surface (negative inside)."""
        return self.body_shape.signed_distance(np.ascontiguousarray(x, dtype=np.float64))[0]


def CappedCylinder(radius, length, cutoff, strength, first_bead=2, potential="wca-c2",
                   shape="capped-cylinder") -> BodyContact:
    """The contact of the built-in shape ``shape`` of ``radius`` and ``length`` (core units;
    :func:`flagwrap.body.shapes.make_shape`)."""
    from flagwrap.body.shapes import make_shape

    return BodyContact(make_shape(shape, radius, length), cutoff, strength, first_bead,
                       potential)


class ShapeContact:
    """The body contact of a shape the fused kernel does not know, as an interaction of the
    system (:mod:`flagwrap.interactions.base`): ``U = sum_i u(d_i)`` over the beads
    ``active`` (the joints' beads feel none), ``d_i`` the shape's signed distance.

    Its Hessian ``u'' n n^T + u' dn/dx`` per bead in range, ``dn/dx`` (the surface's
    curvature) by central differences of the shape's gradient. ``distance`` and ``energy``:
    the last evaluation's (the system reports them as the body's)."""

    name = "body contact"
    nonlocal_hessian = False

    def __init__(self, contact: BodyContact, active):
        self.contact = contact
        self.active = np.asarray(active, bool)
        self.rotation_invariant = bool(contact.body_shape.axisymmetric)
        self.distance = None
        self.energy = 0.0

    def energy_grad(self, x, theta, grad_x, grad_theta) -> float:
        d, n = self.contact.body_shape.signed_distance(np.ascontiguousarray(x, dtype=np.float64))
        self.distance = d
        on = self.active
        e, dU, _ = self.contact.law(d[on])
        grad_x[on] += dU[:, None] * n[on]
        self.energy = float(e.sum())
        return self.energy

    def hessian_coo(self, x, theta):
        shape = self.contact.body_shape
        x = np.ascontiguousarray(x, dtype=np.float64)
        d, n = shape.signed_distance(x)
        _, dU, d2U = self.contact.law(np.where(self.active, d, np.inf))
        near = np.flatnonzero(dU != 0.0)
        if near.size == 0:
            return None
        xn = x[near]
        h = 1e-6 * max(self.contact.cutoff, 1e-12)
        dn = np.empty((len(near), 3, 3))  # dn[i, :, c] = d n / d x_c
        for c in range(3):
            xp, xm = xn.copy(), xn.copy()
            xp[:, c] += h
            xm[:, c] -= h
            dn[:, :, c] = (shape.signed_distance(xp)[1] - shape.signed_distance(xm)[1]) / (2 * h)
        nn = n[near]
        H = d2U[near, None, None] * nn[:, :, None] * nn[:, None, :] + dU[near, None, None] * dn
        H = 0.5 * (H + H.transpose(0, 2, 1))
        base = 3 * near[:, None, None]
        rows = np.broadcast_to(base + np.arange(3)[None, :, None], H.shape)
        cols = np.broadcast_to(base + np.arange(3)[None, None, :], H.shape)
        return rows.ravel(), cols.ravel(), H.ravel()


class NoBody:
    """No cell body (an isolated filament)."""

    radius = 0.0
    length = 0.0
    first_bead = 0
    c2 = 0.0
    shape = "none"
    shape_code = 0
    fused = False
    body_shape = None

    def energy_grad(self, x, grad, dist):
        dist[:] = np.inf
        return 0.0

    def distance(self, x):
        return np.full(len(x), np.inf)


def body_mobility(config, radius: float, wall=None):
    """The beads' mobility beside ``config``'s fixed no-slip surfaces
    (:class:`~flagwrap.body.fixed_mobility.FixedBodyMobility`, bead ``radius`` in core units):
    the no-slip body's blobs and the ``[[tube]]``'s (:mod:`flagwrap.confinement.tube`), both
    held still; beside a ``wall`` too (:class:`~flagwrap.hydrodynamics.wall.PlaneWall`). ``None``
    when there is neither (the free-space mobility applies)."""
    from flagwrap.body.fixed_mobility import FixedBodyMobility
    from flagwrap.body.multiblob import cell_body_blobs

    parts = []
    if config.body.no_slip:
        parts.append(cell_body_blobs(config))
    if config.tubes and config.numerics.hydrodynamics:
        from flagwrap.system.parts import tube_blobs

        parts.append(tube_blobs(config))
    if not parts:
        return None
    blobs = np.concatenate([b for b, _ in parts])
    radii = np.concatenate([r for _, r in parts])
    return FixedBodyMobility(radius, blobs, radii, solver=config.body.solver, wall=wall)
