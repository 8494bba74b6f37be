"""Steppers: order of convergence, agreement with the explicit Euler reference, linear solvers."""

import math

import numpy as np
import pytest

from flagwrap.integrators import ROS2, ROS34PW2, ExplicitEuler
from flagwrap.integrators.linear import BandedW, DenseW, KrylovW, SparseW
from flagwrap.integrators.ros34pw2 import A_T, C_T, GAMMA, M_T
from flagwrap.system.rod_system import RodSystem

from conftest import make_config, paper_filament


def _toy_f(y):
    return np.array([-y[1] * np.exp(0.1 * y[0]), y[0] - 0.5 * y[1] ** 3 + np.sin(y[0])])


def _toy_step(y, h, J):
    W = np.eye(2) - GAMMA * h * J
    U = []
    for i in range(4):
        Yi = y + sum(A_T[i, j] * U[j] for j in range(i))
        rhs = _toy_f(Yi) + sum(C_T[i, j] * U[j] for j in range(i)) / h
        U.append(np.linalg.solve(W, GAMMA * h * rhs))
    U = np.array(U)
    return y + M_T @ U


@pytest.mark.parametrize("jac_scale", [1.0, 0.5, 0.0])
def test_ros34pw2_tableau_is_third_order_for_any_W(jac_scale):
    # oracle: scipy's DOP853 at 1e-13; a W-method keeps its order with a wrong Jacobian
    from scipy.integrate import solve_ivp

    y0 = np.array([1.0, 0.5])
    ref = solve_ivp(lambda t, y: _toy_f(y), (0, 1), y0, rtol=1e-13, atol=1e-13,
                    method="DOP853").y[:, -1]

    def jac(y):
        h = 1e-7
        return np.array([(_toy_f(y + h * e) - _toy_f(y - h * e)) / (2 * h) for e in np.eye(2)]).T

    errs = []
    for n in (20, 40, 80):
        y = y0.copy()
        for _ in range(n):
            y = _toy_step(y, 1.0 / n, jac_scale * jac(y))
        errs.append(np.abs(y - ref).max())
    slopes = np.log2(np.array(errs[:-1]) / np.array(errs[1:]))
    assert np.all(np.abs(slopes - 3.0) < 0.3), slopes


def _settled(system, integ, h=2 * math.pi / 1000, n=300):
    y = system.initial_y()
    info = system.forces(y, system.frames0)
    for _ in range(n):
        r = integ.step(system, y, info.frames, info, h, 1.0)
        y, info = r.y, r.info
    return y, info


def test_ros34pw2_converges_with_order_3_on_the_rod():
    # fixed steps from a settled rotating state; reference = same scheme at h/16 (error ~4000x
    # smaller than the finest compared step). Stated order 3, measured slope within 0.3.
    cfg = make_config(machin=283, filament=paper_filament(n_beads=31))
    s = RodSystem(cfg)
    integ = ROS34PW2(tol=1e9)
    y0, info0 = _settled(s, integ)
    T = 2 * math.pi * 0.05

    def run(n):
        y, info = y0, info0
        for _ in range(n):
            r = integ.step(s, y, info.frames, info, T / n, 1.0)
            assert r.accepted, r.reason
            y, info = r.y, r.info
        return info.x

    ref = run(1600)
    errs = [np.abs(run(n) - ref).max() for n in (50, 100, 200)]
    slopes = np.log2(np.array(errs[:-1]) / np.array(errs[1:]))
    assert np.all(np.abs(slopes - 3.0) < 0.3), (errs, slopes)


