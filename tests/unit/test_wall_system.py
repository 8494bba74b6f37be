"""A plane wall as a part of the system (``[[wall]]``; docs/confinement.md): every kind of
system that takes one runs beside it, its mobility is the wall's, its steric contact holds the
filament off it, the config round-trips, and every kind that does not take one is refused."""

import math
import tomllib

import numpy as np
import pytest

from conftest import tiny_toml
from flagwrap.errors import UserInputError
from flagwrap.io.config import config_from_dict, config_to_toml

SIDE = "[[wall]]\npoint = [0.08, 0.0, 0.0]\nnormal = [-1.0, 0.0, 0.0]\n"
BODY = "[body]\nsurface = 'no-slip'\nblob_spacing = 0.025\n"


def _cfg(numerics="", tables="", wall=SIDE, **kw):
    text = tiny_toml(**kw).replace("[numerics]\n", "[numerics]\n" + numerics)
    return config_from_dict(tomllib.loads(text + tables + wall))


FLOOR = "[[wall]]\npoint = [0.0, 0.0, -0.17]\nnormal = [0.0, 0.0, 1.0]\n"
KINDS = {
    "lab": ("", ""),
    "turning frame, floor wall": ("frame = 'rotating'\n", "", None, FLOOR),
    "krylov": ("linear_solver = 'krylov'\n", ""),
    "no hydrodynamics (contact only)": ("hydrodynamics = false\n", ""),
    "tube chain": ("", "", "hydrodynamic_model = 'tube'\n"),
    "fixed no-slip body": ("", BODY),
    "free cell": ("", BODY + "motion = 'free'\n"),
    "free cell, turning frame": ("frame = 'rotating'\n", BODY + "motion = 'free'\n"),
}


def _kind_config(kinds, kind, default_boundary):
    """The tiny rig's config for ``kinds[kind]`` = (numerics lines, tables[, filament lines[,
    boundary]]), with ``default_boundary`` where the kind names none."""
    numerics, tables, *more = kinds[kind]
    fil = more[0] if more else None
    boundary = more[1] if len(more) > 1 else default_boundary
    text = tiny_toml(ccw=0.2, cw=0.1).replace("[numerics]\n", "[numerics]\n" + numerics)
    if fil:
        text = text.replace("n_beads = 21\n", "n_beads = 21\n" + fil)
    return config_from_dict(tomllib.loads(text + tables + boundary))


@pytest.mark.parametrize("kind", list(KINDS))
def test_every_kind_of_system_runs_beside_a_wall(kind, tmp_path):
    from flagwrap.hydrodynamics.tube import TubeMobility
    from flagwrap.hydrodynamics.wall import WallMobility
    from flagwrap.interactions.wall import WallContact
    from flagwrap.io.runfile import config_of, read_run, write_run
    from flagwrap.simulation import make_system, simulate

    cfg = _kind_config(KINDS, kind, SIDE)
    s = make_system(cfg)
    assert any(isinstance(it, WallContact) for it in s.interactions)
    m = s.mobility.inner if isinstance(s.mobility, TubeMobility) else s.mobility
    if not cfg.numerics.hydrodynamics:
        assert type(m).__name__ == "LocalMobility"
    elif cfg.body.free:  # the swimmer carries the wall itself (its blobs move against it)
        assert s.wall is not None and np.allclose(s.wall.normal, [-1.0, 0.0, 0.0])
    elif cfg.body.no_slip:
        assert m.wall is s.wall and isinstance(m._free, WallMobility)
    else:
        assert isinstance(m, WallMobility)
    tr = simulate(cfg)
    assert tr.ok and tr.n_steps > 0
    write_run(tr, tmp_path / "run.nc")
    assert config_of(read_run(tmp_path / "run.nc")).walls == cfg.walls  # stored


