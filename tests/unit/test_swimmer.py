"""The free-swimming cell (flagwrap.system.swimmer) and the rigid swimmer (body.rigid_swimmer)."""

import dataclasses

import numpy as np
import pytest

from flagwrap.errors import UserInputError
from flagwrap.system.swimmer import SwimmerSystem, make_swimmer, quaternion_matrix, quaternion_rate
from conftest import make_config, paper_filament


def swimmer_config(n_beads=21, spacing=0.025, protocol=(("ccw", 0.05),), **body):
    """A coarse Fig. 4(a)-like cell (21 beads; ~170 blobs at 25 mm on the 50 mm body)."""
    cfg = make_config(protocol=protocol, filament=paper_filament(n_beads=n_beads))
    b = dict(surface="no-slip", motion="free", blob_spacing=spacing)
    b.update(body)
    return cfg.replace(body=dataclasses.replace(cfg.body, **b))


@pytest.fixture(scope="module")
def swimmer():
    return make_swimmer(swimmer_config())


def perturbed_state(s, rng, amp=0.01):
    """A state off the stress-free shape (every generalized force non-zero), away from the body."""
    y = s.initial_y()
    y[s.sl_x] += amp * s.bond * rng.standard_normal(s.sl_x.stop - s.sl_x.start)
    y[s.sl_th] += 0.1 * rng.standard_normal(s.sl_th.stop - s.sl_th.start)
    y[s.i_phi] = 0.3
    return y, s.forces(y, s.frames0)


def tangents(x):
    e = np.diff(x, axis=0)
    return e / np.linalg.norm(e, axis=1)[:, None]


def test_load_on_the_body_is_what_the_free_unknowns_feel_opposite(swimmer, rng):
    # the invariance the module uses (S G of the free unknowns = minus the load on the clamp),
    # checked against the clamp's own gradients: sum of all forces and torques is zero
    s = swimmer
    y, info = perturbed_state(s, rng)
    x = info.x
    t = tangents(x)
    F, tau = -info.grad_x, -info.grad_theta
    assert np.all(info.distance[s.nc:] > s.body.cutoff)  # no contact: the body feels only the clamp
    force = F.sum(axis=0)
    torque = np.cross(x, F).sum(axis=0) + tau @ t
    scale = np.abs(F).sum() * np.abs(x).max() + np.abs(tau).sum()
    assert np.abs(force).max() < 1e-9 * np.abs(F).sum()
    assert np.abs(torque).max() < 1e-9 * scale


def test_free_body_exerts_no_force_or_torque_on_the_fluid(swimmer, rng):
    # the acceptance line: blob forces + bead forces (+ bond torques) sum to zero
    s = swimmer
    y, info = perturbed_state(s, rng)
    V, v, lam = s.body_velocity(y, info.G)
    x, _, _ = s.unpack(y)
    xf = x[s.nc:]
    F = info.G[s.sl_x].reshape(-1, 3)
    tau = info.G[s.sl_th]
    t = tangents(x)[s.ec:]
    L = lam.reshape(-1, 3)
    tot_f = F.sum(axis=0) + L.sum(axis=0)
    tot_t = np.cross(xf, F).sum(axis=0) + tau @ t + np.cross(s.blobs, L).sum(axis=0)
    # round-off of sums of O(|F|) terms (1e-12 relative, a Cholesky solve of ~500 unknowns)
    assert np.abs(tot_f).max() < 1e-10 * np.abs(F).sum()
    assert np.abs(tot_t).max() < 1e-10 * (np.abs(np.cross(xf, F)).sum() + np.abs(tau).sum())
    assert np.abs(V).max() > 0  # it does move


