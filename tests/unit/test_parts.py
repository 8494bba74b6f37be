"""A system of several filaments (flagwrap.system.parts): each on its own motor and anchor,
one mobility over all beads. Oracles: the single filament (far apart, HI off), the RPY far
field (HI on), the symmetry of a symmetric tuft, the sum of the motors' torques."""

import dataclasses
import math

import numpy as np
import pytest

from flagwrap.simulation import Simulation
from flagwrap.system.parts import Placement, cap_placement
from flagwrap.system.rod_system import RodSystem, SeveralFilaments
from conftest import make_config, paper_filament, tiny_toml


def _cfg(hi=False, body=False, n_beads=21, protocol=(("ccw", 0.3), ("cw", 0.2)), **kw):
    cfg = make_config(machin=283.0, protocol=protocol, hi=hi,
                      filament=paper_filament(n_beads=n_beads), **kw)
    cfg = cfg.replace(body=dataclasses.replace(cfg.body, enabled=body),
                      initial=dataclasses.replace(cfg.initial, perturbation=0.004, seed=3))
    return cfg


def _run(cfg, placements=None):
    system = RodSystem(cfg, placements=placements)
    return system, Simulation(cfg, system=system).run()


def test_one_placement_at_the_origin_is_the_single_filament():
    cfg = _cfg()
    a = RodSystem(cfg)
    b = RodSystem(cfg, placements=[Placement()])
    y = a.initial_y()
    assert np.array_equal(y, b.initial_y()) and a.layout.size == b.layout.size
    assert np.array_equal(a.forces(y, a.frames0).G, b.forces(y, b.frames0).G)


def test_two_filaments_far_apart_without_hi_are_each_the_single_filament():
    # HI off: nothing couples them but the layout, the shared step sizes and the banded LU
    # of the whole system; their trajectories are the single run's to rounding (1e-12 L).
    # Unperturbed (filament k would take seed + k: two different filaments)
    cfg = _cfg(hi=False)
    cfg = cfg.replace(initial=dataclasses.replace(cfg.initial, perturbation=0.0))
    _, one = _run(cfg)
    d = np.array([3.0, 0.0, 0.0])  # 3 L apart, beyond any contact
    s, two = _run(cfg, [Placement(), Placement(origin=tuple(d))])
    assert one.ok and two.ok and len(one.t) == len(two.t)
    x1, x2 = np.asarray(one.x), np.asarray(two.x)
    N = s.parts[0].N
    np.testing.assert_allclose(x2[:, :N], x1, atol=1e-12, rtol=0)
    np.testing.assert_allclose(x2[:, N:] - d, x1, atol=1e-12, rtol=0)
    # the recorded torque is the two motors' sum
    np.testing.assert_allclose(np.asarray(two.motor_torque), 2 * np.asarray(one.motor_torque),
                               rtol=1e-9)


def test_a_run_of_placements_from_python_writes_its_filaments(tmp_path):
    # no [[flagellum]] tables: the run file's layout comes from the system's parts, so that
    # the analysis sees two flagella, not one chain from the first anchor to the last tip
    from flagwrap.analysis.runfile_attrs import analyze_run_file
    from flagwrap.io.runfile import filament_slices, read_run, write_run

    cfg = _cfg(body=True, protocol=(("ccw", 0.3), ("cw", 0.3)))
    s, tr = _run(cfg, _tuft(cfg, 2))
    assert tr.ok and not cfg.flagella
    path = write_run(tr, tmp_path / "two.nc")
    ds = read_run(path)
    N = s.parts[0].N
    assert filament_slices(ds) == [slice(0, N), slice(N, 2 * N)]
    np.testing.assert_array_equal(ds["tip_position"].values, ds["position"].values[:, N - 1])
    res = analyze_run_file(path, write=False)
    assert len(res["filaments"]) == 2


