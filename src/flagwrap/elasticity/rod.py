"""Rest state and thin wrappers around the elastic kernels.

All quantities in core units (length L, energy A/L, A = 1): see :mod:`flagwrap.units`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from flagwrap.elasticity import _kernels as K
from flagwrap.geometry.frames import space_parallel_frames


@dataclass(frozen=True)
class RestState:
    """Stress-free reference of the discrete rod.

    Attributes
    ----------
    l0 : (N-1,) rest bond lengths [L]
    vor : (N,) Voronoi lengths of interior vertices [L] (ends unused)
    kbar : (N, 2) rest material curvatures (dimensionless turning, kb.m)
    mbar : (N,) rest twist (rad)
    bending, twist, stretch : float
        ``A`` (=1), ``C`` [A], ``ks`` [A/L^3].
    """

    l0: np.ndarray
    vor: np.ndarray
    kbar: np.ndarray
    mbar: np.ndarray
    bending: float
    twist: float
    stretch: float


@dataclass
class Frames:
    """Reference frames carried along in time (the base of the next step)."""

    t: np.ndarray  # (N-1, 3)
    d1: np.ndarray  # (N-1, 3)
    rt: np.ndarray  # (N,) continuous reference twist

    def copy(self) -> "Frames":
        return Frames(self.t.copy(), self.d1.copy(), self.rt.copy())


def initial_frames(x: np.ndarray) -> Frames:
    t, d1 = space_parallel_frames(x)
    return Frames(t, d1, np.zeros(len(x)))


def rest_state(x0: np.ndarray, frames: Frames, theta0: np.ndarray, bending=1.0, twist=1.0,
               stretch=1.0) -> RestState:
    """Rest values measured on the initial configuration (exact equilibrium by construction)."""
    N = len(x0)
    e = np.diff(x0, axis=0)
    l0 = np.linalg.norm(e, axis=1)
    vor = np.zeros(N)
    vor[1:-1] = 0.5 * (l0[:-1] + l0[1:])
    m1 = np.empty((N - 1, 3))
    m2 = np.empty((N - 1, 3))
    K.material_frames(frames.t, frames.d1, theta0, m1, m2)
    kb = np.zeros((N, 3))
    kappa = np.zeros((N, 2))
    K.curvatures(frames.t, m1, m2, kb, kappa)
    mbar = np.zeros(N)
    mbar[1:-1] = theta0[1:] - theta0[:-1] + frames.rt[1:-1]
    return RestState(l0, vor, kappa, mbar, float(bending), float(twist), float(stretch))


def elastic_energy(x, theta, base: Frames, rest: RestState) -> float:
    gx = np.empty_like(x)
    gth = np.empty(len(theta))
    d1 = np.empty_like(base.d1)
    rt = np.empty_like(base.rt)
    return K.energy_grad(x, theta, base.t, base.d1, base.rt, rest.l0, rest.vor, rest.kbar,
                         rest.mbar, rest.bending, rest.twist, rest.stretch, gx, gth, d1, rt)


def elastic_forces(x, theta, base: Frames, rest: RestState):
    """Energy, forces ``-dE/dx`` (N,3), twist torques ``-dE/dtheta`` (N-1) and new frames."""
    gx = np.empty_like(x)
    gth = np.empty(len(theta))
    d1 = np.empty_like(base.d1)
    rt = np.empty_like(base.rt)
    E = K.energy_grad(x, theta, base.t, base.d1, base.rt, rest.l0, rest.vor, rest.kbar,
                      rest.mbar, rest.bending, rest.twist, rest.stretch, gx, gth, d1, rt)
    e = np.diff(x, axis=0)
    t = e / np.linalg.norm(e, axis=1)[:, None]
    return E, -gx, -gth, Frames(t, d1, rt)
