"""Numba kernels of the discrete elastic rod energy and its gradient.

Discretisation (Bergou et al., "Discrete elastic rods", SIGGRAPH 2008; Bergou et al.,
"Discrete viscous threads", SIGGRAPH 2010; gradients as in Jawed, Novelia & O'Reilly,
"A primer on the kinematics of discrete elastic rods", 2018), an equivalent of the
variational bead model of Chirico & Langowski (1994) and Wada & Netz (2009) that the paper
uses. Beads ``x_0..x_{N-1}``; bonds (edges) ``e_j = x_{j+1} - x_j`` carry a reference frame
``(d1_j, t_j x d1_j)`` kept by parallel transport in time, and a twist angle ``theta_j`` of the
material frame ``m1_j = cos(theta_j) d1_j + sin(theta_j) d2_j``, ``m2_j = -sin d1 + cos d2``.

At interior vertex ``i`` (between bonds i-1 and i):

* curvature binormal  ``kb_i = 2 t_{i-1} x t_i / (1 + t_{i-1}.t_i)``
* material curvatures ``k1 = (m2_{i-1} + m2_i).kb / 2``, ``k2 = -(m1_{i-1} + m1_i).kb / 2``
* twist               ``m_i = theta_i - theta_{i-1} + r_i`` (``r_i``: reference twist)

Energy (dimensionless, A = 1 in the core units)::

    E = sum_j ks/2 (|e_j| - l0_j)^2
      + sum_i cb_i/2 [(k1 - k1bar)^2 + (k2 - k2bar)^2] + ct_i/2 (m_i - mbar_i)^2

with per-vertex coefficients ``cb_i = A_i / l_i`` and ``ct_i = C_i / l_i`` (Voronoi length
``l_i = (l0_{i-1} + l0_i)/2``; a uniform rod has ``A_i = A``, ``C_i = C``). A joint is a vertex
with other coefficients: the lumped hook (:mod:`flagwrap.joints.hook`) sets ``cb_1 = A_h/l_h``.

Discrete curvature ``|kb| = 2 tan(psi/2)`` of the turning angle ``psi`` is right for the small
angles between bonds of a smooth rod, but a lumped joint bends through large angles, where
``cb/2 |kb|^2`` would stiffen without bound (by 7 % at psi = 0.46 rad, 2.5x at pi/2). At
vertices flagged ``angle_law`` the material curvatures are scaled by ``g = psi/|kb|``, so the
energy is ``cb/2 psi^2`` for a plane bend: that of a short rod bent uniformly through ``psi``. Rest values are those of the initial helix,
so the stress-free helix is an exact minimum (E = 0).

The gradient is exact for the energy evaluated with reference frames transported from a base
configuration (the start of the time step): this is what the finite-difference test checks.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from flagwrap.geometry.frames import signed_angle3, transport3



@nb.njit(cache=True)
def _wrap(a):
    """Map an angle to (-pi, pi]."""
    return a - 2.0 * math.pi * math.floor((a + math.pi) / (2.0 * math.pi))


@nb.njit(cache=True)
def update_frames(x, base_t, base_d1, base_rt, t_out, d1_out, rt_out, len_out):
    """Tangents, transported reference directors and continuous reference twist at ``x``."""
    n_e = x.shape[0] - 1
    for j in range(n_e):
        e0 = x[j + 1, 0] - x[j, 0]
        e1 = x[j + 1, 1] - x[j, 1]
        e2 = x[j + 1, 2] - x[j, 2]
        ln = math.sqrt(e0 * e0 + e1 * e1 + e2 * e2)
        len_out[j] = ln
        t_out[j, 0] = e0 / ln
        t_out[j, 1] = e1 / ln
        t_out[j, 2] = e2 / ln
        u0, u1, u2 = transport3(base_t[j, 0], base_t[j, 1], base_t[j, 2],
                                t_out[j, 0], t_out[j, 1], t_out[j, 2],
                                base_d1[j, 0], base_d1[j, 1], base_d1[j, 2])
        # remove rounding drift: keep d1 exactly unit and perpendicular to t
        ut = u0 * t_out[j, 0] + u1 * t_out[j, 1] + u2 * t_out[j, 2]
        u0 -= ut * t_out[j, 0]
        u1 -= ut * t_out[j, 1]
        u2 -= ut * t_out[j, 2]
        nu = math.sqrt(u0 * u0 + u1 * u1 + u2 * u2)
        d1_out[j, 0] = u0 / nu
        d1_out[j, 1] = u1 / nu
        d1_out[j, 2] = u2 / nu
    rt_out[0] = 0.0
    rt_out[x.shape[0] - 1] = 0.0
    for i in range(1, n_e):
        u0, u1, u2 = transport3(t_out[i - 1, 0], t_out[i - 1, 1], t_out[i - 1, 2],
                                t_out[i, 0], t_out[i, 1], t_out[i, 2],
                                d1_out[i - 1, 0], d1_out[i - 1, 1], d1_out[i - 1, 2])
        # no arrays: transport3/signed_angle3 allocate nothing (twice per bond per force
        # call; the array versions cost 10.8 vs 2.9 us per update at N = 61)
        raw = signed_angle3(u0, u1, u2, d1_out[i, 0], d1_out[i, 1], d1_out[i, 2],
                            t_out[i, 0], t_out[i, 1], t_out[i, 2])
        rt_out[i] = base_rt[i] + _wrap(raw - base_rt[i])


@nb.njit(cache=True)
def material_frames(t, d1, theta, m1, m2):
    n_e = t.shape[0]
    for j in range(n_e):
        c = math.cos(theta[j])
        s = math.sin(theta[j])
        d20 = t[j, 1] * d1[j, 2] - t[j, 2] * d1[j, 1]
        d21 = t[j, 2] * d1[j, 0] - t[j, 0] * d1[j, 2]
        d22 = t[j, 0] * d1[j, 1] - t[j, 1] * d1[j, 0]
        m1[j, 0] = c * d1[j, 0] + s * d20
        m1[j, 1] = c * d1[j, 1] + s * d21
        m1[j, 2] = c * d1[j, 2] + s * d22
        m2[j, 0] = -s * d1[j, 0] + c * d20
        m2[j, 1] = -s * d1[j, 1] + c * d21
        m2[j, 2] = -s * d1[j, 2] + c * d22


@nb.njit(cache=True)
def curvatures(t, m1, m2, kb, kappa):
    """Curvature binormals ``kb`` (N,3) and material curvatures ``kappa`` (N,2) at vertices."""
    n_e = t.shape[0]
    for i in range(1, n_e):
        a0, a1, a2 = t[i - 1, 0], t[i - 1, 1], t[i - 1, 2]
        b0, b1, b2 = t[i, 0], t[i, 1], t[i, 2]
        chi = 1.0 + a0 * b0 + a1 * b1 + a2 * b2
        kb[i, 0] = 2.0 * (a1 * b2 - a2 * b1) / chi
        kb[i, 1] = 2.0 * (a2 * b0 - a0 * b2) / chi
        kb[i, 2] = 2.0 * (a0 * b1 - a1 * b0) / chi
        s0 = 0.0
        s1 = 0.0
        for k in range(3):
            s0 += 0.5 * (m2[i - 1, k] + m2[i, k]) * kb[i, k]
            s1 -= 0.5 * (m1[i - 1, k] + m1[i, k]) * kb[i, k]
        kappa[i, 0] = s0
        kappa[i, 1] = s1


@nb.njit(cache=True)
def energy_grad(x, theta, base_t, base_d1, base_rt, l0, cbend, ctwist, angle_law, kbar, mbar,
                ks, grad_x, grad_th, d1_out, rt_out):
    """Elastic energy and its gradient (dE/dx (N,3), dE/dtheta (N-1)).

    ``cbend``, ``ctwist`` (N,): the vertex coefficients ``A_i/l_i``, ``C_i/l_i`` (ends unused);
    ``angle_law`` (N,) bool: vertices whose curvatures measure the turning angle ``psi``
    instead of ``2 tan(psi/2)`` (the lumped hook: module docstring).

    ``grad_x``, ``grad_th`` are overwritten; ``d1_out`` (N-1,3) and ``rt_out`` (N) receive the
    transported reference directors and reference twist at ``x`` (the next base).
    """
    N = x.shape[0]
    n_e = N - 1
    t = np.empty((n_e, 3))
    ln = np.empty(n_e)
    update_frames(x, base_t, base_d1, base_rt, t, d1_out, rt_out, ln)
    m1 = np.empty((n_e, 3))
    m2 = np.empty((n_e, 3))
    material_frames(t, d1_out, theta, m1, m2)
    ge = np.zeros((n_e, 3))  # dE/de_j
    grad_th[:] = 0.0
    E = 0.0
    # stretching
    for j in range(n_e):
        d = ln[j] - l0[j]
        E += 0.5 * ks * d * d
        for k in range(3):
            ge[j, k] += ks * d * t[j, k]
    # bending and twist at interior vertices
    for i in range(1, n_e):
        ta0, ta1, ta2 = t[i - 1, 0], t[i - 1, 1], t[i - 1, 2]
        tb0, tb1, tb2 = t[i, 0], t[i, 1], t[i, 2]
        chi = 1.0 + ta0 * tb0 + ta1 * tb1 + ta2 * tb2
        kb0 = 2.0 * (ta1 * tb2 - ta2 * tb1) / chi
        kb1 = 2.0 * (ta2 * tb0 - ta0 * tb2) / chi
        kb2 = 2.0 * (ta0 * tb1 - ta1 * tb0) / chi
        mt10 = (m1[i - 1, 0] + m1[i, 0]) / chi
        mt11 = (m1[i - 1, 1] + m1[i, 1]) / chi
        mt12 = (m1[i - 1, 2] + m1[i, 2]) / chi
        mt20 = (m2[i - 1, 0] + m2[i, 0]) / chi
        mt21 = (m2[i - 1, 1] + m2[i, 1]) / chi
        mt22 = (m2[i - 1, 2] + m2[i, 2]) / chi
        tt0 = (ta0 + tb0) / chi
        tt1 = (ta1 + tb1) / chi
        tt2 = (ta2 + tb2) / chi
        k1 = 0.5 * (mt20 * kb0 + mt21 * kb1 + mt22 * kb2) * chi
        k2 = -0.5 * (mt10 * kb0 + mt11 * kb1 + mt12 * kb2) * chi
        cb = cbend[i]
        inv_a = 1.0 / ln[i - 1]
        inv_b = 1.0 / ln[i]
        cbg = cb
        if angle_law[i]:
            # the turning angle psi instead of |kb| = 2 tan(psi/2): curvatures scaled by
            # g = psi/|kb| (a short rod bent uniformly through psi stores cb psi^2 / 2)
            q = kb0 * kb0 + kb1 * kb1 + kb2 * kb2
            kn = math.sqrt(q)
            if kn > 1e-4:
                psi = 2.0 * math.atan(0.5 * kn)
                g = psi / kn
                dgdq = (kn / (1.0 + 0.25 * q) - psi) / (q * 2.0 * kn)
            else:  # series (relative error < 1e-16 at kn = 1e-4)
                g = 1.0 - q / 12.0 + q * q / 80.0
                dgdq = -1.0 / 12.0 + q / 40.0
            k1 *= g
            k2 *= g
            d1 = k1 - kbar[i, 0]
            d2 = k2 - kbar[i, 1]
            # chain rule through q = |kb|^2 = 4 (1 - c)/(1 + c), c = t_{i-1}.t_i
            cq = cb * (d1 * k1 + d2 * k2) / g * dgdq * (-8.0 / (chi * chi))
            c = chi - 1.0
            ge[i - 1, 0] += cq * inv_a * (tb0 - c * ta0)
            ge[i - 1, 1] += cq * inv_a * (tb1 - c * ta1)
            ge[i - 1, 2] += cq * inv_a * (tb2 - c * ta2)
            ge[i, 0] += cq * inv_b * (ta0 - c * tb0)
            ge[i, 1] += cq * inv_b * (ta1 - c * tb1)
            ge[i, 2] += cq * inv_b * (ta2 - c * tb2)
            cbg = cb * g
            # the DER terms below differentiate the unscaled curvatures: undo the scaling there
            k1 /= g
            k2 /= g
        else:
            d1 = k1 - kbar[i, 0]
            d2 = k2 - kbar[i, 1]
        E += 0.5 * cb * (d1 * d1 + d2 * d2)
        # t_i x mt2, t_{i-1} x mt2, t_i x mt1, t_{i-1} x mt1
        xb20 = tb1 * mt22 - tb2 * mt21
        xb21 = tb2 * mt20 - tb0 * mt22
        xb22 = tb0 * mt21 - tb1 * mt20
        xa20 = ta1 * mt22 - ta2 * mt21
        xa21 = ta2 * mt20 - ta0 * mt22
        xa22 = ta0 * mt21 - ta1 * mt20
        xb10 = tb1 * mt12 - tb2 * mt11
        xb11 = tb2 * mt10 - tb0 * mt12
        xb12 = tb0 * mt11 - tb1 * mt10
        xa10 = ta1 * mt12 - ta2 * mt11
        xa11 = ta2 * mt10 - ta0 * mt12
        xa12 = ta0 * mt11 - ta1 * mt10
        # d kappa1 / d e_{i-1} = (-k1 tt + t_i x mt2)/|e_{i-1}| ; / d e_i = (-k1 tt - t_{i-1} x mt2)/|e_i|
        # d kappa2 / d e_{i-1} = (-k2 tt - t_i x mt1)/|e_{i-1}| ; / d e_i = (-k2 tt + t_{i-1} x mt1)/|e_i|
        ge[i - 1, 0] += cbg * inv_a * (d1 * (-k1 * tt0 + xb20) + d2 * (-k2 * tt0 - xb10))
        ge[i - 1, 1] += cbg * inv_a * (d1 * (-k1 * tt1 + xb21) + d2 * (-k2 * tt1 - xb11))
        ge[i - 1, 2] += cbg * inv_a * (d1 * (-k1 * tt2 + xb22) + d2 * (-k2 * tt2 - xb12))
        ge[i, 0] += cbg * inv_b * (d1 * (-k1 * tt0 - xa20) + d2 * (-k2 * tt0 + xa10))
        ge[i, 1] += cbg * inv_b * (d1 * (-k1 * tt1 - xa21) + d2 * (-k2 * tt1 + xa11))
        ge[i, 2] += cbg * inv_b * (d1 * (-k1 * tt2 - xa22) + d2 * (-k2 * tt2 + xa12))
        # d kappa1/d theta_j = -kb.m1_j / 2 ; d kappa2/d theta_j = -kb.m2_j / 2
        kbm1a = kb0 * m1[i - 1, 0] + kb1 * m1[i - 1, 1] + kb2 * m1[i - 1, 2]
        kbm1b = kb0 * m1[i, 0] + kb1 * m1[i, 1] + kb2 * m1[i, 2]
        kbm2a = kb0 * m2[i - 1, 0] + kb1 * m2[i - 1, 1] + kb2 * m2[i - 1, 2]
        kbm2b = kb0 * m2[i, 0] + kb1 * m2[i, 1] + kb2 * m2[i, 2]
        grad_th[i - 1] += cbg * (-0.5) * (d1 * kbm1a + d2 * kbm2a)
        grad_th[i] += cbg * (-0.5) * (d1 * kbm1b + d2 * kbm2b)
        # twist
        mtw = theta[i] - theta[i - 1] + rt_out[i] - mbar[i]
        ct = ctwist[i]
        E += 0.5 * ct * mtw * mtw
        grad_th[i] += ct * mtw
        grad_th[i - 1] -= ct * mtw
        # holonomy: d r_i / d e_{i-1} = kb/(2|e_{i-1}|), d r_i / d e_i = kb/(2|e_i|)
        ha = ct * mtw * 0.5 * inv_a
        hb = ct * mtw * 0.5 * inv_b
        ge[i - 1, 0] += ha * kb0
        ge[i - 1, 1] += ha * kb1
        ge[i - 1, 2] += ha * kb2
        ge[i, 0] += hb * kb0
        ge[i, 1] += hb * kb1
        ge[i, 2] += hb * kb2
    for k in range(3):
        grad_x[0, k] = -ge[0, k]
        grad_x[N - 1, k] = ge[n_e - 1, k]
    for j in range(1, n_e):
        for k in range(3):
            grad_x[j, k] = ge[j - 1, k] - ge[j, k]
    return E