def test_floor_wall_turning_frame_agrees_with_the_lab_and_raises_the_threshold():
    # a wall square to the motor axis keeps the turning frame's symmetry: the steady whirl of
    # both frames agrees (as without a wall, to the tolerance's error), and the linear
    # threshold rises as the wall slows the distal turns (docs/confinement.md)
    from flagwrap.simulation import simulate
    from flagwrap.stability.threshold import critical_from_config

    text = tiny_toml(ccw=2.0, cw=0.05, machin=100).replace("tol = 1e-3", "tol = 1e-6")
    tips = []
    for frame in ("lab", "rotating"):
        tr = simulate(config_from_dict(tomllib.loads(
            text.replace("[numerics]\n", f"[numerics]\nframe = '{frame}'\n") + FLOOR)))
        tips.append(np.asarray(tr.x)[-1][-1])
    assert np.linalg.norm(tips[0] - tips[1]) < 2e-5  # L; 5.2e-6 measured (4.6e-6 without a wall)
    free = critical_from_config(config_from_dict(tomllib.loads(tiny_toml())), "cw")
    near = critical_from_config(config_from_dict(tomllib.loads(tiny_toml() + FLOOR)), "cw")
    assert near.machin_c > free.machin_c * 1.03  # 1411 against 1324 measured


def test_far_wall_is_free_space_and_near_wall_screens():
    # the wall's correction decays as 1/h (Blake's image Stokeslet): 1000 L away the mobility
    # is free space to ~1e-3 of its entries' scale; at 0.2 L it slows every bead
    from flagwrap.simulation import make_system

    free = make_system(_cfg(wall=""))
    x = free.x0[free.free_beads]
    M0 = free.mobility.matrix(x)
    far = make_system(_cfg(wall="[[wall]]\npoint = [400.0, 0, 0]\nnormal = [-1.0, 0, 0]\n"))
    Mf = far.mobility.matrix(x)
    assert np.abs(Mf - M0).max() < 1e-3 * np.abs(M0).max()
    near = make_system(_cfg())
    Mn = near.mobility.matrix(x)
    assert np.all(np.diag(Mn) < np.diag(M0))
    assert np.linalg.eigvalsh(Mn).min() > 0 and np.abs(Mn - Mn.T).max() < 1e-14 * np.abs(Mn).max()


def test_fixed_body_beside_a_wall_direct_and_krylov_agree(rng):
    # the same mobility by the factorised blob matrix and by conjugate gradients on the
    # matrix-free RPY + wall products (both to rounding of the CG's 1e-10 residual)
    from flagwrap.body.fixed_mobility import FixedBodyMobility
    from flagwrap.body.multiblob import cell_body_blobs
    from flagwrap.hydrodynamics.wall import config_wall

    cfg = _cfg(tables=BODY.replace("0.025", "0.04"))
    blobs, radii = cell_body_blobs(cfg)
    wall = config_wall(cfg)
    d = FixedBodyMobility(0.004, blobs, radii, "direct", wall=wall)
    k = FixedBodyMobility(0.004, blobs, radii, "krylov", wall=wall)
    x = np.array([[0.05, 0.0, -0.05], [0.1, 0.02, -0.1], [0.15, -0.03, -0.2]])
    F = rng.normal(size=(3, 3))
    M = d.matrix(x)
    np.testing.assert_allclose(d.apply(x, F).ravel(), M @ F.ravel(), rtol=0, atol=1e-12 * np.abs(M).max())
    np.testing.assert_allclose(k.apply(x, F).ravel(), M @ F.ravel(), rtol=0, atol=1e-8 * np.abs(M).max())
    assert np.linalg.eigvalsh(M).min() > 0


def test_wall_contact_force_is_its_energy_gradient(rng):
    from flagwrap.hydrodynamics.wall import PlaneWall
    from flagwrap.interactions.wall import WallContact

    wall = PlaneWall([0.1, -0.2, 0.3], [1.0, 2.0, -0.5])
    c = WallContact(wall, cutoff=0.02, strength=3.0, active=np.ones(6, bool))
    x = wall.point + np.outer(rng.uniform(0.004, 0.03, 6), wall.normal) + 0.01 * rng.normal(size=(6, 3)) * [1, 1, 1]
    x = x - np.outer(wall.heights(x) - rng.uniform(0.004, 0.03, 6), wall.normal)
    g = np.zeros((6, 3))
    c.energy_grad(x, None, g, None)
    h = 1e-7
    for i in range(6):
        for k in range(3):
            xp, xm = x.copy(), x.copy()
            xp[i, k] += h
            xm[i, k] -= h
            ep = c.energy_grad(xp, None, np.zeros((6, 3)), None)
            em = c.energy_grad(xm, None, np.zeros((6, 3)), None)
            assert g[i, k] == pytest.approx((ep - em) / (2 * h), rel=1e-5, abs=1e-6 * np.abs(g).max())
    r, cc, v = c.hessian_coo(x, None)
    H = np.zeros((18, 18))
    np.add.at(H, (r, cc), v)
    for i in range(6):  # a column of the Hessian by differences of the gradient
        gp, gm = np.zeros((6, 3)), np.zeros((6, 3))
        xp, xm = x.copy(), x.copy()
        xp[i, 2] += h
        xm[i, 2] -= h
        c.energy_grad(xp, None, gp, None)
        c.energy_grad(xm, None, gm, None)
        np.testing.assert_allclose(H[:, 3 * i + 2], ((gp - gm) / (2 * h)).ravel(), rtol=1e-4,
                                   atol=1e-6 * np.abs(H).max())