def test_mobility_matches_the_saddle_point_problem_solved_whole(swimmer, rng):
    # independent route: the full constrained Stokes problem over beads + blobs, unknowns the
    # blob forces and the body's rigid motion, one dense solve (no Schur complement)
    from flagwrap.body.multiblob import geometric_matrix
    from flagwrap.hydrodynamics.polydisperse import PolydisperseRPY

    s = swimmer
    y, info = perturbed_state(s, rng)
    x, _, _ = s.unpack(y)
    xf, t = x[s.nc:], tangents(x)[s.ec:]
    F = info.G[s.sl_x].reshape(-1, 3)
    tau = info.G[s.sl_th]
    nb, nbl = len(xf), len(s.blobs)
    P = np.concatenate([xf, s.blobs])
    Mall = PolydisperseRPY(np.concatenate([np.full(nb, s.radius), s.blob_radii])).matrix(P)
    K = geometric_matrix(s.blobs)
    n = 3 * nbl
    A = np.zeros((n + 6, n + 6))
    A[:n, :n] = Mall[3 * nb:, 3 * nb:]
    A[:n, n:] = -K
    A[n:, :n] = K.T
    load = np.concatenate([F.sum(axis=0), np.cross(xf, F).sum(axis=0) + tau @ t])
    rhs = np.concatenate([-Mall[3 * nb:, :3 * nb] @ F.ravel(), -load])
    sol = np.linalg.solve(A, rhs)
    lam, V = sol[:n], sol[n:]
    v = (Mall[:3 * nb, :3 * nb] @ F.ravel() + Mall[:3 * nb, 3 * nb:] @ lam).reshape(-1, 3)
    U, Om = V[:3] / s.machin, V[3:] / s.machin
    expect_x = v / s.machin - U - np.cross(Om, xf)
    expect_t = s.twist_mobility * tau - t @ Om
    got = s.apply_mobility(y, info.G)
    scale = np.abs(expect_x).max()
    assert np.abs(got[s.sl_x].reshape(-1, 3) - expect_x).max() < 1e-8 * scale
    assert np.abs(got[s.sl_th] - expect_t).max() < 1e-8 * np.abs(expect_t).max()
    R = quaternion_matrix(y[s.sl_q])
    assert np.allclose(got[s.sl_X], R @ U, rtol=1e-8, atol=1e-12 * scale)


def test_mobility_matrix_is_the_map_and_symmetric_positive(swimmer, rng):
    s = swimmer
    y, info = perturbed_state(s, rng)
    A = s.mobility_matrix(y)
    f = s.apply_mobility(y, info.G)
    assert np.allclose(A @ info.G[:s.n_in], f[:s.n_in], rtol=0, atol=1e-12 * np.abs(f).max())
    assert np.abs(A - A.T).max() < 1e-12 * np.abs(A).max()
    ev = np.linalg.eigvalsh(0.5 * (A + A.T))
    assert ev[0] > -1e-12 * ev[-1]  # positive semidefinite (the motor angle's row is zero)


def test_swimmer_w_pose_rows_are_the_pose_rates_of_the_force_change(rng):
    # W's pose rows -gamma h P J against their definition: the pose rates (apply_mobility is
    # linear in G at a fixed geometry) of J u, J u from central differences of the forces.
    # Tolerance 1e-6 of |r|: W's J is the kernel's one-sided differences at fd_step, which
    # differ from central ones by 1.4e-7 |r| in these rows (measured); the filament rows are
    # checked against the dense product (test_swimmer_w_from_triplets_is_the_dense_product).
    s = make_swimmer(swimmer_config())
    y, info = perturbed_state(s, rng)
    n, gh = s.n_in, 0.05
    W = s.make_w("dense", y, s.frames0, info.G, gh)
    r = rng.standard_normal(s.ny)
    u = W.solve(r)
    h = 1e-5 * s.bond
    dy = np.zeros(s.ny)
    dy[:n] = h * u[:n]
    Ju = (s.forces(y + dy, s.frames0).G - s.forces(y - dy, s.frames0).G) / 2.0
    Wu = u[n:] - gh * s.apply_mobility(y, Ju)[n:] / h
    assert np.abs(Wu - r[n:]).max() < 1e-6 * np.abs(r).max()
    assert np.abs(u[n:] - r[n:]).max() > 1e-3 * np.abs(r[n:]).max()  # the rows are not nothing


def test_swimmer_w_leaves_the_screening_out_while_a_bead_touches_the_body(rng):
    # with a bead in the body's contact range (here 1.5 bead radii off the cylinder) the
    # screened W made the controller alternate accepted and rejected steps (docs/bacterium.md,
    # "The stage solver"): W's filament block must then be the unscreened one, and the lagged
    # screening not computed; away from the body it is computed
    s = make_swimmer(swimmer_config())
    y, info = perturbed_state(s, rng)
    s.make_w("dense", y, s.frames0, info.G, 0.05)
    assert s._lagged.computed == 1
    k = s.sl_x.start + 3 * 5
    y[k:k + 3] = [0.125 + 1.5 * s.radius, 0.0, 0.2]
    info = s.forces(y, s.frames0)
    assert info.contact_energy > 0
    fresh = make_swimmer(swimmer_config())
    fresh.make_w("dense", y, fresh.frames0, info.G, 0.05)
    assert fresh._lagged.computed == 0
    A = fresh._a_buffers[0].copy()
    assert np.array_equal(A, make_swimmer(swimmer_config()).mobility_matrix(y, screening=False))


