"""Rosenbrock W-methods as data: one tableau per scheme, one stepper for all
(:class:`flagwrap.integrators.rosenbrock.RosenbrockW`).

A scheme is written in the transformed variables of Hairer & Wanner (Solving ODEs II,
Sec. IV.7), in which a step needs no Jacobian-vector products::

    W u_i = gamma h [ f(y + sum_j a_ij u_j) + sum_j (c_ij / h) u_j ],   W = I - gamma h J
    y_{n+1} = y + sum_i m_i u_i,    err = sum_i e_i u_i

From the published ``(alpha, Gamma, b, bhat)`` form: ``a = alpha Gamma^-1``,
``c = diag(1/gamma) - Gamma^-1``, ``m = b Gamma^-1``, ``e = (b - bhat) Gamma^-1``
(:meth:`RosenbrockTableau.from_standard`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True, eq=False)
class RosenbrockTableau:
    """A Rosenbrock W-method in transformed variables (module docstring).

    ``order``: of ``y_{n+1}``; ``estimate_order``: of the embedded solution (the step-size
    controller's exponent is ``1/(estimate_order + 1)``); ``filter_error``: apply ``W^-1`` to the
    error estimate (Shampine), the scheme's default; ``default_tol``: the scheme's default
    tolerance when none is given.
    """

    name: str
    gamma: float
    a: np.ndarray
    c: np.ndarray
    m: np.ndarray
    e: np.ndarray
    order: int
    estimate_order: int
    filter_error: bool = False
    default_tol: float = 1e-4
    reference: str = ""

    @property
    def stages(self) -> int:
        return len(self.m)

    @classmethod
    def from_standard(cls, name, alpha, Gamma, b, bhat, **kw) -> "RosenbrockTableau":
        alpha, Gamma = np.asarray(alpha, float), np.asarray(Gamma, float)
        b, bhat = np.asarray(b, float), np.asarray(bhat, float)
        ginv = np.linalg.inv(Gamma)
        return cls(name=name, gamma=float(Gamma[0, 0]), a=alpha @ ginv,
                   c=np.diag(1.0 / np.diag(Gamma)) - ginv, m=b @ ginv, e=(b - bhat) @ ginv, **kw)


_G34 = 4.3586652150845900e-01
#: ROS34PW2: 4 stages, order 3, L-stable, embedded order 2 (Rang & Angermann, BIT Numer. Math.
#: 45, 761, 2005); a W-method: order 3 for any approximation of the Jacobian in W
ROS34PW2 = RosenbrockTableau.from_standard(
    "ros34pw2",
    alpha=[[0.0, 0.0, 0.0, 0.0],
           [8.7173304301691801e-01, 0.0, 0.0, 0.0],
           [8.4457060015369423e-01, -1.1299064236484185e-01, 0.0, 0.0],
           [0.0, 0.0, 1.0, 0.0]],
    Gamma=[[_G34, 0.0, 0.0, 0.0],
           [-8.7173304301691801e-01, _G34, 0.0, 0.0],
           [-9.0338057013044082e-01, 5.4180672388095326e-02, _G34, 0.0],
           [2.4212380706095346e-01, -1.2232505839045147e+00, 5.4526025533510214e-01, _G34]],
    b=[2.4212380706095346e-01, -1.2232505839045147e+00, 1.5452602553351020e+00, _G34],
    bhat=[3.7810903145819369e-01, -9.6042292212423178e-02, 0.5, 2.1793326075422950e-01],
    order=3, estimate_order=2, filter_error=False, default_tol=1e-4,
    reference="Rang & Angermann, BIT Numer. Math. 45, 761 (2005)")

_G2 = 1.0 + 1.0 / math.sqrt(2.0)
#: ROS2: 2 stages, order 2 for any W, L-stable, embedded linearly implicit Euler (Verwer,
#: Spee, Blom & Hundsdorfer, SIAM J. Sci. Comput. 20, 1456, 1999), gamma = 1 + 1/sqrt(2). In
#: the rate form k_i = u_i/(gamma h): W k1 = f(y), W k2 = f(y + h k1) - 2 k1,
#: y_{n+1} = y + h (3 k1 + k2)/2, err = h (k1 + k2)/2; with Shampine's filter by default (the
#: raw estimate's spurious error in the stiff components would otherwise cap the step)
ROS2 = RosenbrockTableau(
    "ros2", gamma=_G2,
    a=np.array([[0.0, 0.0], [1.0 / _G2, 0.0]]),
    c=np.array([[0.0, 0.0], [-2.0 / _G2, 0.0]]),
    m=np.array([1.5 / _G2, 0.5 / _G2]),
    e=np.array([0.5 / _G2, 0.5 / _G2]),
    order=2, estimate_order=1, filter_error=True, default_tol=1e-3,
    reference="Verwer, Spee, Blom & Hundsdorfer, SIAM J. Sci. Comput. 20, 1456 (1999)")

TABLEAUS = {t.name: t for t in (ROS34PW2, ROS2)}