def test_contact_holds_the_filament_off_a_wall_it_is_pushed_against():
    # a wall 1.5 a under the free end of a heavy filament (gravity along -z, the run's own
    # settling): contact keeps every bead's centre above the wall (the cut-off is 2 a)
    from flagwrap.simulation import simulate

    fil = "density_mismatch = 50.0\n"
    text = tiny_toml(ccw=0.5, cw=0.0, machin=100).replace(
        ', {direction = "cw", turns = 0.0}', "").replace("n_beads = 21\n", "n_beads = 21\n" + fil)
    base = config_from_dict(tomllib.loads(text))
    from flagwrap.geometry.helix import filament_positions

    a = base.filament.cross_section_radius
    z0 = float(filament_positions(base.filament, base.clamp)[:, 2].min())
    wall = f"[[wall]]\npoint = [0.0, 0.0, {z0 - 1.5 * a!r}]\nnormal = [0.0, 0.0, 1.0]\n"
    cfg = config_from_dict(tomllib.loads(text + wall))
    tr = simulate(cfg)
    assert tr.ok
    z = np.asarray(tr.x)[..., 2] * cfg.filament.length
    free = simulate(base)
    zf = np.asarray(free.x)[..., 2] * cfg.filament.length
    assert zf.min() < z0 - 2 * a  # without the wall it sinks through where the wall is
    assert z.min() > z0 - 1.5 * a + 0.5 * a  # with it, no centre within a / 2 of the wall


def test_config_round_trips_the_wall():
    cfg = _cfg()
    again = config_from_dict(tomllib.loads(config_to_toml(cfg)))
    assert again.walls == cfg.walls and again.walls[0].normal == (-1.0, 0.0, 0.0)
    assert config_from_dict(tomllib.loads(tiny_toml())).walls == ()


REFUSED = {
    "zero normal": ("[[wall]]\npoint = [0.08, 0, 0]\nnormal = [0.0, 0.0, 0.0]\n", "", "",
                    "wall[0].normal must not be zero"),
    "filament across": ("[[wall]]\npoint = [0.02, 0, 0]\nnormal = [-1.0, 0, 0]\n", "", "",
                        "wall[0].point"),
    "body across": ("[[wall]]\npoint = [0.0, 0, 0.05]\nnormal = [0.0, 0, -1.0]\n", "", "",
                    "cell body crosses the wall"),
    "two walls": (SIDE + SIDE.replace("0.08", "0.09"), "", "", "one wall is supported"),
    "free body, krylov blobs": (SIDE, "", BODY + "motion = 'free'\nsolver = 'krylov'\n",
                                "body.solver = 'direct'"),
    "turning frame, side wall": (SIDE, "frame = 'rotating'\n", "", "numerics.frame = 'rotating'"),
    "unknown key": ("[[wall]]\npoint = [0.08, 0, 0]\nnormal = [-1, 0, 0]\nradius = 1\n", "", "",
                    "unknown key wall[0].radius"),
}