def test_cached_geometry_gives_the_fresh_systems_velocities(rng):
    # the swimmer keeps its last bead-blob block; velocities asked at y1, y2, y1 again (and
    # at y1 after the caller changed its array in place) must be a fresh system's, and the
    # stage solver's reusing A the same as a fresh one
    s, fresh = make_swimmer(swimmer_config()), make_swimmer(swimmer_config())
    (y1, i1), (y2, i2) = perturbed_state(s, rng), perturbed_state(s, rng)
    ref1 = fresh.apply_mobility(y1, i1.G)
    ref2 = make_swimmer(swimmer_config()).apply_mobility(y2, i2.G)
    for y, info, ref in ((y1, i1, ref1), (y2, i2, ref2), (y1, i1, ref1)):
        assert np.array_equal(s.apply_mobility(y, info.G), ref)
    y = y1.copy()
    s.apply_mobility(y, i1.G)
    y[s.sl_x] += 1e-3  # in place: the cache must not see its old state through a view
    assert np.array_equal(s.apply_mobility(y1.copy(), i1.G), ref1)
    A = s.mobility_matrix(y1, screening=False, reuse=True)
    assert np.array_equal(A, fresh.mobility_matrix(y1, screening=False))


def test_quaternion_kinematics_turn_about_a_fixed_axis():
    # dq/dt = q (0, Omega)/2 at constant Omega integrates to the rotation by |Omega| t
    from scipy.integrate import solve_ivp

    from flagwrap.system.rotating import rotation

    om = np.array([0.3, -0.5, 0.8])
    sol = solve_ivp(lambda t, q: quaternion_rate(q, om), (0.0, 2.0), [1.0, 0, 0, 0],
                    rtol=1e-11, atol=1e-12)
    R = quaternion_matrix(sol.y[:, -1])
    n = np.linalg.norm(om)
    assert np.allclose(R, rotation(om / n, 2.0 * n), atol=1e-8)
    assert np.allclose(R @ R.T, np.eye(3), atol=1e-12)


def test_a_short_free_run_counter_rotates_and_records_the_body(tmp_path):
    from flagwrap.io.runfile import read_run, write_run
    from flagwrap.simulation import simulate

    cfg = swimmer_config()
    traj = simulate(cfg)
    assert traj.ok, traj.message
    b = np.asarray(traj.body)
    assert b.shape == (len(traj.t), 13)
    # the motor turns the filament CCW about -z: the body turns the other way (+z)
    assert np.all(b[1:, 12] > 0)
    # the lab positions are X + R x': the clamp's first bead sits at the body's pole
    x = np.asarray(traj.x)
    for k in (0, -1):
        assert np.allclose(x[k, 0], b[k, :3], atol=1e-12)
    ds = read_run(write_run(traj, tmp_path / "swim.nc"))
    assert ds["body_position"].shape == (len(traj.t), 3)
    assert float(ds["body_angular_velocity"][-1, 2]) > 0


def test_fixed_body_limit_of_a_huge_body_drag(swimmer, rng):
    # scaling the body's mobility N to zero (an immovable body) gives the fixed no-slip body
    from flagwrap.body.fixed_mobility import FixedBodyMobility

    s = swimmer
    y, info = perturbed_state(s, rng)
    saved = s.body_mobility
    try:
        s.body_mobility = 0.0 * saved
        A = s.mobility_matrix(y)
    finally:
        s.body_mobility = saved
    x, _, _ = s.unpack(y)
    fixed = FixedBodyMobility(s.radius, s.blobs, s.blob_radii).matrix(x[s.nc:]) / s.machin
    n3 = fixed.shape[0]
    assert np.allclose(A[:n3, :n3], fixed, rtol=0, atol=1e-12 * np.abs(fixed).max())


@pytest.mark.parametrize("body, match", [
    (dict(motion="free"), "needs body.surface = 'no-slip'"),
    (dict(surface="no-slip", blob_radius=0.004), "body.blob_radius"),
    (dict(surface="no-slip", blob_spacing=0.2), "body.blob_spacing"),
    (dict(surface="sticky"), "body.surface must be one of"),
    (dict(motion="spinning"), "body.motion must be one of"),
])
def test_bad_body_input_names_the_key(body, match):
    cfg = make_config()
    with pytest.raises(UserInputError, match=match):
        cfg.replace(body=dataclasses.replace(cfg.body, **body))


