"""A free swimmer's observables (flagwrap.observables.swimming)."""

import math

import numpy as np

from flagwrap.observables.swimming import body_frame, phase_summary, quaternion_matrices
from flagwrap.system.rotating import rotation
from flagwrap.system.swimmer import quaternion_matrix


def _quat(axis, angle):
    a = np.asarray(axis, float) / np.linalg.norm(axis)
    return np.concatenate([[math.cos(angle / 2)], math.sin(angle / 2) * a])


def test_quaternion_matrices_match_the_single_one():
    rng = np.random.default_rng(1)
    q = rng.standard_normal((5, 4))
    R = quaternion_matrices(q)
    for k in range(5):
        assert np.allclose(R[k], quaternion_matrix(q[k]), atol=1e-14)


def test_body_frame_undoes_the_pose():
    rng = np.random.default_rng(2)
    xb = rng.standard_normal((4, 7, 3))  # body-frame beads, 4 frames
    X = rng.standard_normal((4, 3))
    q = np.array([_quat(rng.standard_normal(3), a) for a in (0.1, 1.0, 2.0, 3.0)])
    R = quaternion_matrices(q)
    lab = np.einsum("tij,tbj->tbi", R, xb) + X[:, None, :]
    assert np.allclose(body_frame(lab, X, q), xb, atol=1e-13)


def test_a_steady_corkscrew_gives_its_speed_rotation_and_pitch():
    # analytic: the body advances at v along its tilted axis e while turning at Omega about
    # it and the motor turns at omega relative to it: speed v, rotation Omega / 2 pi,
    # motor omega / 2 pi, displacement 2 pi v / omega per motor turn
    e0 = np.array([0.3, -0.2, 0.9])
    tilt = np.cross([0, 0, 1.0], e0 / np.linalg.norm(e0))
    tilt_angle = math.asin(np.linalg.norm(tilt))
    R0 = rotation(tilt / np.linalg.norm(tilt), tilt_angle)  # body z -> e
    e = R0[:, 2]
    v, Om, om = 2e-6, 9.0, 150.0
    t = np.linspace(0.0, 0.05, 201)
    X = np.outer(v * t, e)
    q = []
    for tk in t:  # R(t) = rot(e, Om t) R0
        Rk = rotation(e, Om * tk) @ R0
        w = math.sqrt(max(1e-300, 1 + np.trace(Rk))) / 2
        q.append([w, (Rk[2, 1] - Rk[1, 2]) / (4 * w), (Rk[0, 2] - Rk[2, 0]) / (4 * w),
                  (Rk[1, 0] - Rk[0, 1]) / (4 * w)])
    res = phase_summary(t, om * t, X, np.array(q), 0.0, t[-1])
    assert math.isclose(res["speed"], v, rel_tol=1e-10)
    assert math.isclose(res["body_rotation_hz"], Om / (2 * math.pi), rel_tol=1e-9)
    assert math.isclose(res["motor_rate_hz"], om / (2 * math.pi), rel_tol=1e-12)
    assert math.isclose(res["displacement_per_turn"], 2 * math.pi * v / om, rel_tol=1e-10)
    # the motor's power oscillating about its mean P0 over whole periods averages to P0, and
    # the efficiency is the towing power of the body at v over it
    P0, zeta = 3e-16, 2e-8
    power = P0 * (1 + 0.3 * np.sin(2 * math.pi * t / 0.0125))
    res = phase_summary(t, om * t, X, np.array(q), 0.0, t[-1], power=power, drag=zeta)
    assert math.isclose(res["motor_power"], P0, rel_tol=1e-6)  # trapezoids, 50 frames a period
    assert math.isclose(res["efficiency"], zeta * v * v / P0, rel_tol=1e-6)


def test_body_drag_of_a_sphere_is_stokes():
    # a spherical body's free-space drag 6 pi eta R (Stokes); 1 %: the blob shell at four
    # blobs per radius, whose drag converges from above (+2.9 % at two, +0.6 % at four)
    from test_swimmer import swimmer_config

    from flagwrap.observables.swimming import body_drag

    cfg = swimmer_config(spacing=0.0125, shape="sphere")
    Rb = cfg.body.resolved_radius(cfg.filament.helix_radius)
    assert math.isclose(body_drag(cfg), 6 * math.pi * cfg.fluid.viscosity * Rb, rel_tol=0.01)


