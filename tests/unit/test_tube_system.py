"""A tube as a part of the system (``[[tube]]``; docs/confinement.md, "Tubes"): every kind of
system that takes one runs inside it and stores it, its blobs screen the beads' flow, its
contact is its energy's gradient, and every kind that does not take one is refused by name."""

import math
import tomllib

import numpy as np
import pytest

from conftest import tiny_toml
from flagwrap.errors import UserInputError
from flagwrap.io.config import config_from_dict, config_to_toml

# the tiny rig hangs from the origin to z ~ -0.38 m, helix radius 0.03 m
TUBE = ("[[tube]]\nradius = 0.07\nlength = 0.5\ncenter = [0.0, 0.0, -0.2]\n"
        "blob_spacing = 0.025\n")
BODY = "[body]\nsurface = 'no-slip'\nblob_spacing = 0.025\n"
FREE_TUBE = ("[[tube]]\nradius = 0.07\nlength = 0.7\ncenter = [0.0, 0.0, -0.1]\n"
             "blob_spacing = 0.05\n")
KINDS = {
    "lab": ("", ""),
    "krylov": ("linear_solver = 'krylov'\n", ""),
    "no hydrodynamics (contact only)": ("hydrodynamics = false\n", ""),
    "tube chain": ("", "", "hydrodynamic_model = 'tube'\n"),
    "fixed no-slip body": ("", BODY),
    # a free cell's tube covers its body too (the body stands 0.3 m above the motor)
    "free cell": ("", BODY + "motion = 'free'\n", None, FREE_TUBE),
    "free cell, turning frame": ("frame = 'rotating'\n", BODY + "motion = 'free'\n", None,
                                 FREE_TUBE),
}


def _text(numerics="", tables="", fil=None, tube=TUBE, **kw):
    text = tiny_toml(**kw).replace("[numerics]\n", "[numerics]\n" + numerics)
    if fil:
        text = text.replace("n_beads = 21\n", "n_beads = 21\n" + fil)
    return text + tables + tube


@pytest.mark.parametrize("kind", list(KINDS))
def test_every_kind_of_system_runs_in_a_tube(kind, tmp_path):
    from flagwrap.body.fixed_mobility import FixedBodyMobility
    from flagwrap.hydrodynamics.tube import TubeMobility
    from flagwrap.interactions.wall import TubeContact
    from flagwrap.io.runfile import config_of, read_run, write_run
    from flagwrap.simulation import make_system, simulate

    numerics, tables, *more = KINDS[kind]
    fil = more[0] if more else None
    tube = more[1] if len(more) > 1 else TUBE
    cfg = config_from_dict(tomllib.loads(_text(numerics, tables, fil, tube, ccw=0.2, cw=0.1)))
    s = make_system(cfg)
    assert any(isinstance(it, TubeContact) for it in s.interactions)
    m = s.mobility.inner if isinstance(s.mobility, TubeMobility) else s.mobility
    if cfg.body.free:  # the swimmer sees the tube from its body, the tube's blobs apart
        from flagwrap.body.boundaries import TubeFromBody
        from flagwrap.system.parts import tube_blobs

        assert isinstance(s.boundary, TubeFromBody)
        assert len(s.boundary.blobs) == len(tube_blobs(cfg)[0])
    elif cfg.numerics.hydrodynamics:
        assert isinstance(m, FixedBodyMobility)
        n_body = 0
        if cfg.body.no_slip:
            from flagwrap.body.multiblob import cell_body_blobs

            n_body = len(cell_body_blobs(cfg)[0])
        from flagwrap.system.parts import tube_blobs

        assert len(m.blobs) == n_body + len(tube_blobs(cfg)[0])
    tr = simulate(cfg)
    assert tr.ok and tr.n_steps > 0
    write_run(tr, tmp_path / "run.nc")
    assert config_of(read_run(tmp_path / "run.nc")).tubes == cfg.tubes  # stored


