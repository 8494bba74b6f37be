"""Rest state and thin wrappers around the elastic kernels.

All quantities in core units (length L, energy A/L, A = 1): see :mod:`flagwrap.units`.
"""

from __future__ import annotations

import dataclasses
import math
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
        the rod's ``A`` (=1), ``C`` [A], ``ks`` [A/L^3].
    cbend, ctwist : (N,) vertex coefficients ``A_i/l_i``, ``C_i/l_i`` the kernel uses
        (``bending/vor``, ``twist/vor`` for a uniform rod; joints change theirs:
        :meth:`with_vertex`). Ends unused (0).
    angle_law : (N,) bool, vertices that measure curvature by the turning angle (lumped
        joints; :mod:`flagwrap.elasticity._kernels`), ``kbar`` there in the same measure.
    """

    l0: np.ndarray
    vor: np.ndarray
    kbar: np.ndarray
    mbar: np.ndarray
    bending: float
    twist: float
    stretch: float
    cbend: np.ndarray = None
    ctwist: np.ndarray = None
    angle_law: np.ndarray = None

    def __post_init__(self):
        if self.angle_law is None:
            object.__setattr__(self, "angle_law", np.zeros(len(self.vor), np.bool_))
        if self.cbend is None:
            object.__setattr__(self, "cbend", _coefficients(self.bending, self.vor))
        if self.ctwist is None:
            object.__setattr__(self, "ctwist", _coefficients(self.twist, self.vor))

    def with_vertex(self, i: int, cbend: float | None = None, ctwist: float | None = None,
                    kbar=None, mbar: float | None = None) -> "RestState":
        """A copy with vertex ``i``'s coefficients and/or rest curvature/twist replaced."""
        cb, ct = self.cbend.copy(), self.ctwist.copy()
        kb, mb = self.kbar.copy(), self.mbar.copy()
        if cbend is not None:
            cb[i] = cbend
        if ctwist is not None:
            ct[i] = ctwist
        if kbar is not None:
            kb[i] = kbar
        if mbar is not None:
            mb[i] = mbar
        return dataclasses.replace(self, cbend=cb, ctwist=ct, kbar=kb, mbar=mb)


def turning_angle_scale(kb_norm: float) -> float:
    """``g = psi / |kb|`` with ``psi = 2 atan(|kb|/2)``: the factor that turns the discrete
    curvature ``|kb| = 2 tan(psi/2)`` into the turning angle (an ``angle_law`` vertex; the
    kernel, :mod:`flagwrap.elasticity._kernels`, computes the same inline)."""
    if kb_norm <= 1e-12:
        return 1.0
    return 2.0 * math.atan(0.5 * kb_norm) / kb_norm


def _coefficients(modulus, vor: np.ndarray) -> np.ndarray:
    """``modulus / vor`` at interior vertices, 0 at the ends; ``modulus``: scalar or (N,)."""
    out = np.zeros(len(vor))
    m = np.broadcast_to(np.asarray(modulus, float), vor.shape)
    out[1:-1] = m[1:-1] / vor[1:-1]
    return out


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
    return K.energy_grad(x, theta, base.t, base.d1, base.rt, rest.l0, rest.cbend,
                         rest.ctwist, rest.angle_law, rest.kbar, rest.mbar, rest.stretch, gx, gth, d1, rt)


def elastic_forces(x, theta, base: Frames, rest: RestState):
    """Energy, forces ``-dE/dx`` (N,3), twist torques ``-dE/dtheta`` (N-1) and new frames."""
    gx = np.empty_like(x)
    gth = np.empty(len(theta))
    d1 = np.empty_like(base.d1)
    rt = np.empty_like(base.rt)
    E = K.energy_grad(x, theta, base.t, base.d1, base.rt, rest.l0, rest.cbend,
                      rest.ctwist, rest.angle_law, rest.kbar, rest.mbar, rest.stretch, gx, gth, d1, rt)
    e = np.diff(x, axis=0)
    t = e / np.linalg.norm(e, axis=1)[:, None]
    return E, -gx, -gth, Frames(t, d1, rt)