def test_motor_power_of_a_stiff_swimmer_is_the_rigid_swimmers(tmp_path):
    # M = 3: the filament co-rotates with its motor as a rigid helix, so the motor's power
    # N_m Omega must be the rigid swimmer's tau omega for that geometry (body.rigid_swimmer),
    # averaged over the helix's phase about the body (8 phases). 0.5 %: the filament's
    # residual bending and the bonds' twist drag, which the rigid swimmer lacks (measured
    # 0.17 %)
    import dataclasses

    from test_swimmer import swimmer_config

    from flagwrap.body.rigid_swimmer import rigid_swimmer
    from flagwrap.io.runfile import read_run, write_run
    from flagwrap.observables.swimming import swimming_summary
    from flagwrap.simulation import Simulation

    cfg = swimmer_config(protocol=(("ccw", 1.5),))
    cfg = cfg.replace(motor=dataclasses.replace(cfg.motor, machin=3.0),
                      numerics=dataclasses.replace(cfg.numerics, tol=1e-6, save_every=0.05))
    sim = Simulation(cfg)
    traj = sim.run()
    assert traj.ok, traj.message
    final = swimming_summary(read_run(write_run(traj, tmp_path / "s.nc")))[-1]
    s = sim.system
    b = np.asarray(traj.body)[-1]
    helix = ((np.asarray(traj.x[-1]) - b[:3]) @ quaternion_matrix(b[3:7]))[s.nc:]
    taus = [rigid_swimmer(s.blobs, s.blob_radii, helix @ rotation([0, 0, 1.0], a).T, s.radius,
                          axis=(0, 0, -1), omega=1.0).tau
            for a in np.linspace(0.0, 2 * math.pi, 8, endpoint=False)]
    L, om = cfg.filament.length, 2 * math.pi * final["motor_rate_hz"]
    rigid = np.mean(taus) * cfg.fluid.viscosity * L ** 3 * om * om  # tau scales as eta L^3 omega
    assert math.isclose(final["motor_power"], rigid, rel_tol=0.005)
    assert 0 < final["efficiency"] < 1


def test_analyze_reports_a_free_swimmer_phase_by_phase(tmp_path):
    import dataclasses

    from conftest import make_config, paper_filament
    from flagwrap.analysis.runfile_attrs import analyze_run_file
    from flagwrap.io.runfile import write_run
    from flagwrap.simulation import simulate

    cfg = make_config(protocol=(("ccw", 0.1), ("cw", 0.1)), filament=paper_filament(n_beads=21))
    cfg = cfg.replace(body=dataclasses.replace(cfg.body, surface="no-slip", motion="free",
                                               blob_spacing=0.025))
    path = write_run(simulate(cfg), tmp_path / "swim.nc")
    res = analyze_run_file(path)
    sw = res["swimming"]
    assert [p["direction"] for p in sw] == ["ccw", "cw", "final"]
    # the motor keeps its rate relative to the body; the body turns against it
    assert math.isclose(sw[0]["motor_rate_hz"], cfg.omega / (2 * math.pi), rel_tol=1e-9)
    assert sw[0]["body_rotation_hz"] > 0 > sw[1]["body_rotation_hz"]
    # the motors do work in both directions, and the body is towed at less than that cost
    assert all(p["motor_power"] > 0 and 0 < p["efficiency"] < 1 for p in sw)


def test_the_moving_body_is_drawn_and_exported_where_it_is(tmp_path):
    # a synthetic free-swimmer run file: the body shifted by d and turned by 90 deg about x;
    # the renderer's body polygons and the VTK body file must carry that pose
    import dataclasses

    from conftest import make_config, paper_filament
    from flagwrap.io.runfile import trajectory_dataset
    from flagwrap.io.vtk import export_vtk
    from flagwrap.plotting.render import CAMERAS, Renderer, body_poses, scene_of, view_limits
    from flagwrap.simulation import Trajectory

    cfg = make_config(protocol=(("ccw", 0.1),), filament=paper_filament(n_beads=21))
    cfg = cfg.replace(body=dataclasses.replace(cfg.body, surface="no-slip", motion="free",
                                               blob_spacing=0.025))
    from flagwrap.system.swimmer import make_swimmer

    s = make_swimmer(cfg)
    y = s.initial_y()
    info = s.forces(y, s.frames0)
    tr = Trajectory(cfg)
    q = _quat([1, 0, 0], math.pi / 2)
    d = np.array([0.01, -0.02, 0.05]) / cfg.filament.length  # core units
    for k in range(2):
        tr.t.append(0.1 * k)
        tr.x.append(info.x)
        tr.theta.append(info.theta)
        tr.m1.append(np.tile([1.0, 0, 0], (len(info.theta), 1)))
        for name in ("phi", "omega", "motor_torque", "elastic_energy", "contact_energy",
                     "min_distance", "max_strain", "interaction_energy", "hook_angle",
                     "hook_torque", "hook_twist_torque"):
            getattr(tr, name).append(0.0)
        tr.body.append(np.concatenate([k * d, q if k else [1.0, 0, 0, 0], np.zeros(6)]))
    ds = trajectory_dataset(tr)
    poses = body_poses(ds)
    assert np.allclose(poses[0][1], d * cfg.filament.length)
    scene = scene_of(ds)
    r = Renderer(scene)
    top = scene.body_radius + scene.body_length
    # turned by 90 deg about x, the body's axis (+z) now points along -y
    ulim, zlim = view_limits(ds["position"].values, scene, poses=poses)
    assert ulim[1] - ulim[0] >= top
    p0, _ = r.polygons(ds["position"].values[1], CAMERAS[0])
    p1, _ = r.polygons(ds["position"].values[1], CAMERAS[0], (poses[0][1], poses[1][1]))
    def height(polys):
        z = np.concatenate(polys)[:, 1]
        return z.max() - z.min()

    # the upright body spans its height; lying along -y it spans ~its diameter vertically
    assert height(p0) - height(p1) > 0.5 * scene.body_length
    pvd = export_vtk(ds, tmp_path / "vtk", with_forces=False)
    files = sorted(p.name for p in pvd.parent.glob("body_*.vtp"))
    assert len(files) == 2


