"""The polymorph state wired in as a layout block (flagwrap.system.polymorph): a config
without [polymorph] is untouched, a one-state filament steps bit for bit as the fixed rod,
the block relaxes to the discrete wall within the lattice error of the tanh profile (P4),
and bad [polymorph] input is one line naming the key."""

import numpy as np
import pytest

from conftest import system_kinds, tiny_toml
from flagwrap.errors import UserInputError
from flagwrap.io.config import config_from_dict, tomllib

# W = 1e-3 N, K = 1e-6 N m^2: wall width sqrt(2 K / W) = 0.0447 m, 2.2 bonds of the tiny
# 21-bead chain (b = 0.02 m)
POLY = "[polymorph]\nenabled = true\nbarrier = 1e-3\nstiffness = 1e-6\n"


def _cfg(extra="", **kw):
    return config_from_dict(tomllib.loads(tiny_toml(**kw) + extra))


def test_no_polymorph_section_reads_and_hashes_as_before():
    cfg = _cfg()
    assert not cfg.polymorph.enabled and cfg.polymorph.is_default
    assert "polymorph" not in cfg.to_dict() and "polymorph" not in cfg.to_dict(for_hash=True)
    from flagwrap.simulation import make_system
    from flagwrap.system.rod_system import RodSystem

    assert type(make_system(cfg)) is RodSystem


def test_polymorph_config_round_trips():
    from flagwrap.io.config import config_to_toml

    cfg = _cfg(POLY + "initial = 'wall'\nrate = 2.0\n")
    assert config_from_dict(tomllib.loads(config_to_toml(cfg))) == cfg


KINDS = system_kinds()
RUNS_ON = ("lab", "turning frame", "krylov", "fixed no-slip body", "free cell",
           "free cell, turning frame", "two flagella on a free cell")


def _kind_cfg(kind, extra="", **kw):
    num, tables = KINDS[kind]
    return config_from_dict(tomllib.loads(
        tiny_toml(**kw).replace("[numerics]\n", "[numerics]\n" + num) + tables + extra))


@pytest.mark.parametrize("kind", RUNS_ON)
def test_one_state_filament_steps_bit_for_bit_as_the_fixed_rod(kind):
    """Both polymorphs the same and phi uniform in a well: the order block's force is exactly
    zero, and the system's own unknowns (a free cell's pose included) take the fixed rod's
    steps to the last bit, on every kind of system the polymorph runs on."""
    from flagwrap.simulation import make_system, simulate

    plain = _kind_cfg(kind, ccw=0.1, cw=0.05)
    one = _kind_cfg(kind, POLY + "polymorph_b = 'ecoli_normal'\n", ccw=0.1, cw=0.05)
    assert type(make_system(one)).__name__ == (
        "PolymorphSwimmerRotating" if kind == "free cell, turning frame" else
        "PolymorphSwimmer" if "free cell" in kind else
        "PolymorphRotating" if kind == "turning frame" else "PolymorphSystem")
    a, b = simulate(plain), simulate(one)
    assert a.status == b.status == "completed"
    assert (a.n_steps, a.n_rejected) == (b.n_steps, b.n_rejected)
    A, B = a.arrays(), b.arrays()
    assert set(B) - set(A) == {"order"}
    for k in A:
        assert np.array_equal(A[k], B[k]), k
    assert np.all(B["order"] == -1.0)


@pytest.mark.parametrize("kind", RUNS_ON)
def test_turning_moves_the_order_on_every_kind(kind):
    """Normal -> semicoiled on each kind: the run completes, records the order per frame,
    and the loaded rod moves phi off -1 (by ~1 % here: the test rig's helix is far below
    its switching load; which way depends on the bending and twist it carries, and on this
    rig CCW raises it; the E. coli test below checks the switch itself)."""
    from flagwrap.simulation import simulate

    tr = simulate(_kind_cfg(kind, POLY, ccw=0.3, cw=0.3))
    assert tr.ok, tr.message
    o = np.asarray(tr.order)
    assert o.shape == (len(tr.t), 21 * len(tr.filament_slices()))
    for sl in tr.filament_slices():  # each filament's own order moves
        assert np.abs(o[-1][sl] + 1.0).max() > 1e-3 and np.all(np.abs(o[:, sl]) < 1.1)


def _relax(system, t_end, h=0.02):
    """Step the system with the default integrator at a fixed motor speed 0 (no load)."""
    from flagwrap.integrators import REGISTRY

    integ = REGISTRY["ros34pw2"](1e-6)
    y = system.initial_y()
    info = system.forces(y, system.frames0.copy())
    t = 0.0
    while t < t_end:
        r = integ.step(system, y, info.frames, info, min(h, t_end - t), 0.0)
        if r.accepted:
            t += min(h, t_end - t)
            y, info = r.y, r.info
        h = r.h_next
    return y, info


