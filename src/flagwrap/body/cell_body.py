"""The cell body as an object: geometry plus the contact law (swap either without ``if``s)."""

from __future__ import annotations

import numpy as np

from flagwrap.body import _kernels as K


class CappedCylinder:
    """Rigid cylinder of radius ``radius`` and length ``length`` closed below by a hemisphere.

    Lengths in core units. The lowest point of the cap is the origin. The fluid passes through
    the body (paper, Methods): it acts on the filament only by the WCA repulsion of range
    ``cutoff`` (bead centre to surface) and energy ``strength``.

    ``shape = "spheroid"`` (or ``"sphere"``) makes it the spheroid of equatorial radius
    ``radius`` and total length ``radius + length`` along the axis, lowest point at the
    origin (:func:`flagwrap.body._kernels.spheroid_distance`); ``length = radius`` is the
    sphere.

    Parameters
    ----------
    radius, length : float
        ``R_cell``, cylinder length ``H``.
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
    #: the contact kernel's shape codes
    SHAPES = {"capped-cylinder": 0, "spheroid": 1, "sphere": 1}

    def __init__(self, radius, length, cutoff, strength, first_bead=2, potential="wca-c2",
                 shape="capped-cylinder"):
        if potential not in self.POTENTIALS:
            raise ValueError(f"contact potential must be one of {tuple(self.POTENTIALS)}, got {potential!r}")
        self.potential = potential
        self.c2 = self.POTENTIALS[potential]
        self.radius = float(radius)
        self.length = float(length)
        self.cutoff = float(cutoff)
        self.sigma = self.cutoff / 2.0 ** (1.0 / 6.0)
        self.strength = float(strength)
        self.first_bead = int(first_bead)
        if shape not in self.SHAPES:
            raise ValueError(f"body shape must be one of {tuple(self.SHAPES)}, got {shape!r}")
        self.shape = shape
        self.shape_code = self.SHAPES[shape]

    def energy_grad(self, x: np.ndarray, grad: np.ndarray, dist: np.ndarray) -> float:
        """Adds ``dU/dx`` into ``grad`` and writes signed distances into ``dist``."""
        return K.wca_energy_grad(x, self.first_bead, self.radius, self.length, self.sigma,
                                 self.strength, self.c2, grad, dist, self.shape_code)

    def distance(self, x: np.ndarray) -> np.ndarray:
        """Signed distance of each point to the surface (negative inside)."""
        grad = np.zeros_like(x)
        dist = np.empty(len(x))
        K.wca_energy_grad(np.ascontiguousarray(x, dtype=np.float64), len(x), self.radius,
                          self.length, self.sigma, 0.0, 0.0, grad, dist, self.shape_code)
        return dist


class NoBody:
    """No cell body (an isolated filament)."""

    radius = 0.0
    length = 0.0
    first_bead = 0
    c2 = 0.0
    shape = "none"
    shape_code = 0

    def energy_grad(self, x, grad, dist):
        dist[:] = np.inf
        return 0.0

    def distance(self, x):
        return np.full(len(x), np.inf)


def body_mobility(config, radius: float):
    """The beads' mobility beside ``config``'s fixed no-slip body
    (:class:`~flagwrap.body.fixed_mobility.FixedBodyMobility`, bead ``radius`` in core
    units), or ``None`` for a transparent body (the free-space mobility applies)."""
    if not config.body.no_slip:
        return None
    from flagwrap.body.multiblob import cell_body_blobs
    from flagwrap.body.fixed_mobility import FixedBodyMobility

    blobs, radii = cell_body_blobs(config)
    return FixedBodyMobility(radius, blobs, radii, solver=config.body.solver)