def test_fast_steppers_agree_with_explicit_euler_reference():
    # oracle: the paper-style explicit Euler at a tiny stable step over a short window
    cfg = make_config(machin=283, filament=paper_filament(n_beads=31))
    s = RodSystem(cfg)
    h_e = 2 * math.pi * 4e-8
    n_e = 2000
    y = s.initial_y()
    info = s.forces(y, s.frames0)
    eu = ExplicitEuler()
    for _ in range(n_e):
        r = eu.step(s, y, info.frames, info, h_e, 1.0)
        y, info = r.y, r.info
    x_euler = info.x
    for integ in (ROS34PW2(tol=1e-9), ROS2(tol=1e-9)):
        y = s.initial_y()
        info = s.forces(y, s.frames0)
        t, T, h = 0.0, n_e * h_e, h_e
        while t < T * (1 - 1e-12):
            hh = min(h, T - t)
            r = integ.step(s, y, info.frames, info, hh, 1.0)
            if r.accepted:
                t += hh
                y, info = r.y, r.info
            h = r.h_next
        # Euler's own error O(h_e) ~ 1e-8 L here; the window moves the beads by ~1e-5 L
        assert np.abs(info.x - x_euler).max() < 1e-7


def _rest_state(n_beads, hi=True):
    """The stress-free paper filament (M = 283): (system, state, forces). Without the body:
    a 5-bead chain's 0.1 m bonds put the polyline's far end inside it."""
    from flagwrap.params import CellBody

    s = RodSystem(make_config(machin=283, filament=paper_filament(n_beads=n_beads), hi=hi,
                              body=CellBody(enabled=False)))
    y = s.initial_y()
    return s, y, s.forces(y, s.frames0)


def _kicked_state(n_beads, seed, kick=1e-4):
    """The paper filament (HI on, M = 283) with its free beads kicked by ``kick`` L at random:
    (system, the generator after the kick, state, forces)."""
    s = RodSystem(make_config(machin=283, filament=paper_filament(n_beads=n_beads)))
    rng = np.random.default_rng(seed)
    y = s.initial_y()
    y[s.sl_x] += kick * rng.standard_normal(3 * s.nb)
    return s, rng, y, s.forces(y, s.frames0)


def test_krylov_solver_matches_dense_lu():
    s, rng, y, info = _kicked_state(31, seed=4)
    for gh in (1e-3, 3e-2):
        D = DenseW(s, y, info.frames, info.G, gh)
        K = KrylovW(s, y, info.frames, info.G, gh, rtol=1e-10)
        r = rng.standard_normal(s.ny)
        ud, uk = D.solve(r), K.solve(r)
        assert np.abs(ud - uk).max() <= 1e-8 * np.abs(ud).max()


def test_krylov_with_single_precision_products_matches_dense_lu_to_their_rounding():
    """From N = 256 GCR applies ``Mob`` in float32 (~1e-6 relative): solved to rtol 1e-10 it
    must agree with the float64 dense LU to that rounding times the amplification of the
    stiff W (<= ~100): 1e-4 relative (measured 1e-7 to 9e-6; 4e-10 with float64 products, so
    the largest error must also show that the float32 path is taken)."""
    s, rng, y, info = _kicked_state(301, seed=5)
    errs = []
    for gh in (1e-4, 3e-2):
        ud = DenseW(s, y, info.frames, info.G, gh).solve(r := rng.standard_normal(s.ny))
        uk = KrylovW(s, y, info.frames, info.G, gh, rtol=1e-10).solve(r)
        errs.append(np.abs(ud - uk).max() / np.abs(ud).max())
    assert max(errs) <= 1e-4
    assert max(errs) > 1e-8


@pytest.mark.parametrize("width", [0, 1, 3])
def test_banded_near_field_w_matches_the_masked_dense_w(width):
    """The banded LU of ``I - gamma h Mob_near J`` against a dense LU of the same operator
    built independently: the dense RPY matrix with blocks beyond ``width`` beads zeroed."""
    s, rng, y, info = _kicked_state(31, seed=6, kick=1e-3)
    gh = 2e-2
    Mob = s.mobility_matrix(y)
    bead = np.arange(s.ny) // 3
    bead[3 * s.nb:] = -10**6 - np.arange(s.ny - 3 * s.nb)  # twists: own diagonal only
    far = np.abs(bead[:, None] - bead[None, :]) > width
    far[np.diag_indices(s.ny)] = False
    Mob[far] = 0.0
    W = np.eye(s.ny) - gh * Mob @ s.force_jacobian(y, info.frames, info.G)
    r = rng.standard_normal(s.ny)
    ref = np.linalg.solve(W, r)
    u = BandedW(s, y, info.frames, info.G, gh, width=width).solve(r)
    # LU of a well-conditioned ny = 117 system: agreement to ~1e-12 of the solution
    assert np.abs(u - ref).max() <= 1e-10 * np.abs(ref).max()