def test_analyze_draws_a_swimmer_and_refuses_a_fixed_body(tmp_path, tiny_run):
    import dataclasses

    from conftest import make_config, paper_filament
    from flagwrap.cli.main import main
    from flagwrap.io.runfile import write_run
    from flagwrap.simulation import simulate

    cfg = make_config(protocol=(("ccw", 0.1), ("cw", 0.1)), filament=paper_filament(n_beads=21))
    cfg = cfg.replace(body=dataclasses.replace(cfg.body, surface="no-slip", motion="free",
                                               blob_spacing=0.025))
    path = write_run(simulate(cfg), tmp_path / "swim.nc")
    assert main(["analyze", str(path), "--no-write", "--figure", str(tmp_path / "s.png")]) == 0
    assert (tmp_path / "s.png").stat().st_size > 10_000
    before = tiny_run.read_bytes()
    assert main(["analyze", str(tiny_run), "--figure", str(tmp_path / "t.png")]) == 2
    assert tiny_run.read_bytes() == before and not (tmp_path / "t.png").exists()


def _screw_motion(V, W, t):
    """Poses of a body whose velocity ``V`` and angular velocity ``W`` are constant in its own
    frame: ``R(t) = exp(t [W])``, ``X(t) = int_0^t R V`` (closed form, Rodrigues)."""
    from scipy.spatial.transform import Rotation

    w = np.linalg.norm(W)
    n = W / w
    R = Rotation.from_rotvec(np.outer(t, W)).as_matrix()
    # int_0^t exp(s[W]) ds V: the part along n advances linearly, the rest turns about n
    par = np.outer(t, (V @ n) * n)
    Vp = V - (V @ n) * n
    K = np.cross(n, Vp)
    perp = (np.outer(np.sin(w * t), Vp) + np.outer(1 - np.cos(w * t), K)) / w
    return par + perp, R


def test_screw_speed_is_the_progress_along_the_helix_whatever_the_window():
    # analytic: constant body-frame velocity V and rotation W give a helical path about W
    # whose progress is V . W/|W| per unit time (Purcell 1977); the body-axis displacement of
    # a tilted, wobbling cell over a part of a wobble depends on the window's start
    from flagwrap.observables.swimming import screw_progress

    rng = np.random.default_rng(7)
    for _ in range(20):
        V = rng.standard_normal(3)
        W = rng.standard_normal(3) * 3.0
        t = np.linspace(0.0, 4.0, 401)
        X, R = _screw_motion(V, W, t)
        # the oracle's own check: central differences are R V (error ~ dt^2 |W|^2 |V| / 6)
        dXdt = (X[2:] - X[:-2]) / (t[2] - t[0])
        assert np.allclose(dXdt, R[1:-1] @ V, atol=1e-3 * np.linalg.norm(V) * (1 + W @ W))
        expect = V @ W / np.linalg.norm(W)
        for i, j in ((0, 57), (120, 333), (200, 400)):
            axis = R[i][:, 2] + R[j][:, 2]
            got = screw_progress(X[[i, j]], R[[i, j]], axis) / (t[j] - t[i])
            assert abs(abs(got) - abs(expect)) < 1e-10 * (1 + abs(expect))


def test_screw_speed_through_phase_summary_and_at_a_half_turn():
    from flagwrap.observables.swimming import screw_progress

    V = np.array([0.4, -0.1, 1.0])
    W = np.array([0.0, 0.0, math.pi])  # half a turn per unit time about the body axis
    t = np.linspace(0.0, 1.0, 11)
    X, R = _screw_motion(V, W, t)
    assert abs(screw_progress(X[[0, -1]], R[[0, -1]], np.array([0, 0, 1.0])) - 1.0) < 1e-12
    q = np.array([_quat(W, math.pi * s) for s in t])
    row = phase_summary(t, 2 * math.pi * t, X, q, 0.0, 1.0)
    assert abs(row["screw_speed"] - 1.0) < 1e-12 and abs(row["speed"] - 1.0) < 1e-12