def test_wall_relaxes_to_the_discrete_wall_near_the_tanh_profile():
    """phi starts as the tanh wall (P4) in a rod at rest (motor still): the block relaxes to
    the discrete wall of (P3), whose distance from tanh is the lattice error, second order
    in b/w (docs/polymorph.md: max abs(phi - tanh) 2.3e-3 at b/w = 0.2, ~0.06 (b/w)^2). Here
    b/w = 0.45 (a coarse chain, to stay fast), so the bound is 0.1 (b/w)^2 = 0.02, and the
    wall's centre, pinned by symmetry, stays at mid-contour. Both polymorphs are the same
    shape, so the rod does not push on phi and the wall is (P3)'s alone. The rate is the default, a well
    relaxing at 2 Gamma W = 10 per unit time; t = 3 is 30 relaxation times."""
    from flagwrap.simulation import make_system

    cfg = _cfg(POLY + "initial = 'wall'\npolymorph_b = 'ecoli_normal'\n")
    system = make_system(cfg)
    phi0 = system.order(system.initial_y()).copy()
    y, info = _relax(system, 3.0)
    phi = system.order(y)
    s = np.concatenate([[0.0], np.cumsum(system.order_bonds)])
    w = system.model.wall_width
    b = system.order_bonds[0]
    tanh = np.tanh((s - 0.5 * s[-1]) / w)
    assert np.array_equal(phi0, tanh)
    err = np.abs(phi - tanh).max()
    assert err < 0.1 * (b / w) ** 2, err
    # antisymmetric about the centre (the wall did not drift)
    assert np.abs(phi + phi[::-1]).max() < 1e-6
    # at rest: the generalized force on phi vanishes, the energy is below the tanh's
    assert np.abs(info.G[system.sl_order]).max() < 1e-5 * system.model.barrier
    from flagwrap.elasticity.polymorph import total_energy

    e_tanh = total_energy(tanh, system.model, 0.0, system.order_vor, system.order_bonds)
    assert info.polymorph_energy <= e_tanh
    # the rod stays at rest (one rest shape, no load; the rest shape's round-off forces only)
    assert np.abs(y[:system.n_rod] - system.initial_y()[:system.n_rod]).max() < 1e-9


@pytest.mark.parametrize("extra, key", [
    ("polymorph_a = 'nope'\n", "polymorph.polymorph_a"),
    ("polymorph_b = 'ecoli_coiled'\n", "polymorph.polymorph_b"),
    ("rate = -1.0\n", "polymorph.rate"),
    ("initial = 'c'\n", "polymorph.initial"),
    ("wall_position = 1.0\n", "polymorph.wall_position"),
    ("transition = 'nope'\n", "polymorph.transition"),
    ("transition = 'salmonella_normal_semicoiled'\ndomain_wall_width = 0.05\n", "polymorph.barrier"),
    ("domain_wall_width = 0.05\n", "polymorph.domain_wall_width"),
    ("domain_wall_width = -0.05\n", "polymorph.domain_wall_width"),
])
def test_bad_polymorph_input_is_one_line_naming_the_key(extra, key):
    with pytest.raises(UserInputError) as exc:
        _cfg(POLY + extra)
    msg = str(exc.value)
    assert key in msg and "\n" not in msg


def test_missing_barrier_and_narrow_wall_are_refused():
    with pytest.raises(UserInputError, match="polymorph.barrier is required"):
        _cfg("[polymorph]\nenabled = true\nstiffness = 1e-6\n")
    with pytest.raises(UserInputError, match="polymorph wall width"):
        _cfg("[polymorph]\nenabled = true\nbarrier = 1e-3\nstiffness = 1e-8\n")


def test_cli_exit_2_names_the_key(tmp_path):
    import subprocess
    import sys

    p = tmp_path / "bad.toml"
    p.write_text(tiny_toml() + POLY + "rate = -3\n")
    r = subprocess.run([sys.executable, "-m", "flagwrap.cli.main", "run", str(p), "-o",
                        str(tmp_path / "o.nc")], capture_output=True, text=True,
                       env={**__import__("os").environ,
                            "PYTHONPATH": str(__import__("pathlib").Path(__file__).parents[2] / "src")})
    assert r.returncode == 2, r.stderr
    assert "polymorph.rate" in r.stderr


