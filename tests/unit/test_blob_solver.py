"""Solves with a blob body's RPY matrix: direct Cholesky and matrix-free CG (body.solver)."""

import numpy as np
import pytest

from flagwrap.body.multiblob import capped_cylinder_blobs
from flagwrap.body.solver import (DirectBlobSolver, KrylovBlobSolver, make_blob_solver,
                                  screening_matrix)


@pytest.fixture(scope="module")
def body():
    b = capped_cylinder_blobs(0.125, 0.625, 0.06)
    return b, np.full(len(b), 0.03)


def test_krylov_solve_equals_the_direct_one(body):
    # CG to rtol 1e-10 on an SPD matrix whose condition number is ~1e3 (measured): the
    # solution's relative error is at most cond x rtol ~ 1e-7
    b, r = body
    rng = np.random.default_rng(0)
    rhs = rng.standard_normal(3 * len(b))
    d, k = DirectBlobSolver(b, r), KrylovBlobSolver(b, r)
    xd, xk = d.solve(rhs), k.solve(rhs)
    assert np.linalg.norm(xk - xd) < 1e-7 * np.linalg.norm(xd)
    assert k.iterations[-1] < 30  # the two-level preconditioner works (block-Jacobi: ~50)
    C = rng.standard_normal((9, 3 * len(b)))
    assert np.allclose(screening_matrix(k, C), screening_matrix(d, C), rtol=1e-6,
                       atol=1e-7 * np.abs(screening_matrix(d, C)).max())


def test_krylov_iterations_stay_bounded_as_a_tube_is_refined():
    # a closed tube's blobs at spacing 0.3 and 0.14 (555 and 2352 blobs): block-Jacobi CG took
    # 154 and 201 iterations; the two-level preconditioner 28 and 32 (up to 17916 blobs: ~30,
    # docs/confinement.md). The bound: under 40 each, the finer within 1.3x the coarser;
    # and the solution the direct one's (cond x rtol, as above)
    from flagwrap.confinement.tube import Tube

    t = Tube(1.0, 6.0, closed=True)
    its = []
    for h in (0.3, 0.14):
        b = t.blob_shell(h, h)
        r = np.full(len(b), h)
        rhs = np.tile([0.0, 0.0, 1.0], len(b)) + 0.1 * np.random.default_rng(0).standard_normal(
            3 * len(b))
        k = KrylovBlobSolver(b, r)
        x = k.solve(rhs)
        its.append(k.iterations[-1])
        if h == 0.3:
            xd = DirectBlobSolver(b, r).solve(rhs)
            assert np.linalg.norm(x - xd) < 1e-7 * np.linalg.norm(xd)
    assert max(its) < 40 and its[1] < 1.3 * its[0]


def test_each_level_of_the_preconditioner_helps(body):
    # overlap off and deflation off: block-Jacobi; each level cuts the iterations
    b, r = body
    rhs = np.random.default_rng(1).standard_normal(3 * len(b))
    its = {}
    for name, kw in (("block-Jacobi", dict(overlap=0.0, deflate=False)),
                     ("overlap", dict(deflate=False)), ("both", {})):
        k = KrylovBlobSolver(b, r, **kw)
        k.solve(rhs)
        its[name] = k.iterations[-1]
    assert its["block-Jacobi"] > its["overlap"] > its["both"], its


def test_auto_picks_direct_for_a_small_body(body):
    assert make_blob_solver("auto", *body).kind == "direct"
    with pytest.raises(ValueError, match="blob solver"):
        make_blob_solver("lu", *body)


def test_krylov_swimmer_moves_as_the_direct_one():
    import dataclasses

    from conftest import make_config, paper_filament
    from flagwrap.system.swimmer import make_swimmer

    cfg = make_config(protocol=(("ccw", 0.05),), filament=paper_filament(n_beads=21))
    b = dict(surface="no-slip", motion="free", blob_spacing=0.025)
    out = []
    for solver in ("direct", "krylov"):
        c = cfg.replace(body=dataclasses.replace(cfg.body, solver=solver, **b))
        s = make_swimmer(c)
        y = s.initial_y()
        rng = np.random.default_rng(5)
        y[s.sl_x] += 1e-2 * s.bond * rng.standard_normal(s.sl_x.stop)
        out.append(s.apply_mobility(y, s.forces(y, s.frames0).G))
    assert np.abs(out[1] - out[0]).max() < 1e-7 * np.abs(out[0]).max()