def test_tube_screens_the_beads_flow():
    """The tube's blobs take flow off the beads: the mobility inside the tube is symmetric
    positive definite and below free space's (M_free - M_tube = the screening, SPD)."""
    from flagwrap.simulation import make_system

    cfg = config_from_dict(tomllib.loads(_text()))
    s = make_system(cfg)
    x = s.positions(s.initial_state()) if hasattr(s, "positions") else None
    x = np.asarray(s.x0 if x is None else x)
    M = s.mobility.matrix(x)
    free = config_from_dict(tomllib.loads(_text(tube="")))
    M0 = make_system(free).mobility.matrix(x)
    assert np.allclose(M, M.T, atol=1e-12 * np.abs(M).max())
    assert np.linalg.eigvalsh(M).min() > 0
    assert np.linalg.eigvalsh(M0 - M).min() > -1e-10 * np.abs(M).max()
    assert np.linalg.norm(M0 - M) > 1e-3 * np.linalg.norm(M0)


def test_tube_contact_is_its_energy_gradient_and_hessian():
    from flagwrap.confinement.tube import Tube
    from flagwrap.interactions.wall import TubeContact

    t = Tube(1.0, 6.0, constriction_radius=0.7, constriction_length=2.0, axis=(0.1, 0.0, 1.0))
    rng = np.random.default_rng(3)
    ang = rng.uniform(0, 2 * np.pi, 30)
    s = rng.uniform(-2.5, 2.5, 30)
    e1, e2, a = t.frame()
    r = t.wall_radius(s) - rng.uniform(0.03, 0.05, 30)  # near the wall, inside the cutoff
    x = s[:, None] * a + r[:, None] * (np.cos(ang)[:, None] * e1 + np.sin(ang)[:, None] * e2)
    c = TubeContact(t, 0.06, 1.0, np.ones(30, bool))
    g = np.zeros_like(x)
    c.energy_grad(x, None, g, None)
    num = np.zeros_like(x)
    eps = 1e-8
    scratch = np.zeros_like(x)
    for i in range(30):
        for k in range(3):
            xp, xm = x.copy(), x.copy()
            xp[i, k] += eps
            xm[i, k] -= eps
            num[i, k] = (c.energy_grad(xp, None, scratch, None)
                         - c.energy_grad(xm, None, scratch, None)) / (2 * eps)
    assert np.allclose(g, num, rtol=1e-5, atol=1e-7 * np.abs(g).max())
    # the Hessian of a straight tube is exact
    st = Tube(1.0, 6.0)
    xs = s[:, None] * st.frame()[2] + (0.98 * (np.cos(ang)[:, None] * st.frame()[0]
                                               + np.sin(ang)[:, None] * st.frame()[1]))
    cs = TubeContact(st, 0.06, 1.0, np.ones(30, bool))
    rows, cols, vals = cs.hessian_coo(xs, None)
    H = np.zeros((90, 90))
    np.add.at(H, (rows, cols), vals)
    Hn = np.zeros((90, 90))
    for j in range(90):
        d = np.zeros(90)
        d[j] = 1e-7
        gp, gm = np.zeros((30, 3)), np.zeros((30, 3))
        cs.energy_grad(xs + d.reshape(30, 3), None, gp, None)
        cs.energy_grad(xs - d.reshape(30, 3), None, gm, None)
        Hn[:, j] = (gp - gm).ravel() / 2e-7
    assert np.allclose(H, Hn, rtol=1e-4, atol=1e-5 * np.abs(H).max())


def test_config_round_trips():
    cfg = config_from_dict(tomllib.loads(_text(tube=TUBE + "constriction_radius = 0.05\n"
                                               "constriction_length = 0.1\nclosed = true\n")))
    back = config_from_dict(tomllib.loads(config_to_toml(cfg)))
    assert back.tubes == cfg.tubes and back.tubes[0].closed
    assert back.tubes[0].constriction_radius == pytest.approx(0.05)