# --- the rod's rest shape follows phi (docs/polymorph.md, "Wiring") ---------------------
@pytest.mark.parametrize("kind", ["lab", "two flagella on a free cell"])
def test_order_force_is_minus_the_gradient_of_the_total_energy(kind):
    """``G_order`` against central differences of the rod's elastic energy plus (P3), at a
    bent and twisted rod with a random phi field (both polymorphs differ: normal ->
    semicoiled), on one filament and on two (each its own chain). Step 1e-6: truncation
    ~1e-12 and round-off ~1e-16/1e-6 relative, so 1e-6 relative is a loose bound that a
    missing term (e.g. the twist part, ~30 % here) fails."""
    from flagwrap.simulation import make_system

    s = make_system(_kind_cfg(kind, POLY))
    rng = np.random.default_rng(0)
    y = s.initial_y()
    y[:s.i_phi] += 1e-3 * rng.standard_normal(s.i_phi)
    y[s.sl_order] = rng.uniform(-1.0, 1.0, s.N)
    base = s.frames0.copy()
    G = s.forces(y, base).G[s.sl_order].copy()

    def energy(yy):
        i = s.forces(yy, base)
        return i.elastic_energy + i.polymorph_energy

    h = 1e-6
    for k in range(s.N):
        yp, ym = y.copy(), y.copy()
        yp[s.sl_order.start + k] += h
        ym[s.sl_order.start + k] -= h
        fd = -(energy(yp) - energy(ym)) / (2 * h)
        assert abs(fd - G[k]) < 1e-6 * max(1.0, abs(G[k])), (k, fd, G[k])


def test_polymorph_b_in_a_material_frames_is_stress_free():
    """The rest pair (``rest_pair``): B's own helix (its positions from the library's ratios),
    carrying A's material frames (its twist-free frames turned by ``c`` per bond, matched at
    one vertex), has zero bending and twist energy under the rest at ``phi = +1`` on every
    transforming vertex, and A's rest costs it O(1): normal (left) -> semicoiled (right), the
    handedness flip."""
    import dataclasses

    from flagwrap.elasticity.rod import elastic_energy, initial_frames, rest_state
    from flagwrap.geometry.helix import helix_positions
    from flagwrap.simulation import make_system
    from flagwrap.system.polymorph import _angles, polymorph_geometry

    cfg = _cfg(POLY)
    s = make_system(cfg)
    L = cfg.filament.length
    R, P, hand = polymorph_geometry(cfg)
    assert hand == "right" and R == cfg.filament.helix_radius
    assert P == pytest.approx(0.5 * cfg.filament.pitch)  # semicoiled: half the normal pitch
    xb = helix_positions(1.0, R / L, P / L, s.N, hand)
    fb = initial_frames(xb)
    rb = rest_state(xb, fb, np.zeros(s.N - 1))
    c = (s.mbar_b - s.mbar_a)[s.order_changes]
    assert np.ptp(c) < 1e-15 and c[0] != 0.0
    c, i = c[0], 5
    theta = _angles(rb.kbar)[i] - _angles(s.kbar_a)[i] - (i - 0.5) * c + c * np.arange(s.N - 1)
    mask = s.order_changes
    rest = s.parts[0].rest
    only = dict(stretch=0.0, cbend=np.where(mask, rest.cbend, 0.0),
                ctwist=np.where(mask, rest.ctwist, 0.0))
    e_b = elastic_energy(xb, theta, fb, dataclasses.replace(rest, kbar=s.kbar_b, mbar=s.mbar_b,
                                                              **only))
    e_a = elastic_energy(xb, theta, fb, dataclasses.replace(rest, kbar=s.kbar_a, mbar=s.mbar_a,
                                                              **only))
    assert e_b < 1e-24 and e_a > 1.0, (e_b, e_a)


def test_rod_at_phi_one_relaxes_to_polymorph_b():
    """A right-handed semicoiled rod switched to curly I (half the radius, same pitch and
    hand: ``initial = 'b'``), motor still: the rod relaxes to B's helix (its pairwise bead
    distances to 1e-8 L, B's positions built independently by ``helix_positions``), phi stays
    at +1 and the elastic energy vanishes."""
    from scipy.spatial.distance import pdist

    from flagwrap.geometry.helix import helix_positions
    from flagwrap.simulation import make_system
    from flagwrap.system.polymorph import polymorph_geometry

    cfg = config_from_dict(tomllib.loads(
        tiny_toml().replace("turns = 2\n", "turns = 2\nhandedness = 'right'\n") + POLY
        + "polymorph_a = 'ecoli_semicoiled'\npolymorph_b = 'ecoli_curly1'\ninitial = 'b'\n"))
    s = make_system(cfg)
    y, info = _relax(s, 50.0)
    x = s.unpack(y)[0]
    L = cfg.filament.length
    R, P, hand = polymorph_geometry(cfg)
    assert R == pytest.approx(0.5 * cfg.filament.helix_radius) and P == cfg.filament.pitch
    xb = helix_positions(1.0, R / L, P / L, s.N, hand)
    assert np.abs(pdist(x[1:]) - pdist(xb[1:])).max() < 1e-8
    assert np.abs(pdist(x[1:]) - pdist(s.x0[1:])).max() > 0.1  # it did move
    assert np.abs(s.order(y) - 1.0).max() < 1e-8
    assert info.elastic_energy < 1e-12


