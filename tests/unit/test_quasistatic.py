"""Quasi-static bead-model stretching (issue 6(b)).

Oracles: the stress-free helix (zero force at rest); the energy (force = dE/dz by central
differences); force and moment balance (equal end reactions, no transverse reaction);
second-order convergence in the bond length; each bond carrying the axial force of the real
rod; main text Eq. 1 as the infinite-length limit (the end effect of a helix pulled by its end
points decays like 1/turns); the SI helix within 3 % of Eq. 1 from z/L = 0.93.
"""

import numpy as np
import pytest

from flagwrap.errors import UserInputError
from flagwrap.elasticity.stretching_test import law_force_at_extension, stretch_helix, stretched_helix_positions
from flagwrap.theory.stretching import StretchedHelix

SI = dict(radius=15e-3, pitch=34e-3, youngs_modulus=1.2 * 1.33e6, poisson_ratio=0.49, semi_axis_a=1.5e-3)
ZZ = [0.4, 0.5, 0.6, 0.7, 0.8, 0.9]


def _helix(turns_factor=1):
    return StretchedHelix(length=turns_factor * 305e-3, **SI)


@pytest.fixture(scope="module")
def runs():
    h = _helix()
    return {N: stretch_helix(h, N, z_over_L=ZZ) for N in (51, 101, 201)}


def test_initial_shape():
    x = stretched_helix_positions(1.0, 15 / 305, 34 / 305, 101)
    b = np.linalg.norm(np.diff(x, axis=0), axis=1)
    assert np.allclose(b, 1.0 / 100, rtol=1e-12)
    assert np.allclose(x[0], 0) and np.allclose(x[-1, :2], 0) and x[-1, 2] > 0
    assert abs(x[50, 1]) < 1e-15 and x[50, 0] > 0


def test_zero_force_at_rest_and_balance(runs):
    r = runs[101]
    h = _helix()
    assert abs(r.force[0]) < 1e-10 * h.force_scale
    assert r.z_over_L[0] == pytest.approx(np.cos(h.psi0), abs=1.5e-3)  # end-to-end of the stress-free helix
    assert np.all(r.force[1:] > 0)
    assert np.allclose(r.force, r.force_fixed_end, rtol=0, atol=1e-7 * h.force_scale)
    assert np.all(r.transverse < 1e-6 * h.force_scale)


def test_force_is_dE_dz():
    h = _helix()
    d = 1e-4
    r = stretch_helix(h, 61, z_over_L=[0.6, 0.7 - d, 0.7, 0.7 + d])
    fd = (r.energy[4] - r.energy[2]) / (2 * d * h.length)
    assert r.force[3] == pytest.approx(fd, rel=1e-5)


def test_bond_springs_carry_the_axial_force_of_the_real_rod():
    """Force balance across any interior bond: its spring carries the tangential part of the
    end force, so its strain is ``F t_z / (pi E a b)`` with the real rod's axial stiffness (a
    bond spring in the wrong units, e.g. missing the L^2 of the core force unit, is off by
    1/L^2 = 10.7 here); equilibrium is solved to 1e-8 of the force scale."""
    h = _helix()
    r = stretch_helix(h, 41, z_over_L=[0.6, 0.85], gtol=1e-8)
    b0 = h.length / (r.n_beads - 1)
    e = np.diff(r.positions, axis=0)
    length = np.linalg.norm(e, axis=1)
    strain = length / b0 - 1.0
    expected = r.force[-1] * (e[:, 2] / length) * h.stretch_compliance
    mid = slice(10, 30)
    np.testing.assert_allclose(strain[mid], expected[mid], rtol=1e-6)


def test_second_order_in_bond_length(runs):
    F = {N: runs[N].force[2:] for N in runs}  # at z/L = 0.4 the N-dependence is below 1e-3
    ratio = np.abs(F[51] - F[101]) / np.abs(F[101] - F[201])
    assert np.all((ratio > 3.0) & (ratio < 5.5))
    assert np.max(np.abs(F[101] - F[201]) / F[201]) < 0.01


def test_si_helix_against_eq1(runs):
    """3.04 turns: below Eq. 1 everywhere by the end effect (docs/theory.md: -34 % at z/L =
    0.4, -4.1 % at 0.9); the 3 % of issue 6(b) is met only from z/L = 0.93 (-2.6 %). The
    physics check proper is the infinite-length limit below; these pin the measured effect."""
    h = _helix()
    dev = (runs[201].force[1:] - law_force_at_extension(h, ZZ)) / law_force_at_extension(h, ZZ)
    assert np.all(dev < 0)
    assert dev[0] == pytest.approx(-0.34, abs=0.02)
    assert dev[-1] == pytest.approx(-0.041, abs=0.005)
    r = stretch_helix(h, 201, z_over_L=[0.93])
    assert abs(r.force[1] / law_force_at_extension(h, [0.93])[0] - 1.0) < 0.03


def test_eq1_is_the_infinite_length_limit():
    """Deviation x turns is constant (1/n end effect); the 1/n extrapolation meets Eq. 1 within 3 %."""
    zz = ZZ[1:]
    out = {}
    for m in (1, 2):
        h = _helix(m)
        r = stretch_helix(h, 100 * m + 1, z_over_L=zz)
        out[m] = (h.turns, r.force[1:] / law_force_at_extension(h, zz) - 1.0)
    (n1, d1), (n2, d2) = out[1], out[2]
    assert np.all(np.abs(d1 * n1 - d2 * n2) < 0.2 * np.abs(d1 * n1) + 0.03)
    extrapolated = (n2 * d2 - n1 * d1) / (n2 - n1)
    assert np.max(np.abs(extrapolated)) < 0.03


def test_rejects_bad_extension():
    with pytest.raises(UserInputError):
        stretch_helix(_helix(), 31, z_over_L_max=0.2)
    with pytest.raises(UserInputError):
        stretch_helix(_helix(), 31, z_over_L=[0.6, 0.5])