@pytest.mark.parametrize("numerics, tables, tube, key", [
    ("frame = 'rotating'\n", "", TUBE, "numerics.frame"),
    ("frame = 'rotating'\n", BODY, TUBE, "numerics.frame"),
    ("", BODY + "motion = 'free'\nsolver = 'krylov'\n", TUBE, "body.solver"),
    ("", "", TUBE + TUBE, "one tube"),
    ("", "[[wall]]\npoint = [0.0, 0.0, -0.5]\nnormal = [0.0, 0.0, 1.0]\n", TUBE, r"\[\[wall\]\]"),
    ("", "", TUBE.replace("radius = 0.07", "radius = 0.04"), "the filament starts"),
    ("", "", TUBE.replace("radius = 0.07", "radius = 0.02"), r"tube\[0\]\.blob_spacing"),
    ("", "", TUBE.replace("center = [0.0, 0.0, -0.2]", "center = [0.2, 0.0, -0.2]"),
     "the filament starts"),
    ("", BODY + "radius = 0.08\n", TUBE, r"tube\[0\]\.radius"),
    ("", "", TUBE + "constriction_radius = 0.05\nconstriction_length = 0.6\n",
     r"tube\[0\]\.constriction_length"),
    ("", "", TUBE + "constriction_radius = 0.08\nconstriction_length = 0.1\n",
     r"tube\[0\]\.constriction_radius"),
    ("", "", TUBE.replace("center = [0.0, 0.0, -0.2]", "axis = [0.0, 0.0, 0.0]"),
     r"tube\[0\]\.axis"),
    ("", "", TUBE + "colour = 'red'\n", r"unknown key tube\[0\]\.colour"),
    ("", "", TUBE.replace("blob_spacing = 0.025", "blob_spacing = -1.0"),
     r"tube\[0\]\.blob_spacing"),
    # ~1e7 blobs: refused from the estimated count, before any blob is placed
    ("", "", TUBE.replace("blob_spacing = 0.025", "blob_spacing = 0.0001"),
     r"tube\[0\]\.blob_spacing = 0.0001 m puts ~\d+ blobs on the tube, more than the Krylov "
     r"blob solve takes \(20000\)"),
    ("", BODY + "solver = 'direct'\n", TUBE.replace("blob_spacing = 0.025", "blob_spacing = 0.004"),
     r"tube\[0\]\.blob_spacing = 0.004 m puts ~\d+ blobs on the tube and the body, more than "
     r"the direct blob solve takes \(10000\); .* or body.solver = 'krylov'"),
])
def test_refusals_name_the_key(numerics, tables, tube, key):
    with pytest.raises(UserInputError, match=key):
        config_from_dict(tomllib.loads(_text(numerics, tables, tube=tube)))


@pytest.mark.parametrize("kind, tube, key", [
    ("free cell", FREE_TUBE, r"a free cell in a \[\[tube\]\] has no steady whirl"),
    ("lab", TUBE.replace("center = [0.0, 0.0, -0.2]", "center = [0.01, 0.0, -0.2]"),
     r"tube\[0\] must be coaxial with the motor axis"),
    ("fixed no-slip body", TUBE.replace("[[tube]]\n", "[[tube]]\naxis = [0.0, 0.1, 1.0]\n"),
     r"tube\[0\] must be coaxial with the motor axis"),
])
def test_stability_refuses_a_tube_without_a_steady_whirl_by_name(kind, tube, key):
    from flagwrap.stability.threshold import make_frame

    numerics, tables = KINDS[kind][:2]
    cfg = config_from_dict(tomllib.loads(_text(numerics, tables, tube=tube)))
    with pytest.raises(UserInputError, match=key):
        make_frame(cfg, -1.0)


@pytest.mark.parametrize("kind", ["lab", "fixed no-slip body"])
def test_stability_in_a_coaxial_tube_is_a_whirl_the_lab_frame_keeps(kind):
    """A coaxial tube around the rig or a held cell: the turning frame holds the tube's blobs
    at one angle (as a held body's shell), an approximation the lab frame does not make
    (there the filament turns past the blobs standing still). Started on the turning frame's
    steady whirl at M = 500, the lab-frame integrator stays on it to the lattice's ripple:
    measured 1.2e-4 L over one turn (bounded: 1.3e-4 over two), where the rig without a tube
    keeps it to 1e-5 (test_stability); 5e-4 allows 4x. Newton converges on the whirl."""
    from test_stability import _lab_run

    from flagwrap.stability.steady import branch
    from flagwrap.stability.threshold import make_frame

    numerics, tables = KINDS[kind][:2]
    cfg = config_from_dict(tomllib.loads(_text(numerics, tables)))
    frame = make_frame(cfg, -1.0)
    st = branch(frame, [500.0])[500.0]
    assert st.converged
    _, dev = _lab_run(frame, st, np.zeros_like(st.z), 1.0)
    assert dev.max() < 5e-4