def test_krylov_error_test_tightens_the_solve_beyond_the_residual_test():
    """With ``err_scale`` the GCR solve must also bring its per-unknown error estimate below
    ``kappa err_scale``: a tiny scale forces a near-exact solution although rtol is 1e-3."""
    s, rng, y, info = _kicked_state(31, seed=7)
    gh = 3e-2
    r = rng.standard_normal(s.ny)
    ud = DenseW(s, y, info.frames, info.G, gh).solve(r)
    loose = KrylovW(s, y, info.frames, info.G, gh, rtol=1e-3)
    ul = loose.solve(r)
    tight = KrylovW(s, y, info.frames, info.G, gh, rtol=1e-3,
                    err_scale=np.full(s.ny, 1e-11 * np.abs(ud).max()), kappa=1.0)
    ut = tight.solve(r)
    assert tight.iterations > loose.iterations
    assert np.abs(ut - ud).max() <= 1e-9 * np.abs(ud).max()
    assert np.abs(ul - ud).max() > 10 * np.abs(ut - ud).max()


def test_gcr_restart_when_its_storage_is_full_still_solves_exactly():
    """Recycled directions over four solves with room for only two: each restart keeps the
    current x and r, so every solve still reaches rtol against the dense LU."""
    s, rng, y, info = _kicked_state(31, seed=8)

    class TinyGCR(KrylovW):
        max_vectors = 2

    D = DenseW(s, y, info.frames, info.G, 3e-2)
    K = TinyGCR(s, y, info.frames, info.G, 3e-2, rtol=1e-10, maxiter=2000)
    for _ in range(4):
        r = rng.standard_normal(s.ny)
        ud = D.solve(r)
        assert np.abs(K.solve(r) - ud).max() <= 1e-8 * np.abs(ud).max()
    assert K.iterations > 2 * 4  # it did have to restart


def test_near_field_w_on_a_chain_shorter_than_its_near_field_is_the_exact_w():
    # default width 4a/b + 4 = 5 beads > the 3 free beads of a 5-bead chain: the near field
    # is then the whole mobility and NearW must equal the dense LU
    from flagwrap.integrators.linear import NearW

    s, y, info = _rest_state(5)
    r = np.random.default_rng(9).standard_normal(s.ny)
    ud = DenseW(s, y, info.frames, info.G, 1e-2).solve(r)
    un = NearW(s, y, info.frames, info.G, 1e-2).solve(r)
    assert np.abs(un - ud).max() <= 1e-10 * np.abs(ud).max()


def test_banded_solver_refuses_long_range_hydrodynamics():
    from flagwrap.integrators.linear import make_w

    s, y, info = _rest_state(11)
    with pytest.raises(ValueError, match="hydrodynamics = false"):
        make_w("banded", s, y, info.frames, info.G, 1e-2)


def test_gcr_preconditioner_width_follows_the_bead_overlap():
    """Refined at fixed L (a/b = 0.68, N = 181) a 1-bead near field leaves the preconditioned
    operator far from the identity (measured 507 iterations to rtol 1e-6); the default width
    ceil(15 a/b) = 11 must bring that to a few tens and still solve exactly."""
    from flagwrap.integrators.linear import preconditioner_width

    s, rng, y, info = _kicked_state(181, seed=3)
    assert preconditioner_width(s) == math.ceil(15 * s.radius / s.bond) == 11
    r = rng.standard_normal(s.ny)
    narrow = KrylovW(s, y, info.frames, info.G, 1e-2, rtol=1e-6, maxiter=2000, width=1)
    narrow.solve(r)
    default = KrylovW(s, y, info.frames, info.G, 1e-2, rtol=1e-6)
    u = default.solve(r)
    assert default.iterations <= 30 < 10 * default.iterations <= narrow.iterations
    ud = DenseW(s, y, info.frames, info.G, 1e-2).solve(r)
    # residual 1e-6: cond(W) ~5e6 lives in stiff modes that W^-1 damps; measured error
    # 1.8e-7, so allow 10x rtol
    assert np.abs(u - ud).max() <= 1e-5 * np.abs(ud).max()