def test_free_body_needs_a_turning_motor_and_hydrodynamics():
    with pytest.raises(UserInputError, match="needs a motor that turns"):
        swimmer_config(protocol=(("stop", 1),))
    cfg = make_config(hi=False)
    with pytest.raises(UserInputError, match="numerics.hydrodynamics = true"):
        cfg.replace(body=dataclasses.replace(cfg.body, surface="no-slip"))


def test_body_overlapping_the_filament_is_refused():
    # a large seed perturbation (it grows as (s/L)^2 from the clamp) throws the far end of
    # the helix up into the 25 cm body: refused before any step, naming the key
    from flagwrap.params import Initial
    from flagwrap.system.rod_system import RodSystem

    cfg = make_config(initial=Initial(perturbation=0.2, seed=4))
    with pytest.raises(UserInputError, match="body overlaps the filament.*initial.perturbation"):
        RodSystem(cfg).initial_y()
    RodSystem(make_config(initial=Initial(perturbation=0.2, seed=3))).initial_y()  # outside


def test_swimmer_needs_the_direct_free_space_mobility():
    from flagwrap.body.fixed_mobility import FixedBodyMobility
    from flagwrap.system.rod_system import RodSystem

    cfg = swimmer_config()
    inner = RodSystem(cfg, mobility=FixedBodyMobility(0.01, np.zeros((1, 3)) + 5, 0.1))
    with pytest.raises(ValueError, match="free-space direct RPY"):
        SwimmerSystem(inner, np.zeros((1, 3)), 0.1)


# the rigid swimmer ----------------------------------------------------------------------------
def _helix_and_sphere(level=2, distance=0.0):
    """The Fig. 4(a) helix's free beads (core units) hanging below a blob sphere of radius
    0.125 L whose lowest point is the motor at the origin; ``distance``: extra gap along -z."""
    from flagwrap.body.multiblob import sphere_blobs
    from flagwrap.system.rod_system import RodSystem

    s = RodSystem(make_config())
    helix = s.x0[s.nc:] - np.array([0.0, 0.0, distance])
    body = sphere_blobs(0.125 - 0.0104, level) + np.array([0.0, 0.0, 0.125])
    return body, 0.0104, helix, s.radius


def test_rigid_swimmer_is_force_and_torque_free_and_turns_at_the_motor_rate():
    from flagwrap.body.rigid_swimmer import rigid_swimmer

    body, ab, helix, a = _helix_and_sphere()
    r = rigid_swimmer(body, ab, helix, a, axis=(0, 0, -1), omega=1.0)
    assert r.residual_force < 1e-10 and r.residual_torque < 1e-10
    assert np.isclose((r.Omega_helix - r.Omega) @ np.array([0, 0, -1.0]), 1.0)
    assert r.Omega[2] > 0 and r.tau > 0  # the body counter-rotates; the motor does work


def test_rigid_swimmer_far_apart_reduces_to_the_two_resistance_matrices():
    # independent answer: with the helix on a long invisible stalk the bodies stop feeling each
    # other's flow and V_B = -(R_B + R_H)^-1 R_H omega [0; a] (each R from its own spheres); the
    # coupling falls as (size / distance), so the relative difference must too
    from flagwrap.body.multiblob import resistance_matrix
    from flagwrap.body.rigid_swimmer import rigid_swimmer
    from flagwrap.hydrodynamics.mobility import RPYMobility

    diffs = []
    for d in (2.0, 8.0):
        body, ab, helix, a = _helix_and_sphere(distance=d)
        r = rigid_swimmer(body, ab, helix, a, axis=(0, 0, -1), omega=1.0)
        RB = resistance_matrix(body, ab)
        RH = resistance_matrix(helix, a, mobility=RPYMobility(a).matrix(helix))
        e = np.array([0, 0, 0, 0, 0, -1.0])
        V = -np.linalg.solve(RB + RH, RH @ e)
        diffs.append(max(abs(r.U[2] - V[2]) / abs(V[2]), abs(r.Omega[2] - V[5]) / abs(V[5])))
    assert diffs[1] < 0.4 * diffs[0]  # 4x farther: at least 2.5x closer (1/d would be 4x)
    assert diffs[1] < 0.05


