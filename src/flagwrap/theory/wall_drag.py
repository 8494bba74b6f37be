"""Exact drag of a rigid sphere translating beside a no-slip plane wall, the oracles of the
wall mobility (tests/unit/test_wall.py, docs/confinement.md).

Sphere of radius ``a``, centre at height ``h`` above the wall, ``alpha = arccosh(h/a)``
(bispherical coordinates). Drag ``F = 6 pi eta a U lambda``:

* :func:`brenner_normal`: translation along the normal. H. Brenner, Chem. Eng. Sci. 16, 242
  (1961), Eq. 2.19::

    lambda_perp = 4/3 sinh(alpha) sum_{n>=1} n(n+1)/((2n-1)(2n+3))
                  [(2 sinh((2n+1) alpha) + (2n+1) sinh(2 alpha))
                   / (4 sinh^2((n+1/2) alpha) - (2n+1)^2 sinh^2(alpha)) - 1]

* :func:`oneill_parallel`: translation parallel to the wall, the sphere held from rotating.
  M. E. O'Neill, Mathematika 11, 67 (1964), the exact solution in bispherical coordinates
  used by Goldman, Cox & Brenner, Chem. Eng. Sci. 22, 637 (1967), Part I: coefficients
  ``A_n`` from a tridiagonal system, the force from their sum. Its limits are GCB's:
  far field ``1/(1 - 9/16 x + 1/8 x^3 - 45/256 x^4 - 1/16 x^5)``, ``x = a/h`` (Faxen), and
  near contact ``-8/15 ln(delta/a) + 0.9588``, ``delta = h - a``.

Terms fall as ``exp(-(2n+1) alpha)``; the sums stop where that is below 1e-17.
"""

from __future__ import annotations

import math

import numpy as np


def _terms(h_over_a: float) -> tuple[float, int]:
    H = float(h_over_a)
    if not H > 1.0:
        raise ValueError(f"h/a must exceed 1 (the sphere above the wall), got {h_over_a!r}")
    al = math.acosh(H)
    return al, int(math.ceil(40.0 / al)) + 10


def brenner_normal(h_over_a: float) -> float:
    """Brenner's ``lambda_perp`` (module docstring)."""
    al, nmax = _terms(h_over_a)
    n = np.arange(1, nmax + 1, dtype=float)
    s1 = math.sinh(al)
    num = 2.0 * np.sinh((2 * n + 1) * al) + (2 * n + 1) * math.sinh(2 * al)
    den = 4.0 * np.sinh((n + 0.5) * al) ** 2 - (2 * n + 1) ** 2 * s1 * s1
    terms = n * (n + 1) / ((2 * n - 1) * (2 * n + 3)) * (num / den - 1.0)
    return float(4.0 / 3.0 * s1 * np.sum(terms))


def oneill_parallel(h_over_a: float) -> float:
    """O'Neill's ``F*_x = |F|/(6 pi eta a U)`` for a sphere translating parallel to the wall
    without rotating (module docstring)."""
    from scipy.linalg import solve_banded

    al, nmax = _terms(h_over_a)
    cth = 1.0 / math.tanh(al)
    m = np.arange(nmax + 3, dtype=float)
    k = (m + 0.5) / np.tanh((m + 0.5) * al) - cth
    i = np.arange(1, nmax + 1, dtype=float)
    ii = i.astype(int)
    ca = (2 * i - 1) * k[ii - 1] - (2 * i - 3) * k[ii]
    cb = (2 * i + 5) * k[ii] - (2 * i + 3) * k[ii + 1]
    ab = np.zeros((3, nmax))
    ab[1] = -ca * i / (2 * i + 1) - cb * (i + 1) / (2 * i + 1)
    ab[0, 1:] = (cb * (i + 2) / (2 * i + 3))[:-1]  # super-diagonal: row i, column i + 1
    ab[2, :-1] = (ca * (i - 1) / (2 * i - 1))[1:]  # sub-diagonal: row i, column i - 1
    coth = lambda z: 1.0 / np.tanh(z)  # noqa: E731
    rhs = math.sqrt(2.0) * (2 * coth((i + 0.5) * al) - coth((i - 0.5) * al)
                            - coth((i + 1.5) * al))
    A = np.concatenate([[0.0], solve_banded((1, 1), ab, rhs), [0.0, 0.0]])  # A[0] = A_0 := 0
    f = 0.0
    for mm in range(nmax):
        E = 2.0 * math.sqrt(2.0) * math.exp(-(mm + 0.5) * al) / math.sinh((mm + 0.5) * al)
        if mm >= 2:
            E += k[mm] * (mm - 1) * mm / (2 * mm - 1) * A[mm - 1]
        E -= k[mm] * (mm + 1) * (mm + 2) / (2 * mm + 3) * A[mm + 1]
        C = 0.0
        if mm >= 1:
            if mm >= 2:
                C += (mm - 1) / (2 * mm - 1) * A[mm - 1]
            C += -A[mm] + (mm + 2) / (2 * mm + 3) * A[mm + 1]
            C *= -2.0 * k[mm]
        f += E + mm * (mm + 1) * C
    return float(math.sqrt(2.0) / 6.0 * math.sinh(al) * f)


def faxen_parallel(h_over_a: float) -> float:
    """GCB's far-field ``F*_x`` (Faxen's series, to ``(a/h)^5``)."""
    x = 1.0 / float(h_over_a)
    return 1.0 / (1 - 9 / 16 * x + x**3 / 8 - 45 / 256 * x**4 - x**5 / 16)


def lubrication_parallel(h_over_a: float) -> float:
    """GCB's near-contact ``F*_x = -8/15 ln(delta/a) + 0.9588``."""
    return -8.0 / 15.0 * math.log(float(h_over_a) - 1.0) + 0.9588


def haberman_sayre(a_over_rt: float) -> float:
    """Drag ``F/(6 pi eta a U)`` of a sphere moving along the axis of a circular tube of radius
    ``R_t`` (W. L. Haberman & R. M. Sayre, David Taylor Model Basin Report 1143 (1958)),
    ``l = a/R_t``: ``(1 - 0.75857 l^5)/(1 - 2.1050 l + 2.0865 l^3 - 1.7068 l^5 + 0.72603 l^6)``."""
    lam = float(a_over_rt)
    return (1 - 0.75857 * lam**5) / (1 - 2.1050 * lam + 2.0865 * lam**3 - 1.7068 * lam**5
                                     + 0.72603 * lam**6)
