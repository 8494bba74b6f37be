"""Discrete Kirchhoff rod: gradients against finite differences, equilibrium, invariances."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from flagwrap.elasticity.rod import elastic_energy, elastic_forces, initial_frames, rest_state
from flagwrap.geometry.frames import rotation_matrix
from flagwrap.geometry.helix import ramp_helix_positions

from conftest import fd_gradient


def setup(n=20, stretch=1e4, twist=1 / 1.49):
    x0 = ramp_helix_positions(1.0, 0.075, 0.167, n, "left", 0.5)
    fr = initial_frames(x0)
    th0 = np.zeros(n - 1)
    return x0, th0, fr, rest_state(x0, fr, th0, 1.0, twist, stretch)


def perturbed(rng, x0, fr, rest, amp=0.01):
    x = x0 + amp * rng.standard_normal(x0.shape)
    th = 0.3 * rng.standard_normal(len(x0) - 1)
    _, _, _, base = elastic_forces(x, th, fr, rest)
    return x, th, base


def test_undeformed_helix_has_zero_energy_and_force():
    x0, th0, fr, rest = setup()
    E, F, tau, _ = elastic_forces(x0, th0, fr, rest)
    assert E < 1e-25
    assert np.abs(F).max() < 1e-9 and np.abs(tau).max() < 1e-9


@pytest.mark.parametrize("stretch", [0.0, 1e4])
def test_forces_are_minus_gradient_of_energy(rng, stretch):
    # oracle: central finite differences of the discrete energy (error O(h^2) ~ 1e-10 relative)
    x0, th0, fr, rest = setup(stretch=stretch)
    x, th, base = perturbed(rng, x0, fr, rest)
    E, F, tau, _ = elastic_forces(x, th, base, rest)
    g, gt = fd_gradient(lambda xx, tt: elastic_energy(xx, tt, base, rest), x, th)
    assert np.abs(F + g).max() / np.abs(g).max() < 1e-5
    assert np.abs(tau + gt).max() / np.abs(gt).max() < 1e-5


@settings(max_examples=25, deadline=None)
@given(st.integers(0, 10_000))
def test_internal_forces_sum_to_zero_and_torques_balance(seed):
    # oracle: internal forces of a free rod cannot move or turn it (Newton's third law)
    rng = np.random.default_rng(seed)
    x0, th0, fr, rest = setup()
    x, th, base = perturbed(rng, x0, fr, rest)
    E, F, tau, fr2 = elastic_forces(x, th, base, rest)
    scale = np.abs(F).max()
    np.testing.assert_allclose(F.sum(axis=0), 0, atol=1e-9 * scale)
    # total torque = sum r x F + sum tau_j t_j (twist torques act about the bond tangents)
    T = np.cross(x, F).sum(axis=0) + (tau[:, None] * fr2.t).sum(axis=0)
    np.testing.assert_allclose(T, 0, atol=1e-8 * scale)


@settings(max_examples=25, deadline=None)
@given(st.integers(0, 10_000), st.floats(-3, 3), st.floats(-3, 3), st.floats(-3, 3))
def test_energy_invariant_under_rigid_rotation(seed, a, b, c):
    rng = np.random.default_rng(seed)
    x0, th0, fr, rest = setup()
    x, th, base = perturbed(rng, x0, fr, rest)
    E = elastic_energy(x, th, base, rest)
    axis = np.array([a, b, c])
    if np.linalg.norm(axis) < 1e-3:
        return
    Rm = rotation_matrix(axis, np.linalg.norm(axis))
    from flagwrap.elasticity.rod import Frames

    rbase = Frames(base.t @ Rm.T, base.d1 @ Rm.T, base.rt.copy())
    Er = elastic_energy(x @ Rm.T, th, rbase, rest)
    assert abs(Er - E) <= 1e-9 * max(1.0, abs(E))