def test_run_file_and_checkpoint_keep_the_order_parameter(tmp_path):
    """The order parameters are recorded per frame, written to the run file
    (``polymorph_order``, with the two polymorphs' names) and kept by a checkpoint: a run
    resumed from it equals the uninterrupted one bit for bit, order included."""
    from flagwrap.io.checkpoint import read_checkpoint
    from flagwrap.io.runfile import read_run, write_run
    from flagwrap.simulation import simulate

    cfg = _cfg(POLY + "initial = 'wall'\n", ccw=0.2, cw=0.3)
    ref = simulate(cfg)
    assert ref.ok and np.asarray(ref.order).shape == (len(ref.t), 21)
    ck = tmp_path / "c.h5"
    simulate(cfg, checkpoint_path=ck, checkpoint_every_steps=40)
    assert "order" in read_checkpoint(ck).records
    again = simulate(cfg, resume=ck)
    A, B = ref.arrays(), again.arrays()
    assert set(A) == set(B) and "order" in A
    for k in A:
        assert np.array_equal(A[k], B[k]), k
    ds = read_run(write_run(ref, tmp_path / "r.nc"))
    assert np.array_equal(ds["polymorph_order"].values, np.asarray(ref.order))
    assert ds.attrs["polymorph_a"] == "ecoli_normal" and ds.attrs["polymorph_b"] == "ecoli_semicoiled"
    # a run without the state has no such variable
    plain = simulate(_cfg(ccw=0.05, cw=0.05))
    assert not plain.order and "order" not in plain.arrays()


def test_polymorph_summary_reads_a_known_front(tmp_path):
    """``polymorph_summary`` on a run file whose order field is replaced by a tanh front
    leaving the motor at a known speed v (B behind it): B begins at the motor, the front's
    speed is v (the zero crossing of a tanh two bonds wide, interpolated linearly, is exact
    to 1e-3 of a bond: the bound 1 %), the final fraction is the front's position over the
    transforming contour; a run that never enters B says so."""
    from flagwrap.io.runfile import read_run, write_run
    from flagwrap.observables.polymorph import polymorph_summary, transforming_vertices
    from flagwrap.simulation import simulate

    cfg = _cfg(POLY, ccw=0.05, cw=0.5)
    ds = read_run(write_run(simulate(cfg), tmp_path / "r.nc"))
    none = polymorph_summary(ds)
    assert none["start_turns"] is None and none["fraction_b_final"] == 0.0
    assert polymorph_summary(read_run(write_run(simulate(_cfg(ccw=0.05, cw=0.05)),
                                                tmp_path / "p.nc"))) is None
    mask = transforming_vertices(cfg)
    x0 = ds["position"].values[0]
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(x0, axis=0), axis=1))])
    t = ds["time"].values
    L = cfg.filament.length
    v = 0.6 * L / t[-1]  # crosses 60 % of the filament over the run
    w = 2 * cfg.filament.bond_length
    front = 0.15 * L + v * (t - t[0])
    order = np.tanh((front[:, None] - s[None, :]) / w)
    order[0] = -1.0  # all A at first: B appears in the second frame, at the motor
    ds["polymorph_order"].values[:] = order
    res = polymorph_summary(ds)
    assert res["starts_at"] == "motor" and res["start_turns"] == ds["turns"].values[1]
    assert res["start_position_m"] < 0.2 * L
    # semicoiled: half the pitch, the same radius: its helix hangs shorter (a higher free end)
    fil = cfg.filament
    assert res["height_a"] == pytest.approx(-fil.pitch / np.hypot(2 * np.pi * fil.helix_radius,
                                                                   fil.pitch))
    assert res["height_b"] > res["height_a"]
    assert res["front_speed_m_s"] == pytest.approx(v, rel=0.01)
    sm = s[mask]
    assert res["fraction_b_final"] == pytest.approx(np.mean(sm < front[-1]), abs=1e-12)