def test_memory_estimate_counts_the_tube_and_names_it():
    """The tube's blobs join the blob solver: the estimate counts them (to the shell's count)
    and, when they are what does not fit, the memory refusal names the tube's spacing."""
    from flagwrap.body.solver import AUTO_DIRECT_MAX
    from flagwrap.params import MAX_BLOBS
    from flagwrap.resources import check_memory, estimate
    from flagwrap.system.parts import tube_blobs

    assert AUTO_DIRECT_MAX <= MAX_BLOBS  # "auto" factorises only what the direct solve takes
    cfg = config_from_dict(tomllib.loads(_text()))
    est = estimate(cfg)
    assert est.blobs == pytest.approx(len(tube_blobs(cfg)[0]), rel=0.06)  # as the shell's test
    assert est.blob_memory >= 2 * 8 * (3 * est.blobs) ** 2  # the factor and the inverse
    with pytest.raises(UserInputError, match=r"the tube: about .* blobs with "
                                             r"tube\[0\]\.blob_spacing = 0\.025 m need"):
        check_memory(cfg, limit=0.5 * est.blob_memory)


@pytest.mark.parametrize("kind", ["lab", "fixed no-slip body"])
def test_analyze_reports_the_gap_to_the_tube(kind, tmp_path, capsys):
    # the straight tube's gap is R_t - r - a exactly, r each bead's distance from the axis
    # (the z axis through x = y = 0 here), computed from the run's positions directly
    from flagwrap.cli.main import main
    from flagwrap.io.runfile import read_run

    path = tmp_path / "t.toml"
    path.write_text(_text(*KINDS[kind][:2], ccw=0.2, cw=0.1))
    out = tmp_path / "t.nc"
    assert main(["run", str(path), "-o", str(out), "--quiet"]) == 0
    capsys.readouterr()
    assert main(["analyze", str(out), "--json", "--no-write"]) == 0
    import json

    res = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    ds = read_run(out)
    x = ds["position"].values
    gap = 0.07 - np.hypot(x[..., 0], x[..., 1]) - 0.0015
    w = res["wall"]
    assert w["boundary"] == "tube"
    assert w["gap_min"] == pytest.approx(gap.min(), rel=1e-12)
    assert w["gap_final"] == pytest.approx(gap[-1].min(), rel=1e-12)
    tip = ds["tip_position"].values[-1]
    assert w["tip_axis_distance_final"] == pytest.approx(math.hypot(tip[0], tip[1]), rel=1e-12)
    assert main(["analyze", str(out), "--no-write"]) == 0
    assert "tube: closest bead surface" in capsys.readouterr().out


def test_vtk_export_draws_the_tube(tmp_path):
    from flagwrap.io.runfile import read_run, write_run
    from flagwrap.io.vtk import export_vtk
    from flagwrap.simulation import simulate

    cfg = config_from_dict(tomllib.loads(_text(ccw=0.1, cw=0.1)))
    ds = read_run(write_run(simulate(cfg), tmp_path / "t.nc"))
    pvd = export_vtk(ds, tmp_path / "vtk", with_forces=False)
    assert 'part="2" file="boundary.vtp"' in pvd.read_text()
    import xml.etree.ElementTree as ET

    root = ET.parse(tmp_path / "vtk" / "boundary.vtp").getroot()
    pts = np.array(root.find(".//Points/DataArray").text.split(), float).reshape(-1, 3)
    assert np.allclose(np.hypot(pts[:, 0], pts[:, 1]), 0.07, atol=1e-12)  # on the wall
    assert pts[:, 2].min() == pytest.approx(-0.45) and pts[:, 2].max() == pytest.approx(0.05)