@pytest.mark.parametrize("case", list(REFUSED))
def test_bad_walls_are_refused_by_the_cli(case, tmp_path, capsys):
    # one line naming the key, exit 2, nothing written
    from flagwrap.cli.main import main

    wall, numerics, tables, words = REFUSED[case]
    path = tmp_path / "bad.toml"
    path.write_text(tiny_toml().replace("[numerics]\n", "[numerics]\n" + numerics) + tables + wall)
    out = tmp_path / "bad.nc"
    assert main(["run", str(path), "-o", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and words in err[0] and not out.exists()
    with pytest.raises(UserInputError):
        config_from_dict(tomllib.loads(path.read_text()))


def test_wall_normal_need_not_be_unit():
    cfg = _cfg(wall="[[wall]]\npoint = [0.08, 0, 0]\nnormal = [-3.0, 0, 0]\n")
    from flagwrap.hydrodynamics.wall import config_wall

    w = config_wall(cfg)
    np.testing.assert_allclose(w.normal, [-1.0, 0.0, 0.0])
    assert w.point[0] == pytest.approx(0.08 / cfg.filament.length)
    assert math.isclose(float(w.heights(w.point + w.normal)), 1.0)


def test_analyze_reports_the_gap_to_the_wall(tmp_path, capsys):
    # the run file's positions against the stored wall: the smallest gap is the beads'
    # heights less a, computed here from the positions directly
    from flagwrap.cli.main import main
    from flagwrap.io.runfile import read_run

    path = tmp_path / "w.toml"
    path.write_text(tiny_toml(ccw=0.2, cw=0.1) + SIDE)
    out = tmp_path / "w.nc"
    assert main(["run", str(path), "-o", str(out)]) == 0
    capsys.readouterr()
    assert main(["analyze", str(out), "--json", "--no-write"]) == 0
    import json

    res = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    x = read_run(out)["position"].values
    gap = (0.08 - x[..., 0]) - 0.0015
    assert res["wall"]["gap_min"] == pytest.approx(gap.min(), rel=1e-12)
    assert res["wall"]["gap_final"] == pytest.approx(gap[-1].min(), rel=1e-12)
    assert main(["analyze", str(out), "--no-write"]) == 0
    assert "wall: closest bead surface" in capsys.readouterr().out


FREE_SPHERE = ("[body]\nsurface = 'no-slip'\nshape = 'sphere'\nradius = 0.05\n"
               "blob_spacing = 0.012\nmotion = 'free'\n")


def test_analyze_reports_a_free_cell_beside_the_wall(tmp_path):
    # the sphere's centre is its pole (the body's reference point, its lowest point in the
    # body frame) plus its radius along the body axis: its height above the wall, the axis's
    # angle to the plane and the speeds, computed here from the pose directly
    from flagwrap.analysis.runfile_attrs import analyze_run_file
    from flagwrap.io.runfile import read_run, write_run
    from flagwrap.observables.swimming import quaternion_matrices
    from flagwrap.simulation import simulate

    cfg = _cfg(tables=FREE_SPHERE, ccw=0.2, cw=0.1)
    path = write_run(simulate(cfg), tmp_path / "free.nc")
    w = analyze_run_file(path, write=False)["wall"]
    ds = read_run(path)
    R = quaternion_matrices(ds["body_orientation"].values)
    c = ds["body_position"].values + 0.05 * R[:, :, 2]
    h = 0.08 - c[:, 0]  # the wall x = 0.08 faces -x
    assert w["boundary"] == "wall"
    assert w["body_height_final"] == pytest.approx(h[-1], rel=1e-9)
    assert w["body_height_min"] == pytest.approx(h.min(), rel=1e-9)
    assert w["body_tilt_final_deg"] == pytest.approx(math.degrees(math.asin(-R[-1, 0, 2])), abs=1e-9)
    t = ds["time"].values
    k = np.flatnonzero(t >= t[-1] - 2 * math.pi / cfg.scales.omega - 1e-12 * t[-1])
    d = c[k[-1]] - c[k[0]]
    dt = t[k[-1]] - t[k[0]]
    assert w["speed_normal"] == pytest.approx(-d[0] / dt, rel=1e-9)
    assert w["speed_parallel"] == pytest.approx(math.hypot(d[1], d[2]) / dt, rel=1e-9)


@pytest.mark.parametrize("h", [1.5, 2.0, 4.0])
def test_free_cells_mobility_beside_a_wall_is_brenners(h):
    # the swimmer's own body mobility at its pose, a 212-blob sphere with a wall above it
    # (normal along the body axis: no rotation couples in), against Brenner's exact normal
    # drag at the blob sphere's radius R_t; measured 6e-5 to 1.4e-4 (64 blobs: 2.3e-3)
    from flagwrap.body.multiblob import effective_radii
    from flagwrap.simulation import make_system
    from flagwrap.theory.wall_drag import brenner_normal

    base = make_system(config_from_dict(tomllib.loads(tiny_toml() + FREE_SPHERE)))
    L = base.config.filament.length
    Rt, _ = effective_radii(base.blobs - [0.0, 0.0, 0.05 / L], base.blob_radii[0])
    zw = float(0.05 + h * Rt * L)  # the centre is 0.05 m up; the wall h R_t above it
    wall = f"[[wall]]\npoint = [0.0, 0.0, {zw!r}]\nnormal = [0.0, 0.0, -1.0]\n"
    s = make_system(config_from_dict(tomllib.loads(tiny_toml() + FREE_SPHERE + wall)))
    N = s._body(s.initial_y())[2]
    assert N[2, 2] * 6 * math.pi * Rt == pytest.approx(1 / brenner_normal(h), rel=1e-3)
    far = make_system(config_from_dict(tomllib.loads(tiny_toml() + FREE_SPHERE + wall.replace(
        f"{zw!r}", "400.0"))))
    np.testing.assert_allclose(far._body(far.initial_y())[2], base.body_mobility, rtol=1e-3,
                               atol=1e-3 * np.abs(base.body_mobility).max())


def test_free_cell_far_from_a_wall_swims_as_in_free_space(rng):
    # a force- and torque-free swimmer's image flow decays fast: 1000 L away its velocities
    # are free space's to 1e-9 (measured 3.5e-12); 0.2 L away they move by ~1 %
    from flagwrap.simulation import make_system

    text = tiny_toml() + BODY + "motion = 'free'\n"
    free = make_system(config_from_dict(tomllib.loads(text)))
    y = free.initial_y()
    y[free.sl_x] += 1e-3 * rng.standard_normal(free.sl_x.stop - free.sl_x.start)
    f0 = free.apply_mobility(y, free.forces(y, free.frames0.copy()).G)
    for wall, lo, hi in ((SIDE.replace("0.08", "400.0"), 0.0, 1e-9), (SIDE, 1e-3, 0.1)):
        s = make_system(config_from_dict(tomllib.loads(text + wall)))
        f = s.apply_mobility(y, s.forces(y, s.frames0.copy()).G)
        d = np.linalg.norm(f - f0) / np.linalg.norm(f0)
        assert lo <= d < hi, d
        A = s.mobility_matrix(y)
        assert np.abs(A - A.T).max() < 1e-12 * np.abs(A).max()


def test_the_walls_push_on_a_free_body_is_its_contact_energys_gradient():
    # the body's steric load: -dU/dX along the normal by differences of the energy as the
    # wall moves (U depends on X - p), and no push beyond the cut-off
    from flagwrap.body import _kernels as BK
    from flagwrap.body.boundaries import WallFromBody
    from flagwrap.hydrodynamics.wall import PlaneWall
    from flagwrap.simulation import make_system

    s = make_system(config_from_dict(tomllib.loads(tiny_toml() + FREE_SPHERE + (
        "[[wall]]\npoint = [0.0, 0.0, 0.1]\nnormal = [0.0, 0.0, -1.0]\n"))))
    y = s.initial_y()
    wc = s._boundary_contact
    cutoff, strength, c2 = wc.cutoff, wc.strength, wc.c2
    top = float(np.max(s.blobs[:, 2] + s.blob_radii))

    def energy(zwall):
        d = np.ascontiguousarray(zwall - s.blobs[:, 2] - s.blob_radii)
        e = np.empty(len(d))
        BK.wca_law(d, cutoff / 2 ** (1 / 6), strength, c2, e, np.empty(len(d)), np.empty(len(d)))
        return e.sum()

    z = top + 0.5 * cutoff  # the wall within reach of the top blobs
    s.boundary = WallFromBody(PlaneWall([0.0, 0.0, z], [0.0, 0.0, -1.0]))
    s._body_cache = (None, None)
    load = s.wall_load(y)
    h = 1e-6 * cutoff
    dUdz = (energy(z + h) - energy(z - h)) / (2 * h)  # moving the wall up = the body down
    assert load[2] == pytest.approx(dUdz, rel=1e-5) and load[2] < 0  # pushed away (down)
    assert np.abs(load[[0, 1, 3, 4, 5]]).max() < 1e-9 * abs(load[2])  # symmetric sphere
    s.boundary = WallFromBody(PlaneWall([0.0, 0.0, top + 2 * cutoff], [0.0, 0.0, -1.0]))
    s._body_cache = (None, None)
    assert np.all(s.wall_load(y) == 0.0)


def test_stability_refuses_a_free_cell_beside_a_wall(tmp_path, capsys):
    from flagwrap.cli.main import main

    path = tmp_path / "f.toml"
    path.write_text(tiny_toml() + BODY + "motion = 'free'\n" + SIDE)
    assert main(["stability", str(path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "no steady whirl" in err[0]


def test_vtk_export_draws_the_wall_under_the_run(tmp_path):
    from flagwrap.io.runfile import read_run, write_run
    from flagwrap.io.vtk import export_vtk
    from flagwrap.simulation import simulate

    ds = read_run(write_run(simulate(_cfg(ccw=0.1, cw=0.1)), tmp_path / "w.nc"))
    pvd = export_vtk(ds, tmp_path / "vtk", with_forces=False)
    assert 'part="2" file="boundary.vtp"' in pvd.read_text()
    import xml.etree.ElementTree as ET

    root = ET.parse(tmp_path / "vtk" / "boundary.vtp").getroot()
    pts = np.array(root.find(".//Points/DataArray").text.split(), float).reshape(-1, 3)
    assert np.allclose(pts[:, 0], 0.08, atol=1e-14)  # the plane x = 0.08
    x = ds["position"].values.reshape(-1, 3)  # the square covers every bead's foot
    assert (pts[:, 1].min() < x[:, 1].min() and pts[:, 1].max() > x[:, 1].max()
            and pts[:, 2].min() < x[:, 2].min() and pts[:, 2].max() > x[:, 2].max())


def test_movies_and_snapshots_draw_the_wall_seen_edge_on():
    # the wall x = 0.08 faces camera C1 (no edge to draw) and is edge-on to C2, whose image
    # axis is -x: the line u = -0.08
    from flagwrap.plotting.render import CAMERAS, boundary_lines

    cfg = _cfg()
    assert boundary_lines(cfg, CAMERAS[0]) == []
    (u, v), = boundary_lines(cfg, CAMERAS[1])
    assert np.allclose(u, -0.08) and np.ptp(v) > 10 * cfg.filament.length


def test_stage_hessian_looks_ahead_of_the_cut_off_and_nowhere_else(rng):
    # W's stiffness (docs in flagwrap.interactions.wall): beads deep in the contact keep the
    # exact Hessian, beads within the lookahead of the cut-off (either side) get the law's
    # stiffness that far inside, beads beyond it none
    from flagwrap.hydrodynamics.wall import PlaneWall
    from flagwrap.interactions.wall import WallContact

    wall = PlaneWall([0.0, 0.0, 0.0], [0.0, 0.0, 1.0])
    c = WallContact(wall, cutoff=0.02, strength=3.0, active=np.ones(5, bool))
    la = c.lookahead
    assert la == pytest.approx(0.5 * (0.02 - 0.02 / 2 ** (1 / 6)))  # half the shell
    h = np.array([0.012, 0.02 - 0.5 * la, 0.02, 0.02 + 0.5 * la, 0.02 + 2 * la])
    x = np.column_stack([rng.normal(size=(5, 2)), h])

    def zz(hess):
        out = np.zeros(15)
        trip = hess(x, None)
        if trip is not None:
            r, cc, v = trip
            np.add.at(out, r[r == cc], v[r == cc])
        return out[2::3]

    exact, stage = zz(c.hessian_coo), zz(c.stage_hessian_coo)
    k_ahead = c.law([0.02 - la])[2][0]
    assert exact[0] > k_ahead and stage[0] == exact[0]  # deep: the law's own
    assert 0 < exact[1] < k_ahead and stage[1] == k_ahead  # inside, near the cut-off
    assert exact[2] == exact[3] == 0 and stage[2] == stage[3] == k_ahead  # at and just beyond
    assert exact[4] == stage[4] == 0  # out of reach
    # and the forces are the law's: the lookahead is in W only
    g = np.zeros((5, 3))
    c.energy_grad(x, None, g, None)
    assert np.all(g[2:] == 0)


def _free_sphere_under(gap_in_cutoffs, normal=(0.0, 0.0, -1.0)):
    """The free sphere of FREE_SPHERE with a wall of normal ``normal`` this many contact
    cut-offs from its nearest blob's surface."""
    from flagwrap.body.boundaries import WallFromBody
    from flagwrap.hydrodynamics.wall import PlaneWall
    from flagwrap.simulation import make_system

    s = make_system(config_from_dict(tomllib.loads(tiny_toml() + FREE_SPHERE + (
        "[[wall]]\npoint = [0.0, 0.0, 0.1]\nnormal = [0.0, 0.0, -1.0]\n"))))
    y = s.initial_y()
    n = np.asarray(normal) / np.linalg.norm(normal)
    top = float(np.max(-(s.blobs @ n) + s.blob_radii))  # the blobs' reach along -n
    d = top + gap_in_cutoffs * s._boundary_contact.cutoff
    s.boundary = WallFromBody(PlaneWall(-d * n, n))
    s._body_cache = (None, None)
    return s, y


def test_the_bodys_contact_stiffness_is_its_loads_derivative_under_a_translation():
    # K = d[F; T]/dxi (body axes) by central differences of wall_load as the body moves:
    # exact for translations beside a plane; symmetric and negative semidefinite. A wall whose
    # blob gaps avoid the lookahead band, so the stage law is the law itself there
    from flagwrap.geometry.frames import quaternion_matrix

    n = (0.3, -0.2, -1.0)
    for off in np.linspace(0.3, 0.6, 31):
        s, y = _free_sphere_under(off, n)
        c = s._boundary_contact
        g = s._view(y).gap_gradient(s.blobs)[0] - s.blob_radii
        if not np.any(np.abs(g - c.cutoff) < 1.5 * c.lookahead):
            break
    else:
        pytest.fail("no wall position clear of the lookahead band")
    K = s.contact_stiffness(y)
    assert K is not None and np.abs(K).max() > 0
    R = quaternion_matrix(y[s.sl_q])
    h = 1e-4 * c.lookahead
    for k in range(3):
        dX = h * R[:, k]
        yp, ym = y.copy(), y.copy()
        yp[s.sl_X] += dX
        ym[s.sl_X] -= dX
        col = (s.wall_load(yp) - s.wall_load(ym)) / (2 * h)
        np.testing.assert_allclose(K[:, k], col, rtol=1e-5, atol=1e-7 * np.abs(K).max())
    assert np.allclose(K, K.T)
    assert np.linalg.eigvalsh(K).max() <= 1e-9 * np.abs(K).max()


def test_the_bodys_contact_stiffness_reaches_the_cut_off_and_goes_no_further():
    # a sphere resting at the cut-off has no exact stiffness (the C2 law's is zero there)
    # but W's looks ahead; beyond reach the pose block is the identity (pose_stiffness None)
    s, y = _free_sphere_under(1.0)  # the top blob's surface at the cut-off
    K = s.contact_stiffness(y)
    assert K is not None and K[2, 2] < 0
    P = s.pose_stiffness(y)
    assert P.shape == (7, 7) and P[2, 2] < 0  # pushed back along z: decays, not grows
    s, y = _free_sphere_under(1.0 + 1.5 * s._boundary_contact.lookahead
                              / s._boundary_contact.cutoff)
    assert s.contact_stiffness(y) is None and s.pose_stiffness(y) is None


def check_a_start_state_across_the_boundary_is_refused(cfg, shift):
    """A run from ``y0`` (not the config's rest shape) with its filament (and a free body)
    moved by ``shift`` (core units, lab axes) across the boundary is refused naming y0 before
    any step; the unmoved state passes the same check."""
    from flagwrap.simulation import Simulation
    from flagwrap.system.parts import check_start_state

    sim = Simulation(cfg)
    s = sim.system
    y = s.initial_y()
    check_start_state(cfg, s, y, s.forces(y, s.frames0.copy()))  # the config's own start
    bad = y.copy()
    if hasattr(s, "sl_X"):  # a free cell: move the whole cell
        bad[s.sl_X] += shift
    else:
        bad[s.sl_x] = (bad[s.sl_x].reshape(-1, 3) + shift).ravel()
    with pytest.raises(UserInputError, match=r"^y0: (bead \d+'s centre starts|the cell body crosses)"):
        sim.run(y0=bad)


@pytest.mark.parametrize("kind", list(KINDS))
def test_a_run_from_a_state_across_the_wall_is_refused(kind):
    cfg = _kind_config(KINDS, kind, SIDE)
    n = np.asarray(cfg.walls[0].unit_normal)
    check_a_start_state_across_the_boundary_is_refused(cfg, -0.5 * n)