def test_stiff_elastic_swimmer_moves_like_the_rigid_one():
    # M = 3: the filament barely bends and co-rotates with its motor, so the elastic swimmer's
    # body velocity at a state must be the rigid swimmer's for that geometry. What separates
    # them: the state's error times the chain's stiffness (the velocity of a stiff chain is
    # the derivative of a state held to tol; measured 2e-2, 7e-3, 7e-5 of |V| at tol 1e-5,
    # 1e-6, 1e-7, and 2e-4 at 1e-7 with a W without the pose rows) and the bonds' twist drag
    # the rigid swimmer lacks (< 1e-4 at tol 1e-7). Tolerance 0.1 %: 5x the larger 2e-4.
    from flagwrap.body.rigid_swimmer import rigid_swimmer
    from flagwrap.simulation import Simulation

    cfg = swimmer_config(protocol=(("ccw", 0.1),))
    cfg = cfg.replace(motor=dataclasses.replace(cfg.motor, machin=3.0),
                      numerics=dataclasses.replace(cfg.numerics, tol=1e-7))
    sim = Simulation(cfg)
    traj = sim.run()
    assert traj.ok, traj.message
    s = sim.system
    b = np.asarray(traj.body)[-1]
    R = quaternion_matrix(b[3:7])
    xb = (np.asarray(traj.x[-1]) - b[:3]) @ R  # back to the body frame
    r = rigid_swimmer(s.blobs, s.blob_radii, xb[s.nc:], s.radius, axis=(0, 0, -1), omega=1.0)
    U, Om = R.T @ b[7:10], R.T @ b[10:13]
    assert np.abs(Om - r.Omega).max() < 0.001 * np.linalg.norm(r.Omega)
    assert np.abs(U - r.U).max() < 0.001 * np.linalg.norm(r.U)


def test_fixed_no_slip_body_is_wired_and_keeps_the_paper_keys():
    from flagwrap.body.fixed_mobility import FixedBodyMobility
    from flagwrap.params import Numerics
    from flagwrap.simulation import make_system

    cfg = make_config()
    ns = cfg.replace(body=dataclasses.replace(cfg.body, surface="no-slip"))
    s = make_system(ns)
    assert isinstance(s.mobility, FixedBodyMobility) and len(s.mobility.blobs) == 344
    # defaults leave the stored keys of the paper cases as they were
    assert "surface" not in cfg.to_dict(for_hash=True)["body"]
    assert ns.to_dict(for_hash=True)["body"]["surface"] == "no-slip"
    with pytest.raises(UserInputError, match="numerics.frame = 'rotating'"):
        ns.replace(numerics=Numerics(frame="rotating"))


def test_swimmer_frame_jacobian_is_the_derivative_of_its_velocity(swimmer, rng):
    # the linear-stability Jacobian (A dG + (dA/dx)[G] + exact rotation terms) against central
    # differences of the frame's velocity: 1e-5 of its largest entry (the differences' own
    # error at steps 1e-4 b on the stiff bonds is ~1e-7)
    from flagwrap.system.swimmer import SwimmerFrame

    s = swimmer
    fr = SwimmerFrame(s, -1.0)
    y, _ = perturbed_state(s, rng, amp=0.003)
    z = y[:fr.n]
    base = s.frames0
    J = fr.jacobian(z, base)
    h = 1e-4 * s.bond
    fd = np.empty_like(J)
    for k in range(fr.n):
        zp, zm = z.copy(), z.copy()
        zp[k] += h
        zm[k] -= h
        fd[:, k] = (fr.velocity(zp, base)[0] - fr.velocity(zm, base)[0]) / (2 * h)
    assert np.abs(J - fd).max() < 1e-5 * np.abs(fd).max()