def test_cli_analyze_reports_the_polymorph_and_stability_refuses_two_flagella(tmp_path, capsys):
    """``flagwrap analyze`` prints the polymorph line of a polymorph run (and none for a
    fixed-shape one); ``flagwrap stability`` refuses a polymorph config with two flagella by
    name, exit 2, before any work (its turning frame needs one on the motor axis)."""
    from flagwrap.cli.main import main

    body = "[body]\nenabled = true\n"
    for extra, expect in ((POLY + body, "polymorph ecoli_normal -> ecoli_semicoiled"),
                          (body, None)):
        cfg = tmp_path / "c.toml"
        cfg.write_text(tiny_toml(ccw=0.1, cw=0.3) + extra)
        out = tmp_path / "r.nc"
        assert main(["run", str(cfg), "-o", str(out), "--quiet"]) == 0
        capsys.readouterr()
        assert main(["analyze", str(out), "--no-store"]) == 0
        text = capsys.readouterr().out
        assert (expect in text) if expect else ("polymorph" not in text)
    cfg.write_text(tiny_toml() + POLY + KINDS["two flagella on a free cell"][1])
    assert main(["stability", str(cfg), "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert "polymorph.enabled" in err and "[[flagellum]]" in err and err.count("\n") == 1


def test_tube_is_coloured_by_polymorph():
    """``polymorph_rgb``: phi = -1 gives the tube's colour, +1 the B colour, a wall in the
    middle mixes them in order along the tube; ``Renderer.polygons`` with ``order`` colours
    the faces per segment (both colours present for a half-and-half filament)."""
    from flagwrap.plotting.render import (CAMERAS, POLYMORPH_B_RGB, TUBE_RGB, Renderer, Scene,
                                          polymorph_rgb)

    n = 11
    a = polymorph_rgb(-np.ones(n), 30, 4)
    b = polymorph_rgb(np.ones(n), 30, 4)
    assert np.allclose(a, TUBE_RGB) and np.allclose(b, POLYMORPH_B_RGB) and a.shape == (120, 3)
    ramp = polymorph_rgb(np.linspace(-1, 1, n), 30, 1)
    w = (ramp - TUBE_RGB) @ (POLYMORPH_B_RGB - TUBE_RGB) / np.sum((POLYMORPH_B_RGB - TUBE_RGB) ** 2)
    assert np.all(np.diff(w) > 0) and w[0] < 0.05 and w[-1] > 0.95
    x = np.column_stack([np.zeros(n), np.zeros(n), -np.linspace(0, 1, n)])
    x[:, 0] = 0.05 * np.sin(np.linspace(0, 6, n))
    rend = Renderer(Scene(tube_radius=0.01, body_radius=0.0, body_length=0.0, length=1.0))
    order = np.where(np.arange(n) < n // 2, 1.0, -1.0)
    _, rgba = rend.polygons(x, CAMERAS[0], order=order)
    plain = rend.polygons(x, CAMERAS[0])[1]
    hue = rgba[:, 0] - rgba[:, 2]  # orange: red > blue; blue: blue > red
    assert (hue > 0).any() and (hue < 0).any()
    assert ((plain[:, 0] - plain[:, 2]) < 0).all()


def test_movie_and_snapshots_of_a_polymorph_run(tmp_path):
    """A polymorph run's movie frames and snapshot strip render with the tube coloured by
    form: with B over the first half of the filament, the frame has orange pixels, which the
    same run drawn without the order (one colour) has not."""
    from flagwrap.io.runfile import read_run, write_run
    from flagwrap.plotting.movies import MovieFrames
    from flagwrap.plotting.snapshots import write_snapshots
    from flagwrap.simulation import simulate

    tr = simulate(_cfg(POLY + "initial = 'wall'\n", ccw=0.05, cw=0.1))
    ds = read_run(write_run(tr, tmp_path / "r.nc"))
    n = ds.sizes["bead"]
    ds["polymorph_order"].values[:] = np.where(np.arange(n) < n // 2, 1.0, -1.0)
    frames = MovieFrames(ds, fps=10, size=(320, 192))
    assert frames.order is not None
    img = frames.render(0).astype(int)
    frames.order = None
    plain = frames.render(0).astype(int)

    def orange(im):
        r, g, b = im[..., 0], im[..., 1], im[..., 2]
        return int(np.sum((r > b + 60) & (r > 120) & (g < r)))

    assert orange(img) > 10 and orange(img) > 5 * orange(plain)
    paths = write_snapshots(ds, tmp_path / "s.png", formats=("png",), dpi=60, n=2)
    assert paths and all(p.stat().st_size > 0 for p in paths)


def test_vtk_export_uses_each_frames_polymorph_rest(tmp_path):
    """ParaView export of a polymorph run: the rebuilt elastic energy at each frame's order
    parameters equals the simulator's stored one (the oracle of tests/unit/test_vtk.py), which
    A's fixed rest does not; each frame's .vtp carries ``polymorph_order``."""
    import xml.etree.ElementTree as ET

    from flagwrap.io.runfile import config_of, read_run, write_run
    from flagwrap.io.vtk import ElasticForces, export_vtk
    from flagwrap.simulation import simulate

    ds = read_run(write_run(simulate(_cfg(POLY + "initial = 'wall'\n", ccw=0.1, cw=0.2)),
                            tmp_path / "r.nc"))
    ef = ElasticForces(config_of(ds))
    X, M, O = ds["position"].values, ds["director"].values, ds["polymorph_order"].values
    stored = ds["elastic_energy"].values
    E = []
    for x, m, o in zip(X, M, O):
        ef.set_order(o)
        E.append(ef(x, m)[0])
    np.testing.assert_allclose(E, stored, rtol=1e-8, atol=1e-12 * stored.max())
    ef.set_order(-np.ones(O.shape[1]))  # A's rest: not the run's energy
    assert abs(ef(X[-1], M[-1])[0] - stored[-1]) > 1e-3 * stored[-1]
    pvd = export_vtk(ds, tmp_path / "vtk", stride=5)
    vtp = sorted(pvd.parent.glob("filament_*.vtp"))[-1]
    names = [a.get("Name") for a in ET.parse(vtp).getroot().iter("DataArray")]
    assert "polymorph_order" in names and "elastic_force" in names


@pytest.mark.parametrize("direction, switches", [("cw", True), ("ccw", False)])
def test_ecoli_cw_torque_switches_normal_to_semicoiled_from_the_motor(direction, switches):
    """The E. coli case (31 beads, a speed motor at 500 Hz for 3 turns): CW turns the
    filament semicoiled, starting at the motor's end (the first B vertex in the filament's
    first third), CCW never does (docs/polymorph.md, "The model's switching torque":
    the switch lies between 350 and 400 Hz CW at this resolution)."""
    import dataclasses

    from flagwrap.cases import get_case
    from flagwrap.params import Phase
    from flagwrap.simulation import Simulation

    base = get_case("ecoli_polymorph")
    cfg = base.replace(
        filament=dataclasses.replace(base.filament, n_beads=31, pitch_angle_deg=None, turns=None),
        motor=dataclasses.replace(base.motor, kind="speed", frequency=500.0, machin=None,
                                  stall_torque=None, zero_load_speed=None,
                                  protocol=(Phase(direction, 3.0),)))
    sim = Simulation(cfg)
    tr = sim.run()
    assert tr.ok, tr.message
    o = np.asarray(tr.order)[:, sim.system.order_changes]
    inb = o > 0.0
    assert inb.any() == switches
    if switches:
        k = np.flatnonzero(inb.any(axis=1))[0]
        first = np.flatnonzero(inb[k])
        assert first.min() < o.shape[1] / 3
        assert 0.1 < inb[-1].mean() < 0.9  # a front that stops: B at the motor, A beyond


def test_a_library_transition_gives_the_landscape_with_hotanis_thresholds():
    """``transition = 'salmonella_normal_semicoiled'`` (Hotani's loop, a stand-in on the E.
    coli forms) with a 0.5 um wall: the model's spinodal torques (P6) are the library's two
    torques with the rod's sign, +1.1 and -0.4 pN um, to round-off, its wall is 0.5 um, and
    its Delta is the rod's own (within 2 % of the continuum torsions' 4.594 /um)."""
    import dataclasses

    from flagwrap.cases import get_case
    from flagwrap.simulation import make_system

    base = get_case("ecoli_polymorph")
    pm = dataclasses.replace(base.polymorph, barrier=None, stiffness=None, maxwell_torque=0.0,
                             transition="salmonella_normal_semicoiled", domain_wall_width=0.5e-6)
    s = make_system(base.replace(polymorph=pm))
    sc = base.scales
    up, down = (v * sc.torque for v in s.model.switch_torques)
    assert up == pytest.approx(1.1e-18, rel=1e-12) and down == pytest.approx(-0.4e-18, rel=1e-12)
    assert s.model.wall_width * sc.length == pytest.approx(0.5e-6, rel=1e-12)
    assert s.model.delta_twist / sc.length * 1e-6 == pytest.approx(4.594, rel=0.02)


def test_transition_without_a_wall_width_or_of_other_forms_is_refused():
    no_wall = ("[polymorph]\nenabled = true\ntransition = 'salmonella_normal_semicoiled'\n")
    with pytest.raises(UserInputError, match="polymorph.domain_wall_width is required"):
        _cfg(no_wall)
    with pytest.raises(UserInputError, match="normal and curly I"):
        _cfg(no_wall + "domain_wall_width = 0.05\npolymorph_b = 'ecoli_curly1'\n")
    with pytest.raises(UserInputError, match="polymorph.domain_wall_width"):  # < the 0.02 m bond
        _cfg(no_wall + "domain_wall_width = 0.01\n")
    cfg = _cfg(no_wall + "domain_wall_width = 0.05\n")
    assert cfg.polymorph.wall_width() == 0.05


def test_two_flagella_analysis_and_vtk_read_each_filaments_order(tmp_path, capsys):
    """Two polymorphic flagella on a free cell: ``analyze`` prints one polymorph line per
    flagellum; the ParaView export's rebuilt elastic energy, summed over the two filaments
    at each frame's order, is the simulator's stored one (1e-8)."""
    from flagwrap.cli.main import main
    from flagwrap.io.runfile import config_of, filament_slices, read_run, write_run
    from flagwrap.io.vtk import ElasticForces
    from flagwrap.simulation import simulate

    cfg = _kind_cfg("two flagella on a free cell", POLY + "initial = 'wall'\n", ccw=0.1, cw=0.2)
    path = write_run(simulate(cfg), tmp_path / "two.nc")
    assert main(["analyze", str(path), "--no-store"]) == 0
    out = capsys.readouterr().out
    assert "flagellum 0: polymorph" in out and "flagellum 1: polymorph" in out
    ds = read_run(path)
    ef = ElasticForces(config_of(ds))
    sls = filament_slices(ds)
    E = []
    for x, m, o in zip(ds["position"].values, ds["director"].values,
                       ds["polymorph_order"].values):
        ef.set_order(o)
        E.append(sum(ef(x[sl], m[slice(sl.start - k, sl.stop - k - 1)], k)[0]
                     for k, sl in enumerate(sls)))
    stored = ds["elastic_energy"].values
    np.testing.assert_allclose(E, stored, rtol=1e-8, atol=1e-12 * stored.max())


def test_b_in_the_initial_state_is_not_called_a_transformation(tmp_path):
    """``initial = 'wall'``: the first frame already holds B, which the summary reports as
    present from the start (no start position), not as a transformation at turn 0."""
    from flagwrap.io.runfile import read_run, write_run
    from flagwrap.observables.polymorph import polymorph_summary
    from flagwrap.simulation import simulate

    ds = read_run(write_run(simulate(_cfg(POLY + "initial = 'wall'\n", ccw=0.05, cw=0.05)),
                            tmp_path / "w.nc"))
    res = polymorph_summary(ds)
    assert res["starts_at"] == "present at the start" and res["start_position_m"] is None
    assert 0.3 < res["fraction_b_final"] < 0.7


def test_filament_of_the_other_hand_and_an_absurd_rate_are_refused():
    """The configured filament is polymorph A: a right-handed filament named ecoli_normal
    (left-handed) is refused naming both keys; a rate above 1e6 times the default is
    refused naming polymorph.rate (at the system's build, before any step)."""
    from flagwrap.simulation import make_system

    with pytest.raises(UserInputError, match="filament.handedness.*polymorph.polymorph_a"):
        config_from_dict(tomllib.loads(
            tiny_toml().replace("turns = 2\n", "turns = 2\nhandedness = 'right'\n") + POLY))
    with pytest.raises(UserInputError, match="polymorph.rate must be in"):
        make_system(_cfg(POLY + "rate = 1e300\n"))
    with pytest.raises(UserInputError, match="polymorph.domain_wall_width"):
        _cfg("[polymorph]\nenabled = true\ntransition = 'salmonella_normal_semicoiled'\n"
             "domain_wall_width = 0.001\n")


def test_turning_frame_and_lab_frame_agree_with_the_order_block():
    """The same polymorph run (a wall relaxing and moving under 0.5 CCW + 0.5 CW turns) in the
    lab and in the turning frame, both at tol 1e-7: the order parameters (which change by
    0.58) agree to 2e-4 and the beads to 1e-4 L; measured 2.1e-5 and 5.7e-6 L, the bounds
    10x that (two integrations of the same equations, each to its tolerance)."""
    import dataclasses

    from flagwrap.simulation import simulate

    runs = {}
    for kind in ("lab", "turning frame"):
        cfg = _kind_cfg(kind, POLY + "initial = 'wall'\n", ccw=0.5, cw=0.5)
        runs[kind] = simulate(cfg.replace(numerics=dataclasses.replace(cfg.numerics, tol=1e-7)))
    a, b = runs["lab"], runs["turning frame"]
    assert a.ok and b.ok
    oa, ob = np.asarray(a.order), np.asarray(b.order)
    assert np.abs(oa[-1] - oa[0]).max() > 0.3
    assert np.abs(oa[-1] - ob[-1]).max() < 2e-4
    assert np.abs(np.asarray(a.x)[-1] - np.asarray(b.x)[-1]).max() < 1e-4



# the kinds of system linear stability takes with the order block: the rig with a held cell,
# and a free-swimming no-slip cell (the swimmer's turning frame)
STABILITY_BODIES = {"held cell": "[body]\nenabled = true\n",
                    "free cell": "[body]\nsurface = 'no-slip'\nmotion = 'free'\n"
                                 "blob_spacing = 0.025\n"}


def _tiny_stability_cfg(extra="", body="held cell"):
    return _cfg(STABILITY_BODIES[body] + POLY + extra)


@pytest.mark.parametrize("body", list(STABILITY_BODIES))
def test_one_state_filament_has_the_fixed_rods_threshold(body):
    """Linear stability with the order block: a one-state filament's order modes decouple
    (no rest shape to move), so its M_c is the fixed rod's, bisection bracket for bracket, on
    the rig and on a free cell; a two-state (normal -> semicoiled) filament has another
    (measured 1351.8 vs 1323.8 held, 1373.4 vs 1318.1 free)."""
    from flagwrap.stability.threshold import critical_from_config

    plain = critical_from_config(_cfg(STABILITY_BODIES[body]), "cw", m_start=400.0)
    one = critical_from_config(_tiny_stability_cfg("polymorph_b = 'ecoli_normal'\n", body),
                               "cw", m_start=400.0)
    two = critical_from_config(_tiny_stability_cfg(body=body), "cw", m_start=400.0)
    # the same bisection steps; M_c interpolated inside the bracket from eigenvalues whose
    # finite-difference noise is ~1e-10 (measured 4e-10 and 6e-10 apart)
    assert one.bracket == plain.bracket
    assert one.machin_c == pytest.approx(plain.machin_c, rel=1e-8)
    assert one.crossing == plain.crossing
    assert abs(two.machin_c / plain.machin_c - 1.0) > 0.005


@pytest.mark.parametrize("body", list(STABILITY_BODIES))
def test_polymorph_frame_jacobian_is_the_derivative_of_its_velocity(body):
    """``PolymorphFrame.jacobian`` (the rod's block plus the order's cross blocks) against
    central differences of ``velocity`` over every unknown, at a steady whirl of the
    two-state filament on the rig and on a free cell (the swimmer's dense mobility in the
    cross block): each block to 1e-7 of its largest entry (measured 1.5e-10 to 3e-10;
    central differences with step 1e-6 carry ~1e-10 relative error)."""
    from flagwrap.stability.steady import start_state
    from flagwrap.stability.threshold import make_frame

    fr = make_frame(_tiny_stability_cfg(body=body), -1.0)
    st = start_state(fr, 1000.0)
    assert st.converged
    J = fr.jacobian(st.z, st.base, st.machin, st.info)
    h = 1e-6
    Jfd = np.empty_like(J)
    for k in range(fr.n):
        zp, zm = st.z.copy(), st.z.copy()
        zp[k] += h
        zm[k] -= h
        Jfd[:, k] = (fr.velocity(zp, st.base, st.machin)[0]
                     - fr.velocity(zm, st.base, st.machin)[0]) / (2 * h)
    nr = fr.n_rod
    for r, c in ((slice(0, nr), slice(0, nr)), (slice(0, nr), slice(nr, None)),
                 (slice(nr, None), slice(0, nr)), (slice(nr, None), slice(nr, None))):
        scale = np.abs(Jfd[r, c]).max()
        assert scale > 0
        assert np.abs(J[r, c] - Jfd[r, c]).max() < 1e-7 * scale


@pytest.mark.parametrize("body", list(STABILITY_BODIES))
def test_stability_starts_from_the_relaxed_order(body):
    """With tilted wells (``maxwell_torque``) the configured state is not at rest: the frame's
    ``initial_state`` relaxes it first. At rest the rod is stress-free for any uniform phi,
    so phi is the tilted well's root, ``W (phi^3 - phi) = h`` with ``h = -N_M Delta / 2``
    (P2), to 1e-6; Newton then converges from it at a low M."""
    from scipy.optimize import brentq

    from flagwrap.stability.steady import newton
    from flagwrap.stability.threshold import make_frame

    fr = make_frame(_tiny_stability_cfg("maxwell_torque = 1e-5\n", body), -1.0)
    z, base = fr.initial_state()
    m = fr.system.model
    h = m.tilt(0.0)
    assert abs(h) > 0.01 * m.barrier  # a real tilt
    root = brentq(lambda p: m.barrier * (p**3 - p) - h, -1.6, -0.58)
    phi = z[fr.n_rod:]
    assert np.abs(phi - root).max() < 1e-6 and abs(root + 1.0) > 1e-3
    st = newton(fr, 50.0, z, base)
    assert st.converged


@pytest.mark.slow
def test_far_diagram_of_a_one_state_filament_is_the_fixed_rods():
    """``flagwrap stability --far`` with the order block: a one-state filament's diagram is
    the fixed rod's (the same Hopf to 1e-8, the same far states to 1e-6 in M and tip, lost
    below the same M), the order modes being decoupled; two forms answer too, with stable
    far states (43 s and 23 s here)."""
    from flagwrap.stability.bifurcation import bifurcation_diagram

    kw = dict(cycles=(), m_hi=1500.0, settle=10.0)
    plain = bifurcation_diagram(_cfg(), **kw)
    one = bifurcation_diagram(_cfg(POLY + "polymorph_b = 'ecoli_normal'\n"), **kw)
    assert one.machin_hopf == pytest.approx(plain.machin_hopf, rel=1e-8)
    assert len(one.far) == len(plain.far) > 0
    for a, b in zip(one.far, plain.far):
        assert a.machin == pytest.approx(b.machin, rel=1e-6)
        assert a.tip_z == pytest.approx(b.tip_z, abs=1e-6)
    assert one.far_lost_below == pytest.approx(plain.far_lost_below, rel=1e-6)
    two = bifurcation_diagram(_cfg(POLY), **kw)
    assert two.far and all(p.leading.real < 0 for p in two.far)