def test_hi_between_two_filaments_is_the_rpy_far_field():
    # the second filament's beads move the first one's through the RPY tensor. Far away that
    # is a multipole series in 1/d: the Stokeslet of the second filament's net force F (the
    # clamp's reaction, non-zero off the rest shape), dv = (I + e e) F / (8 pi M d) for every
    # bead of the first, then its force dipole, ~1/d^2. So |dv| falls with slope -1 and
    # |dv - Stokeslet| with slope -2 (fits over d = 250..1000 L; the next orders move the
    # slopes by O(l/d) with l ~ 30 L the dipole's length: 0.05)
    cfg = _cfg(hi=True)
    single = RodSystem(cfg)
    y1 = single.initial_y()
    v1 = single.velocity(y1, single.forces(y1, single.frames0), 1.0)[single.sl_x]
    ds = np.array([250.0, 500.0, 1000.0])
    dev, rest = [], []
    for d in ds:
        s = RodSystem(cfg, placements=[Placement(), Placement(origin=(d, 0.0, 0.0))])
        y = s.initial_y()
        info = s.forces(y, s.frames0)
        v = s.velocity(y, info, 1.0)[s.sl_x]
        n = v1.size
        dv = (v[:n] - v1).reshape(-1, 3)
        F = info.G[s.sl_x][n:].reshape(-1, 3).sum(axis=0)
        e = np.array([1.0, 0.0, 0.0])
        stokeslet = (F + e * (e @ F)) / (8 * math.pi * cfg.machin * d)
        dev.append(np.linalg.norm(dv))
        rest.append(np.linalg.norm(dv - stokeslet))
    assert np.polyfit(np.log(ds), np.log(dev), 1)[0] == pytest.approx(-1.0, abs=0.05), dev
    assert np.polyfit(np.log(ds), np.log(rest), 1)[0] == pytest.approx(-2.0, abs=0.05), rest


def _tuft(cfg, n, polar_deg=35.0):
    Rc = cfg.body.resolved_radius(cfg.filament.helix_radius) / cfg.filament.length
    return [cap_placement(Rc, math.radians(polar_deg), 2 * math.pi * k / n) for k in range(n)]


def test_anchors_sit_on_the_cap_with_the_motor_axis_along_the_normal():
    cfg = _cfg(body=True)
    s = RodSystem(cfg, placements=_tuft(cfg, 3))
    body = s.body
    assert body.shape == "capped-cylinder" and body.fused
    for p in s.parts:
        # the anchor bead on the surface; the motor axis along the outward normal there
        assert abs(body.distance(p.x0[:1])[0]) < 1e-12
        n = p.joint.origin - np.array([0.0, 0.0, body.radius])
        np.testing.assert_allclose(p.joint.axis, n / np.linalg.norm(n), atol=1e-12)
        assert np.all(body.distance(p.x0[p.nc:]) > 0)


def test_a_symmetric_pair_on_the_body_keeps_its_symmetry():
    # two flagella at azimuths 0 and pi on the pole cap, HI on, transparent body: the whole
    # problem is invariant under the half turn about the body axis, so the run is too (the
    # perturbation is off: it would break the symmetry). Not to rounding: the coloured
    # Jacobian in W differences Cartesian components, so W is not rotation covariant and the
    # two halves differ at the steps' local error, which the controller holds to tol
    cfg = _cfg(hi=True, body=True, protocol=(("ccw", 0.5), ("cw", 0.5)))
    cfg = cfg.replace(initial=dataclasses.replace(cfg.initial, perturbation=0.0))
    s, tr = _run(cfg, _tuft(cfg, 2))
    assert tr.ok
    x = np.asarray(tr.x)
    N = s.parts[0].N
    half = np.diag([-1.0, -1.0, 1.0])
    np.testing.assert_allclose(x[:, N:], x[:, :N] @ half.T, atol=cfg.numerics.tol, rtol=0)
    assert np.abs(x[-1, N:] - x[0, N:]).max() > 1e-3  # and they moved


def test_single_filament_attributes_refuse_by_name_on_several():
    cfg = _cfg()
    s = RodSystem(cfg, placements=[Placement(), Placement(origin=(1.0, 0.0, 0.0))])
    for name in ("joint", "rest", "nc", "ec"):
        with pytest.raises(SeveralFilaments, match=f"RodSystem.{name}: this system has 2"):
            getattr(s, name)


