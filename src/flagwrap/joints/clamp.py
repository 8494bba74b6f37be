"""The clamp: the paper's boundary condition at the driven end.

:class:`AxialClamp` holds the first bond (beads 0 and 1) and turns it, with its material frame,
about the body axis by the motor angle ``phi``. Vertex 1, where the filament leaves the
clamped bond, bends and twists with the filament's own stiffness (``A/b``, ``C/b``).

With ``clamp.lead = "connector"`` (:func:`flagwrap.geometry.helix.connector_helix_positions`)
it holds more beads: a radial arm from the anchor and then the clamped bond, parallel to the
axis, whose end is the helix's first bead. The whole held part turns rigidly; the vertices
between held bonds carry no stiffness (their energy would only depend on ``phi``), and the
vertex where the filament leaves the last held bond is the joint's vertex. It is
the base of the other joints (:mod:`flagwrap.joints.hook`), which keep its kinematics and
change what happens at and after vertex 1. The interface every joint has is
:class:`flagwrap.joints.base.Joint`.
"""

from __future__ import annotations

import math

import numpy as np

from flagwrap.joints.base import Joint


class AxialClamp(Joint):
    """Clamped first bond, rotated about ``axis`` (unit) through ``origin`` (the anchor, the
    system's origin by default) by ``phi``.

    Attributes
    ----------
    n_beads : int  number of prescribed beads (2; more with a connector's arm)
    n_edges : int  number of prescribed twist angles (``n_beads - 1``)
    vertex : int   the joint's vertex, where the filament leaves the last held bond
    motor_bond : int  the last held bond (the motor's), along the axis
    """

    n_beads = 2
    n_edges = 1

    def __init__(self, x0: np.ndarray, theta0: np.ndarray, axis=(0.0, 0.0, -1.0),
                 origin=(0.0, 0.0, 0.0), n_beads: int = 2):
        if n_beads != 2:  # a connector's arm: every held bond is prescribed
            if not 2 <= n_beads < len(x0) - 1:
                raise ValueError(f"AxialClamp: n_beads = {n_beads} must be in [2, {len(x0) - 2}]")
            self.n_beads, self.n_edges = int(n_beads), int(n_beads) - 1
            self.vertex = self.exit_bond = self.n_beads - 1
            self.motor_bond = self.n_beads - 2
        self.axis = np.asarray(axis, float) / np.linalg.norm(axis)
        self.origin = np.array(origin, float)
        # the held beads relative to the anchor (what the fused kernel rotates)
        self.x_ref = np.array(x0[: self.n_beads], float) - self.origin
        self.theta_ref = np.array(theta0[: self.n_edges], float)
        # generators: d x_c / d phi = axis x x_c, d theta / d phi = a . t of the motor's bond
        # (a rigid rotation turns the material frame about t at that rate against the director
        # transported in time; exact for the bond along the axis, whose twist is what the
        # joint's vertex feels: the held bonds before it meet at vertices without stiffness)
        m = self.motor_bond
        t0 = x0[m + 1] - x0[m]
        t0 = t0 / np.linalg.norm(t0)
        self.twist_rate = float(np.dot(t0, self.axis))
        # Rodrigues split once: x(phi) = par + cos(phi) perp + sin(phi) axis x perp (called at
        # every force evaluation, where building a rotation matrix cost more than the forces)
        par = np.outer(self.x_ref @ self.axis, self.axis)
        self._par = par
        self._perp = self.x_ref - par
        self._cross = np.cross(self.axis, self._perp)

    def rest(self, rest):
        """No stiffness at the vertices between held bonds (a connector's): they turn rigidly."""
        if self.n_beads == 2:
            return rest
        cb, ct = rest.cbend.copy(), rest.ctwist.copy()
        cb[1:self.vertex] = 0.0
        ct[1:self.vertex] = 0.0
        import dataclasses

        return dataclasses.replace(rest, cbend=cb, ctwist=ct)

    def positions(self, phi: float) -> np.ndarray:
        return self.origin + (self._par + math.cos(phi) * self._perp + math.sin(phi) * self._cross)

    def theta(self, phi: float) -> np.ndarray:
        return self.theta_ref + self.twist_rate * phi

    def generalized_force(self, phi: float, grad_x: np.ndarray, grad_th: np.ndarray) -> float:
        """``dE/dphi`` from the energy gradient on the clamped beads and twist angles."""
        xc = self.positions(phi) - self.origin
        dx = np.cross(self.axis, xc)
        return float(np.sum(dx * grad_x[: self.n_beads])
                     + self.twist_rate * grad_th[self.motor_bond])