def test_movies_and_snapshots_draw_the_tubes_silhouette(tmp_path):
    # a tube along z of radius 0.07 seen side-on by both cameras: two lines at u = -0.07 and
    # +0.07 over its length; a tube along x is a circle of its radius for the camera on x
    from flagwrap.plotting.render import CAMERAS, boundary_lines

    cfg = config_from_dict(tomllib.loads(_text()))
    for cam in CAMERAS:
        lines = boundary_lines(cfg, cam)
        assert sorted(round(float(u.mean()), 12) for u, _ in lines) == [-0.07, 0.07]
        assert all(np.ptp(u) < 1e-12 and v.min() == pytest.approx(-0.45)
                   and v.max() == pytest.approx(0.05) for u, v in lines)
    from types import SimpleNamespace

    from flagwrap.params import TubeWall

    along_x = SimpleNamespace(tubes=(TubeWall(radius=0.3, length=0.9, center=(0.0, 0.0, -0.2),
                                              axis=(1.0, 0.0, 0.0)),), walls=())
    (u, v), = boundary_lines(along_x, CAMERAS[0])
    assert np.allclose(np.hypot(u, v + 0.2), 0.3)
    from flagwrap.io.runfile import read_run, write_run
    from flagwrap.plotting.snapshots import snapshot_figure

    ds = read_run(write_run(__import__("flagwrap.simulation").simulation.simulate(
        config_from_dict(tomllib.loads(_text(ccw=0.1, cw=0.1)))), tmp_path / "t.nc"))
    fig = snapshot_figure(ds, n=2)
    grey = [ln for ax in fig.axes for ln in ax.lines if ln.get_color() == "0.55"]
    assert len(grey) == 2 * 2 * 2  # two lines, two cameras, two panels


def test_analyze_reports_a_free_cell_in_a_tube(tmp_path, capsys):
    """The body centre's distance from the tube's axis, its tilt and its speeds along the
    tube and away from its axis, computed here from the pose directly (the sphere's centre
    is its pole plus its radius along the body axis); and the CLI prints them."""
    from flagwrap.analysis.runfile_attrs import analyze_run_file
    from flagwrap.cli.main import main
    from flagwrap.io.runfile import read_run, write_run
    from flagwrap.observables.swimming import quaternion_matrices
    from flagwrap.simulation import simulate

    sphere = ("[body]\nsurface = 'no-slip'\nshape = 'sphere'\nradius = 0.05\n"
              "blob_spacing = 0.02\nmotion = 'free'\n")
    tube = FREE_TUBE.replace("center = [0.0, 0.0, -0.1]", "center = [0.005, 0.0, -0.1]")
    cfg = config_from_dict(tomllib.loads(_text("", sphere, None, tube, ccw=0.2, cw=0.1)))
    path = write_run(simulate(cfg), tmp_path / "free.nc")
    w = analyze_run_file(path, write=False)["wall"]
    ds = read_run(path)
    R = quaternion_matrices(ds["body_orientation"].values)
    c = ds["body_position"].values + 0.05 * R[:, :, 2]
    r = np.hypot(c[:, 0] - 0.005, c[:, 1])  # the tube's axis is z through (0.005, 0)
    assert w["boundary"] == "tube"
    assert w["body_axis_distance_final"] == pytest.approx(r[-1], rel=1e-9)
    assert w["body_axis_distance_max"] == pytest.approx(r.max(), rel=1e-9)
    assert w["body_tilt_final_deg"] == pytest.approx(
        math.degrees(math.acos(abs(R[-1, 2, 2]))), abs=1e-9)
    t = ds["time"].values
    k = np.flatnonzero(t >= t[-1] - 2 * math.pi / cfg.scales.omega - 1e-12 * t[-1])
    dt = t[k[-1]] - t[k[0]]
    assert w["speed_along"] == pytest.approx((c[k[-1], 2] - c[k[0], 2]) / dt, rel=1e-9)
    assert w["speed_radial"] == pytest.approx((r[k[-1]] - r[k[0]]) / dt, rel=1e-9)
    assert main(["analyze", str(path), "--no-store"]) == 0
    assert "um/s along it" in capsys.readouterr().out


@pytest.mark.parametrize("kind", list(KINDS))
def test_a_run_from_a_state_across_the_tube_is_refused(kind):
    from test_wall_system import _kind_config, check_a_start_state_across_the_boundary_is_refused

    cfg = _kind_config(KINDS, kind, TUBE)
    check_a_start_state_across_the_boundary_is_refused(cfg, np.array([0.1, 0.0, 0.0]))
