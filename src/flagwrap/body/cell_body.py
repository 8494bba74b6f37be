"""The cell body as an object: geometry plus the contact law (swap either without ``if``s)."""

from __future__ import annotations

import numpy as np

from flagwrap.body import _kernels as K


class CappedCylinder:
    """Rigid cylinder of radius ``radius`` and length ``length`` closed below by a hemisphere.

    Lengths in core units. The lowest point of the cap is the origin. The fluid passes through
    the body (paper, Methods): it acts on the filament only by the WCA repulsion of range
    ``cutoff`` (bead centre to surface) and energy ``strength``.

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

    def __init__(self, radius, length, cutoff, strength, first_bead=2, potential="wca-c2"):
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

    def energy_grad(self, x: np.ndarray, grad: np.ndarray, dist: np.ndarray) -> float:
        """Adds ``dU/dx`` into ``grad`` and writes signed distances into ``dist``."""
        return K.wca_energy_grad(x, self.first_bead, self.radius, self.length, self.sigma,
                                 self.strength, self.c2, grad, dist)

    def distance(self, x: np.ndarray) -> np.ndarray:
        """Signed distance of each point to the surface (negative inside)."""
        grad = np.zeros_like(x)
        dist = np.empty(len(x))
        K.wca_energy_grad(x, len(x), self.radius, self.length, self.sigma, 0.0, 0.0, grad, dist)
        return dist


class NoBody:
    """No cell body (an isolated filament)."""

    radius = 0.0
    length = 0.0
    first_bead = 0
    c2 = 0.0

    def energy_grad(self, x, grad, dist):
        dist[:] = np.inf
        return 0.0

    def distance(self, x):
        return np.full(len(x), np.inf)


def body_mobility(config, radius: float):
    """The beads' mobility beside ``config``'s fixed no-slip body
    (:class:`~flagwrap.hydrodynamics.polydisperse.FixedBodyMobility`, bead ``radius`` in core
    units), or ``None`` for a transparent body (the free-space mobility applies)."""
    if not config.body.no_slip:
        return None
    from flagwrap.body.multiblob import cell_body_blobs
    from flagwrap.hydrodynamics.polydisperse import FixedBodyMobility

    blobs, radii = cell_body_blobs(config)
    return FixedBodyMobility(radius, blobs, radii, solver=config.body.solver)