def test_rigid_swimmer_speed_converges_with_the_blob_resolution():
    # the acceptance line's table (docs/bacterium.md, studies/swimmer_convergence.py): on a
    # blob sphere of fixed hydrodynamic radius the speed converges at second order, so each
    # refinement must shrink the change at least 2x (measured 3.5x, then 4x)
    from flagwrap.body.multiblob import effective_radii, sphere_blobs
    from flagwrap.body.rigid_swimmer import rigid_swimmer
    from flagwrap.system.rod_system import RodSystem
    from scipy.spatial import cKDTree

    s = RodSystem(make_config())
    helix, a = s.x0[s.nc:], s.radius
    speeds = []
    for lev in (1, 2, 3):
        u = sphere_blobs(1.0, lev)
        ab = 0.5 * cKDTree(u).query(u, k=2)[0][:, 1].mean()
        Rg = 0.125 / effective_radii(u, ab)[0]  # same hydrodynamic sphere at every level
        body = Rg * u + np.array([0.0, 0.0, 0.125])
        r = rigid_swimmer(body, ab * Rg, helix, a, axis=(0, 0, -1), omega=1.0)
        speeds.append(r.speed((0, 0, -1)))
    d1, d2 = abs(speeds[1] - speeds[0]), abs(speeds[2] - speeds[1])
    assert d2 < 0.5 * d1
    assert d2 < 0.005 * abs(speeds[2])


def test_fixed_no_slip_stage_w_is_the_lagged_screened_matrix(monkeypatch):
    # the stage solver's W is built from the screened matrix as last computed (FixedBodyMobility.
    # stage_matrix, LaggedScreening), the velocities from the exact one. A W-method keeps its
    # order for any W, so the run with the exact W (stage_matrix removed) must end where this
    # one does, to the errors of two tol-controlled runs: 20 tol, under the 25 x tol the
    # shorter one's 25 steps can add up to
    from flagwrap.body.fixed_mobility import FixedBodyMobility
    from flagwrap.simulation import make_system, simulate

    cfg = swimmer_config(motion="fixed")
    s = make_system(cfg)
    y = s.initial_y()
    Mxx, _ = s.mobility_blocks(y, stage=True)
    exact, _ = s.mobility_blocks(y)
    assert np.allclose(Mxx, exact, rtol=0, atol=1e-14 * np.abs(exact).max())  # first: exact
    free = s.mobility._free.matrix(s.unpack(y)[0][s.nc:]) / s.machin
    assert np.abs(exact - free).max() > 1e-3 * np.abs(free).max()  # the screening is not nothing
    approx = simulate(cfg)
    monkeypatch.delattr(FixedBodyMobility, "stage_matrix")
    ref = simulate(cfg)
    assert ref.status == approx.status == "completed"
    assert np.abs(np.asarray(approx.x[-1]) - np.asarray(ref.x[-1])).max() < 20 * cfg.numerics.tol


def test_swimmer_w_from_triplets_is_the_dense_product(swimmer, rng):
    # W^T = (I - gamma h A J)^T from the Jacobian's COO triplets (duplicates add) against the
    # dense product: the same sums in another order, so rounding (1e-12 of the largest entry)
    import scipy.sparse as sp

    from flagwrap.system.kernels import w_transpose_dense

    s = swimmer
    y, info = perturbed_state(s, rng)
    n = s.n_in
    rows, cols, vals = s.force_jacobian_coo(y[:n], s.frames0, info.G[:n])
    A = s.mobility_matrix(y, screening=False)
    WT = np.empty((n, n))
    w_transpose_dense(rows, cols, vals, A, np.empty(0), 0.3, WT)
    J = sp.coo_matrix((vals, (rows, cols)), shape=(n, n)).toarray()
    W = np.eye(n) - 0.3 * A @ J
    assert np.abs(WT.T - W).max() < 1e-12 * np.abs(W).max()


def test_the_swimmer_is_the_system_transformed_with_a_pose_block(rng):
    # a RodSystem over the same parts with the free body's pose after the filaments'
    # unknowns: pack takes the pose, pose() gives it back, the forces' pose rows are 0
    from flagwrap.system.rod_system import RodSystem

    s = make_swimmer(swimmer_config())
    assert isinstance(s, RodSystem) and "__getattr__" not in vars(SwimmerSystem)
    assert s.ny == s.n_rod + 7 and s.n_in == s.n_rod
    x, theta, phi = s.unpack(s.initial_y())
    q = rng.standard_normal(4)
    q /= np.linalg.norm(q)
    y = s.pack(x, theta, phi, X=(1.0, 2.0, 3.0), q=q)
    X, R = s.pose(y)
    np.testing.assert_array_equal(X, [1.0, 2.0, 3.0])
    np.testing.assert_allclose(R @ R.T, np.eye(3), atol=1e-14)
    assert np.array_equal(y[:s.n_rod], s.initial_y()[:s.n_rod])
    G = s.forces(y, s.frames0).G
    assert G.shape == (s.ny,) and not G[s.n_rod:].any()