def test_torque_motors_of_two_filaments_far_apart_each_turn_as_the_single_one():
    # each motor's angle is an unknown with its own torque balance: with HI off and 3 L
    # apart, each filament and its motor's rate are the single torque-speed run's to
    # rounding. The torque motors take the dense LU of W (the speed test's banded one): two
    # factorisations of different size differ by eps kappa(W) ~ 1e-16 x 1e4 per step, over
    # ~450 steps <= 1e-10 L, five orders below the step's error tolerance
    cfg = _cfg(hi=False)
    cfg = cfg.replace(initial=dataclasses.replace(cfg.initial, perturbation=0.0),
                      motor=dataclasses.replace(cfg.motor, kind="torque-speed",
                                                stall_torque=2e-4, zero_load_speed=0.02))
    one_sys, one = _run(cfg)
    s, two = _run(cfg, [Placement(), Placement(origin=(3.0, 0.0, 0.0))])
    assert s.layout.block("phi").size == 2 and s.layout.block("phi").kind == "angle"
    assert one.ok and two.ok and len(one.t) == len(two.t)
    N = s.parts[0].N
    x1, x2 = np.asarray(one.x), np.asarray(two.x)
    np.testing.assert_allclose(x2[:, :N], x1, atol=1e-10, rtol=0)
    np.testing.assert_allclose(x2[:, N:] - [3.0, 0.0, 0.0], x1, atol=1e-10, rtol=0)
    np.testing.assert_allclose(two.omega, one.omega, rtol=1e-9)  # motor 0's own rate
    np.testing.assert_allclose(two.motor_torque, 2 * np.asarray(one.motor_torque), rtol=1e-9)
    assert abs(np.asarray(one.omega)[-1] - 1.0) > 1e-3  # it turns at its load, not at omega
    # each motor recorded: torques add up to the total, rates equal by symmetry
    m = np.asarray(two.motors)
    np.testing.assert_allclose(m[:, :2].sum(axis=1), two.motor_torque, rtol=1e-12)
    np.testing.assert_allclose(m[:, 2], two.omega, rtol=0)
    np.testing.assert_allclose(m[:, 3], m[:, 2], rtol=1e-9)


def test_placement_turns_the_default_axis_onto_the_given_one():
    rng = np.random.default_rng(7)
    for _ in range(5):
        a = rng.standard_normal(3)
        p = Placement.from_axis((0.1, 0.2, 0.3), a, spin=rng.uniform(0, 6))
        np.testing.assert_allclose(p.axis, a / np.linalg.norm(a), atol=1e-13)
        np.testing.assert_allclose(p.R @ p.R.T, np.eye(3), atol=1e-13)
        assert np.linalg.det(p.R) == pytest.approx(1.0)
    with pytest.raises(ValueError, match="motor axis"):
        Placement.from_axis((0, 0, 0), (0, 0, 0))


# ---- the config's [[flagellum]] tables -------------------------------------------------------

TWO = tiny_toml(ccw=0.2, cw=0.1, machin=283)


def with_tables(tables: str) -> str:
    """:data:`TWO` and ``tables``; ``[numerics]`` lines in ``tables`` go into TWO's table
    (TOML defines a table once)."""
    if "[numerics]\n" not in tables:
        return TWO + tables
    head, rest = tables.split("[numerics]\n", 1)
    lines = rest.split("\n")
    k = next((i for i, ln in enumerate(lines) if ln.startswith("[")), len(lines))
    return TWO.replace("[numerics]\n", "[numerics]\n" + "\n".join(lines[:k]) + "\n") + head + \
        "\n".join(lines[k:])


def _load(text):
    import tomllib

    from flagwrap.io.config import config_from_dict

    return config_from_dict(tomllib.loads(text))


def test_tables_place_the_flagella_and_read_back():
    from flagwrap.io.config import config_to_toml

    cfg = _load(TWO + "[[flagellum]]\npolar_deg = 35\n[[flagellum]]\npolar_deg = 35\n"
                "azimuth_deg = 180\n")
    s = RodSystem(cfg)
    assert s.n_filaments == 2
    ref = RodSystem(cfg, placements=_tuft(cfg, 2))
    assert np.array_equal(s.x0, ref.x0)
    assert _load(config_to_toml(cfg)) == cfg


def test_one_table_at_the_pole_is_the_config_without_tables():
    from flagwrap.simulation import simulate

    a = simulate(_load(TWO))
    b = simulate(_load(TWO + "[[flagellum]]\npolar_deg = 0\n"))
    assert a.ok and b.ok
    for k in ("t", "x", "theta", "motor_torque"):
        assert np.array_equal(np.asarray(getattr(a, k)), np.asarray(getattr(b, k))), k


def test_free_cell_with_three_flagella_exerts_no_force_or_torque_on_the_fluid(rng):
    # blob forces + bead forces + bond torques on the fluid sum to zero (the cell is force-
    # and torque-free), for an asymmetric tuft; round-off of sums of O(|F|) terms
    from flagwrap.simulation import make_system

    cfg = _load(TWO + "[body]\nsurface = 'no-slip'\nmotion = 'free'\nblob_spacing = 0.025\n"
                + "".join(f"[[flagellum]]\npolar_deg = 30\nazimuth_deg = {az}\n"
                          for az in (0, 100, 230)))
    s = make_system(cfg)
    assert s.n_filaments == 3
    y = s.initial_y()
    y[s.sl_x] += 0.01 * s.bond * rng.standard_normal(s.sl_x.stop - s.sl_x.start)
    y[s.sl_th] += 0.1 * rng.standard_normal(s.sl_th.stop - s.sl_th.start)
    from conftest import fluid_force_and_torque

    force, torque, f_scale, t_scale = fluid_force_and_torque(s, y)
    assert np.abs(force).max() < 1e-10 * f_scale
    assert np.abs(torque).max() < 1e-10 * t_scale
    V = s.body_velocity(y, s.forces(y, s.frames0).G)[0]
    assert np.abs(V).max() > 0