def test_sparse_and_dense_jacobians_agree():
    s, y, info = _rest_state(31)
    Jd = s.force_jacobian(y, info.frames, info.G)
    Js = s.force_jacobian_sparse(y, info.frames, info.G).toarray()
    # same triplets; only the summation order of duplicate entries differs
    np.testing.assert_allclose(Jd, Js, rtol=1e-12, atol=1e-12 * np.abs(Jd).max())


def test_sparse_solver_matches_dense_without_hydrodynamic_interactions():
    s, y, info = _rest_state(31, hi=False)
    r = np.random.default_rng(5).standard_normal(s.ny)
    ud = DenseW(s, y, info.frames, info.G, 1e-2).solve(r)
    us = SparseW(s, y, info.frames, info.G, 1e-2).solve(r)
    assert np.abs(ud - us).max() <= 1e-9 * np.abs(ud).max()
    bw = BandedW(s, y, info.frames, info.G, 1e-2)
    ub = bw.solve(r)
    assert np.abs(ud - ub).max() <= 1e-9 * np.abs(ud).max()
    assert bw.kl <= 12 and bw.ku <= 12  # interleaved beads/twists: O(N) band, not dense


def _run_with(solver, protocol, n_beads=31, tol=1e-5, **numerics):
    from flagwrap.params import Numerics
    from flagwrap.simulation import Simulation

    cfg = make_config(machin=283, protocol=protocol, filament=paper_filament(n_beads=n_beads),
                      numerics=Numerics(tol=tol, linear_solver=solver, **numerics))
    return Simulation(cfg).run()


def test_near_field_w_method_keeps_the_stress_free_helix_still():
    # motor off (omega = 0 is not a protocol phase): integrate a relaxation of the undeformed
    # helix with the approximate W alone, 200 steps of a fixed h
    s, y, info = _rest_state(31)
    integ = ROS34PW2(tol=1e-5, linear_solver="near")
    x0 = info.x.copy()
    for _ in range(200):
        r = integ.step(s, y, info.frames, info, 2 * math.pi * 1e-3, 0.0)
        assert r.accepted
        y, info = r.y, r.info
    assert np.abs(info.x - x0).max() < 1e-8


def test_near_field_w_method_converges_to_the_exact_w_solution():
    # Both are ROS34PW2, order 3 for any W; with the approximate W the embedded error
    # estimate is looser (measured: global free-end error 6.4e-4 L at tol 1e-5 vs 7.9e-5 L with
    # the exact W, docs/numerics.md). What must hold: the difference shrinks with the tolerance.
    p = (("ccw", 0.3), ("cw", 0.2))
    diffs = []
    for tol in (1e-5, 1e-6):
        exact, near = _run_with("dense", p, tol=tol), _run_with("near", p, tol=tol)
        assert exact.ok and near.ok
        diffs.append(np.abs(np.asarray(exact.x)[-1] - np.asarray(near.x)[-1]).max())
    assert diffs[0] < 2e-3  # free end within 0.2 % of L at the default tolerance
    assert diffs[1] < 0.4 * diffs[0]  # order >= 1 in tol (10x tighter tol -> >= 2.5x closer)


def test_inexact_krylov_stage_solves_track_the_exact_lu():
    # GCR to rtol 1e-3 and 0.1 x tol per unknown leaves ~1e-6 L per step, below the step
    # tolerance 1e-5: the trajectory must agree with the exact-LU one to a few tolerances
    p = (("ccw", 0.3), ("cw", 0.2))
    exact, kry = _run_with("dense", p), _run_with("krylov", p)
    assert exact.ok and kry.ok
    assert abs(kry.n_steps - exact.n_steps) <= 0.1 * exact.n_steps
    assert np.abs(np.asarray(exact.x)[-1] - np.asarray(kry.x)[-1]).max() < 5e-5


