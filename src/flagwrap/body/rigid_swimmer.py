"""A rigid swimmer: a rigid body and a rigid helix joined by a motor, force- and torque-free.

The textbook model of a bacterium with a rigid flagellum (Purcell, Proc. Natl. Acad. Sci.
94, 11307 (1997); Higdon, J. Fluid Mech. 94, 331 (1979)), solved here as one rigid-multiblob
problem (Usabiaga et al. 2016) with both bodies' spheres in one RPY mobility, so that the
flow each body makes reaches the other. It is the reference the elastic swimmer
(:mod:`flagwrap.system.swimmer`) reduces to for a stiff filament, and the test bed of the blob
resolution: its swimming speed converges as the body's blobs are refined (docs/bacterium.md).

Unknowns: the spheres' forces ``lambda`` (both clusters), the body's ``V_B = [U; Omega_B]``
about the common reference point (the origin, on the motor axis ``a``) and the motor torque
``tau``. The helix turns relative to the body at ``omega`` about ``a`` through the origin:
``V_H = V_B + omega [0; a]``. Equations::

    M lambda - K V_B = omega K_H [0; a]          (no slip on every sphere)
    K_B^T lambda_B = [0; -tau a],  K_H^T lambda_H = [0; tau a]   (the motor's torque pair)

which close with the motor torque's own unknown: the first two rows of force balance sum to
``K^T lambda = 0`` (the swimmer is force- and torque-free) and the third is the axial part of
the helix's balance. Solved densely (a few thousand spheres at most).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class RigidSwimmerResult:
    """Body velocity ``U`` and angular velocity ``Omega`` (lab axes, about the origin), the
    helix's ``Omega_H = Omega + omega a``, the motor torque ``tau`` (viscosity 1), and the
    largest total force and torque on the fluid (zero up to round-off)."""

    U: np.ndarray
    Omega: np.ndarray
    Omega_helix: np.ndarray
    tau: float
    residual_force: float
    residual_torque: float

    def speed(self, axis) -> float:
        """Swimming speed along ``axis``."""
        return float(self.U @ np.asarray(axis, float))


def rigid_swimmer(body_points, body_radii, helix_points, helix_radius, axis=(0.0, 0.0, -1.0),
                  omega: float = 1.0) -> RigidSwimmerResult:
    """Solve the rigid swimmer (module docstring). ``body_points`` (n, 3) with ``body_radii``
    (n,) or one radius; ``helix_points`` (m, 3) with one ``helix_radius``; lengths in any unit,
    viscosity 1; ``omega``: the helix's rate relative to the body about ``axis``."""
    from flagwrap.body.multiblob import geometric_matrix
    from flagwrap.hydrodynamics.polydisperse import PolydisperseRPY

    a = np.asarray(axis, float)
    a = a / np.linalg.norm(a)
    B = np.asarray(body_points, float)
    H = np.asarray(helix_points, float)
    nb, nh = len(B), len(H)
    radii = np.concatenate([np.broadcast_to(np.asarray(body_radii, float), (nb,)),
                            np.full(nh, float(helix_radius))])
    X = np.concatenate([B, H])
    M = PolydisperseRPY(radii).matrix(np.ascontiguousarray(X))
    K = geometric_matrix(X)
    KH = K[3 * nb:]
    n = 3 * (nb + nh)
    e = np.concatenate([np.zeros(3), a])  # [0; a]
    # unknowns [lambda (n), V_B (6), tau (1)]
    A = np.zeros((n + 7, n + 7))
    rhs = np.zeros(n + 7)
    A[:n, :n] = M
    A[:n, n:n + 6] = -K
    rhs[:n] = omega * np.concatenate([np.zeros(3 * nb), KH @ e])
    A[n:n + 6, :n] = K.T  # total force and torque: zero
    A[n + 6, 3 * nb:n] = e @ KH.T  # the helix's axial torque equals the motor's
    A[n + 6, n + 6] = -1.0
    sol = np.linalg.solve(A, rhs)
    lam, VB, tau = sol[:n], sol[n:n + 6], float(sol[n + 6])
    tot = K.T @ lam
    return RigidSwimmerResult(U=VB[:3], Omega=VB[3:], Omega_helix=VB[3:] + omega * a, tau=tau,
                              residual_force=float(np.abs(tot[:3]).max()),
                              residual_torque=float(np.abs(tot[3:]).max()))