@pytest.mark.parametrize("tables, match", [
    ("flagellum = []\n", "zero flagella"),
    ("[[flagellum]]\nazimuth_deg = 10\nspin = 1\n", r"unknown key flagellum\[0\].spin"),
    ("[[flagellum]]\nanchor = [0.0, 0.0, 0.0]\n", r"flagellum\[0\].axis is missing"),
    ("[[flagellum]]\npolar_deg = 95\n", r"flagellum\[0\].polar_deg must be in \[0, 90\)"),
    ("[[flagellum]]\nanchor = [0.01, 0.0, 0.0]\naxis = [0, 0, -1]\n",
     r"flagellum\[0\].anchor = .* from the body surface"),
    ("[[flagellum]]\nanchor = [0.0, 0.0, 0.0]\naxis = [0, 0, 1]\n",
     r"flagellum\[0\].axis = .* points into the body"),
    ("[[flagellum]]\npolar_deg = 20\n[[flagellum]]\npolar_deg = 20\nazimuth_deg = 1\n",
     r"flagellum\[1\] and flagellum\[0\] are anchored"),
    # copies of one shape not turned with their azimuth (spin 0): the helices meet
    ("[[flagellum]]\npolar_deg = 10\nspin_deg = 0\n[[flagellum]]\npolar_deg = 10\n"
     "azimuth_deg = 30\nspin_deg = 0\n", r"flagellum\[1\] and flagellum\[0\] cross at the start"),
    ("[body]\nshape = 'spheroid'\n[[flagellum]]\npolar_deg = 10\n",
     r"flagellum\[0\].polar_deg places the flagellum on a spherical pole cap"),
    ("[numerics]\nframe = 'rotating'\n[[flagellum]]\npolar_deg = 35\n[[flagellum]]\n"
     "polar_deg = 35\nazimuth_deg = 180\n", "numerics.frame = 'rotating' needs one flagellum"),
])
def test_bad_flagellum_tables_are_one_line_exit_2(tmp_path, capsys, tables, match):
    import re

    from flagwrap.cli.main import main

    p = tmp_path / "bad.toml"
    # a top-level key must come before the tables
    p.write_text(tables + TWO if tables.startswith("flagellum =") else with_tables(tables))
    out = tmp_path / "out.nc"
    assert main(["run", str(p), "-o", str(out), "--quiet"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and re.search(match, err), err
    assert not out.exists()


def test_stability_refuses_several_flagella_by_name(tmp_path, capsys):
    from flagwrap.cli.main import main

    p = tmp_path / "two.toml"
    p.write_text(TWO + "[[flagellum]]\npolar_deg = 35\n[[flagellum]]\npolar_deg = 35\n"
                 "azimuth_deg = 180\n")
    assert main(["stability", str(p)]) == 2
    err = capsys.readouterr().err.strip()
    assert "turning frame" in err and "needs one flagellum" in err and len(err.splitlines()) == 1


def test_turning_frame_refuses_one_flagellum_off_the_body_axis(tmp_path, capsys):
    # no body: an anchor anywhere, its motor axis along -z but 5 cm beside the body axis
    from flagwrap.cli.main import main

    p = tmp_path / "off.toml"
    p.write_text(with_tables("[body]\nenabled = false\n[numerics]\nframe = 'rotating'\n"
                             "[[flagellum]]\nanchor = [0.05, 0.0, 0.0]\naxis = [0, 0, -1]\n"))
    assert main(["run", str(p), "-o", str(tmp_path / "o.nc"), "--quiet"]) == 2
    err = capsys.readouterr().err.strip()
    assert "needs the motor on the body axis" in err and len(err.splitlines()) == 1
    assert "0.05 m off it" in err


def test_resource_estimate_counts_every_flagellum():
    # oracle: the system it estimates (unknowns); memory and step time grow with them
    from flagwrap.resources import estimate, step_seconds

    one = _load(TWO)
    three = _load(TWO + "".join(f"[[flagellum]]\npolar_deg = 35\nazimuth_deg = {az}\n"
                                for az in (0, 120, 240)))
    assert estimate(three).unknowns == RodSystem(three).ny == 3 * RodSystem(one).ny
    assert estimate(three).frame_bytes == 3 * estimate(one).frame_bytes
    assert step_seconds(three) == pytest.approx(9 * step_seconds(one))