def test_jax_backend_runs_the_motion_of_the_direct_sum():
    """The whole time loop on ``mobility_backend = "jax"`` (jax on the CPU here; a GPU where
    there is one): right-hand sides agree with the numba sum to 1e-15, GCR's products are
    float32 in jax and float64 in numba at this N, and both solves stop at 0.1 x tol per
    unknown, so the runs differ by solve errors only: the bound of the inexact-solve test
    above (5e-5 L after 0.3 + 0.2 turn)."""
    pytest.importorskip("jax")
    p = (("ccw", 0.3), ("cw", 0.2))
    direct = _run_with("krylov", p, mobility_backend="direct")
    jx = _run_with("krylov", p, mobility_backend="jax")
    assert direct.ok and jx.ok
    assert abs(jx.n_steps - direct.n_steps) <= 0.1 * direct.n_steps
    assert np.abs(np.asarray(direct.x)[-1] - np.asarray(jx.x)[-1]).max() < 5e-5


@pytest.mark.parametrize("integrator", [ROS34PW2(tol=1e-5), ROS2(tol=1e-5), ExplicitEuler()])
def test_a_degenerate_stage_is_a_rejected_step(integrator, monkeypatch):
    # numba raises ZeroDivisionError where a stage puts two beads on top of each other (found
    # in a Fig. 5 sweep at M ~ 1e5: the exception killed the whole boundary search); it must be
    # a rejection, so the controller shrinks the step
    s, y, info = _rest_state(11)
    real = s.forces

    def degenerate(yy, base):
        if not np.array_equal(yy, y):
            raise ZeroDivisionError("division by zero")
        return real(yy, base)

    monkeypatch.setattr(s, "forces", degenerate)
    res = integrator.step(s, y, info.frames, info, 1e-2, 1.0)
    assert not res.accepted and "bond of zero length" in res.reason
    if integrator.adaptive:
        assert res.h_next < 1e-2


def test_tableaus_are_data_for_one_stepper():
    from flagwrap.integrators import RosenbrockW, make_integrator
    from flagwrap.integrators.controller import IController
    from flagwrap.integrators.tableau import ROS2 as T2
    from flagwrap.integrators.tableau import ROS34PW2 as T34

    # the transformed coefficients give back the published ones (b = m Gamma, Gamma from c)
    # for ROS34PW2, and ROS2's rate form (a21 = 1/gamma, c21 = -2/gamma)
    Gam = np.linalg.inv(np.diag(np.full(4, 1.0 / T34.gamma)) - T34.c)
    assert np.allclose(T34.m @ Gam, [2.4212380706095346e-01, -1.2232505839045147e+00,
                                     1.5452602553351020e+00, T34.gamma], rtol=1e-12)
    assert T2.a[1, 0] * T2.gamma == pytest.approx(1.0) and T2.c[1, 0] * T2.gamma == pytest.approx(-2.0)
    # a scheme given as a tableau runs through the same stepper (here ROS2's, by data)
    custom = RosenbrockW(tol=1e-5, tableau=T2, controller=IController(safety=0.8))
    assert custom.order == 2 and custom.filter_error and custom.controller.safety == 0.8
    assert make_integrator("ros34pw2").tableau is T34


def test_reused_dense_w_buffers_give_the_same_solve():
    # the time loop's dense W factorises in buffers the system keeps (no fresh arrays per step):
    # the solve must be the fresh-array solve, bit for bit, and the buffer is really reused
    from flagwrap.integrators.linear import DenseW

    s, y, info = _rest_state(11)
    rhs = np.random.default_rng(0).standard_normal(s.ny)
    fresh = DenseW(s, y, s.frames0, info.G, 0.01).solve(rhs)
    w1 = DenseW(s, y, s.frames0, info.G, 0.01, reuse=True)
    buf = s._wt_buffer
    assert np.array_equal(w1.solve(rhs), fresh)
    DenseW(s, y, s.frames0, info.G, 0.02, reuse=True)
    assert s._wt_buffer is buf
    Mxx, _ = s.mobility_blocks(y, reuse=True)
    assert Mxx is s._mxx_buffer and np.array_equal(Mxx, s.mobility_blocks(y)[0])