def test_direct_solver_with_and_without_its_inverse_agree(body, monkeypatch):
    # up to INVERSE_MAX blobs the inverse serves the solves, above it the Cholesky factor
    b, r = body
    rhs = np.random.default_rng(3).standard_normal((3 * len(b), 2))
    with_inv = DirectBlobSolver(b, r)
    monkeypatch.setattr(DirectBlobSolver, "INVERSE_MAX", 0)
    factor = DirectBlobSolver(b, r)
    assert with_inv._inv is not None and factor._inv is None
    assert np.allclose(with_inv.solve(rhs), factor.solve(rhs), rtol=1e-12, atol=0)


def test_lagged_screening_recomputes_only_past_its_refresh_distance(body):
    # the screening is computed at the first call; a bead that moves by less than refresh x
    # its distance to the nearest blob gets the old matrix (the same object), one that moves
    # farther a fresh one, equal to the exact screening there
    from flagwrap.body.solver import LaggedScreening
    from flagwrap.body.fixed_mobility import FixedBodyMobility

    b, r = body
    x = np.array([[0.0, 0.0, -0.05], [0.02, 0.0, -0.1], [0.0, 0.03, -0.2]])
    mob = FixedBodyMobility(0.01, b, r)
    lag = LaggedScreening(mob._solver, b, mob._cross, refresh=0.3)
    d = np.min(np.linalg.norm(x[:, None] - b[None], axis=2), axis=1)
    S0 = lag(x)
    assert lag.computed == 1 and np.allclose(S0, mob.screening(x), rtol=1e-13, atol=0)
    near = x.copy()
    near[0, 0] += 0.29 * d[0]
    assert lag(near) is S0 and lag.computed == 1
    far = x.copy()
    far[2, 1] += 0.31 * d[2]
    S1 = lag(far)
    assert lag.computed == 2 and np.allclose(S1, mob.screening(far), rtol=1e-13, atol=0)
    assert np.abs(S1 - S0).max() > 0  # the beads moved, so the screening did
    with pytest.raises(ValueError, match="refresh"):
        LaggedScreening(mob._solver, b, mob._cross, refresh=-1.0)


def test_lagged_screening_stays_out_of_w_with_the_krylov_solver(body):
    # one screening would be a CG solve per bead coordinate: the Krylov path goes without
    from flagwrap.body.solver import LaggedScreening
    from flagwrap.body.fixed_mobility import FixedBodyMobility

    b, r = body
    x = np.array([[0.0, 0.0, -0.05], [0.02, 0.0, -0.1]])
    mob = FixedBodyMobility(0.01, b, r, solver="krylov")
    lag = LaggedScreening(mob._solver, b, mob._cross)
    assert lag(x) is None and lag.computed == 0 and lag.memory().size == 0
    assert np.array_equal(mob.stage_matrix(x), mob._free.matrix(x))


def test_the_krylov_bodys_mobility_never_stores_the_beads_x_blobs_block(body, monkeypatch):
    # with the Krylov blob solver the bead-blob products are computed pair by pair
    # (hydrodynamics.polydisperse.rpy_cross_apply); they are the stored block's products
    # (same pair law, summed in another order: 1e-13), and the mobility never builds it
    from flagwrap.body import fixed_mobility
    from flagwrap.body.fixed_mobility import FixedBodyMobility
    from flagwrap.hydrodynamics.polydisperse import rpy_cross_apply, rpy_cross_block

    b, r = body
    rng = np.random.default_rng(1)
    x = rng.standard_normal((30, 3)) * 0.2 + [0.0, 0.0, -0.2]
    x[0] = b[0] - [0.0, 0.0, 0.03]  # a bead overlapping a blob: the near-pair law
    Fx, Fy = rng.standard_normal((30, 3)), rng.standard_normal((len(b), 3))
    C = rpy_cross_block(x, 0.01, b, r)
    ux, uy = np.empty((30, 3)), np.empty((len(b), 3))
    rpy_cross_apply(x, 0.01, b, r, Fy, Fx, ux, uy)
    np.testing.assert_allclose(ux.ravel(), C @ Fy.ravel(), rtol=1e-12, atol=1e-13 * np.abs(ux).max())
    np.testing.assert_allclose(uy.ravel(), C.T @ Fx.ravel(), rtol=1e-12, atol=1e-13 * np.abs(uy).max())
    m = FixedBodyMobility(0.01, b, r, solver="krylov")
    assert m.matrix_free
    stored = FixedBodyMobility(0.01, b, r, solver="krylov")
    stored.matrix_free = False
    want = stored.apply(x, Fx)
    monkeypatch.setattr(fixed_mobility, "rpy_cross_block",
                        lambda *a: pytest.fail("the (3n, 3m) block was built"))
    got = m.apply(x, Fx)
    # CG to rtol 1e-10 on both sides (test above): the velocities agree to ~1e-9
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-8 * np.abs(want).max())
