"""Buoyancy: the gravity number G, the density mismatch as input, its sweep axis, and the
force the model applies (flagwrap.units.gravity_number, params.Config, model.RodSystem)."""

import math
import subprocess
import sys

import numpy as np
import pytest

from flagwrap.errors import UserInputError
from flagwrap.io.config import config_from_dict
from flagwrap.system.rod_system import RodSystem
from flagwrap.units import G_ACCEL, gravity_number

from conftest import make_config


def _dict(**fil):
    d = make_config(machin=283.0).to_dict()
    d["filament"].update(fil)
    return d


def test_gravity_number_by_hand():
    # G = (rho_f - rho) g pi a^2 L^3 / A; A = pi E a^4 / 4 (the Fig. 4(a) material)
    A = math.pi * 1.5e6 * 1.5e-3**4 / 4
    by_hand = 25.0 * 9.80665 * math.pi * 1.5e-3**2 * 0.4**3 / A
    assert gravity_number(25.0, 1.5e-3, 0.4, A) == pytest.approx(by_hand, rel=1e-14)
    cfg = config_from_dict(_dict(density=1225.0))
    assert cfg.gravity_number == pytest.approx(by_hand, rel=1e-12)  # 2 % lighter: buoyant, > 0
    assert cfg.density_mismatch == pytest.approx(-0.02)
    assert config_from_dict(_dict(density=1275.0)).gravity_number == pytest.approx(-by_hand)
    assert make_config(machin=283.0).gravity_number == 0.0  # density-matched


def test_mismatch_is_resolved_to_the_same_density():
    a = config_from_dict(_dict(density_mismatch=-0.03))
    b = config_from_dict(_dict(density=1250.0 * 0.97))
    assert a.filament.density == pytest.approx(b.filament.density, rel=1e-15)
    assert a.gravity_number == pytest.approx(b.gravity_number, rel=1e-12)
    assert a.filament.density_mismatch is None  # stored as a density, reloadable
    assert config_from_dict(a.to_dict()) == a


@pytest.mark.parametrize("fil,needle", [
    (dict(density_mismatch=-1.0), "filament.density_mismatch"),
    (dict(density_mismatch=-1.5), "filament.density_mismatch"),
    (dict(density_mismatch=float("nan")), "filament.density_mismatch"),
    (dict(density_mismatch=float("inf")), "filament.density_mismatch"),
    (dict(density_mismatch=True), "filament.density_mismatch"),
    (dict(density_mismatch=0.01, density=1200.0), "not both"),
    (dict(density=0.0), "filament.density"),
    (dict(density=-5.0), "filament.density"),
    (dict(density=float("nan")), "filament.density"),
])
def test_bad_density_is_named(fil, needle):
    with pytest.raises(UserInputError, match=needle):
        config_from_dict(_dict(**fil))


def test_bad_mismatch_on_the_command_line_exits_2(tmp_path):
    from flagwrap.io.config import config_to_toml

    cfg = make_config(machin=283.0)
    text = config_to_toml(cfg).replace("[filament]\n", "[filament]\ndensity_mismatch = -1.2\n", 1)
    p = tmp_path / "bad.toml"
    p.write_text(text)
    out = tmp_path / "never.nc"
    r = subprocess.run([sys.executable, "-m", "flagwrap.cli.main", "run", str(p), "-o", str(out)],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 2
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and "filament.density_mismatch" in lines[0], r.stderr
    assert "Traceback" not in r.stderr and not out.exists()


def test_model_force_is_G_times_the_beads_contour():
    cfg = config_from_dict(_dict(density_mismatch=-0.02, n_beads=21))
    s = RodSystem(cfg)
    b = 1.0 / 20
    fz = s.gravity[:, 2]
    assert np.all(s.gravity[:, :2] == 0)
    assert fz[1:-1] == pytest.approx(cfg.gravity_number * b, rel=1e-14)
    assert fz[[0, -1]] == pytest.approx(cfg.gravity_number * b / 2, rel=1e-14)
    # the total buoyant force is q L in SI: G A / L^2
    fil = cfg.filament
    q = (cfg.fluid.density - fil.density) * G_ACCEL * math.pi * fil.cross_section_radius**2
    assert fz.sum() * cfg.scales.force == pytest.approx(q * fil.length, rel=1e-12)


def test_sweep_axis_density_mismatch():
    from flagwrap.sweep.spec import spec_from_dict

    grid = {"turns": 2.0, "r_over_l": 0.075, "density_mismatch": [-0.03, 0.0, 0.02]}
    spec = spec_from_dict({"mode": "boundary", "grid": grid})
    geos = spec.geometries()
    assert len(geos) == 3  # the mismatch is part of a boundary search's geometry
    G = [c.gravity_number for c in geos]
    assert G[0] == pytest.approx(-929.8 * -0.03, rel=1e-3) and G[1] == 0.0 and G[2] < 0
    assert geos[0].config().filament.density == pytest.approx(1250 * 0.97)
    assert geos[0].to_dict()["density_mismatch"] == -0.03
    # density-matched sweeps keep their keys (no mismatch key in the geometry or the config)
    plain = spec_from_dict({"mode": "boundary", "grid": {"turns": 2.0, "r_over_l": 0.075}})
    assert "density_mismatch" not in plain.cases[0].geometry()
    assert plain.cases[0].config().filament.density is None
    assert len({c.key for c in spec.cases} | {plain.cases[0].key}) == 4


@pytest.mark.parametrize("grid,base,needle", [
    ({"density_mismatch": -1.0}, {}, "density_mismatch"),
    ({"density_mismatch": "x"}, {}, "density_mismatch"),
    ({"density_mismatch": -0.02}, {"filament": {"density": 1200.0}}, "filament.density"),
])
def test_sweep_axis_rejects(grid, base, needle):
    from flagwrap.sweep.spec import spec_from_dict

    data = {"mode": "grid", "grid": {"turns": 2.0, "r_over_l": 0.075, "machin": 300.0, **grid}}
    if base:
        data["base"] = base
    with pytest.raises(UserInputError, match=needle):
        spec_from_dict(data)


def _fake_sweeps(tmp_path):
    """A boundary store over the mismatch (Fig. 4(a) helix) and a Fig. 5 store whose rows
    follow M_c = c_k (R/L)^-3 with a known c_k per mismatch."""
    from flagwrap.sweep.store import SweepStore

    a = SweepStore(tmp_path / "g4a")
    for i, (dm, mc) in enumerate([(-0.04, None), (-0.02, 380.0), (0.0, 576.0), (0.02, 700.0)]):
        G = -929.8 * dm
        b = {"psi_deg": 70.47, "turns": 2.0, "r_over_l": 0.075, "density_mismatch": dm,
             "gravity_number": G, "status": "ok"}
        if mc is None:
            b.update(bracket=[None, 35.0], machin_c=None, converged=False)
        else:
            b.update(bracket=[mc / 1.02, mc * 1.02], machin_c=mc, converged=True)
        a.write_boundary(f"g{i}", b)
    f5 = SweepStore(tmp_path / "g5")
    truth = {-0.02: 0.1, 0.0: 0.3}
    for dm, c in truth.items():
        for rl in (0.03, 0.05, 0.08):
            mc = c * rl ** -3
            for q in (0.9, 1.1):
                f5.write_row({"key": f"{dm}-{rl}-{q}", "status": "ok", "psi_deg": 70.0, "turns": 2.0,
                              "r_over_l": rl, "r_over_rcell": 0.6, "hi": True, "n_beads": 31,
                              "ccw_turns": 5.0, "cw_turns": 10.0, "machin": q * mc, "buckled": q > 1,
                              "state": "folding" if q > 1 else "stable", "density_mismatch": dm,
                              "gravity_number": -929.8 * dm})
    return a.root, f5.root, truth


def test_gravity_figure_from_sweeps(tmp_path):
    import json

    from flagwrap.plotting.gravity import boundary_table, diagram_fits, gravity_figure

    g4a, g5, truth = _fake_sweeps(tmp_path)
    tab = boundary_table(g4a)
    assert [r["kind"] for r in tab] == ["upper", "bracket", "bracket", "bracket"]
    fits = diagram_fits(g5)
    assert [f["density_mismatch"] for f in fits] == [-0.02, 0.0]
    for f in fits:  # the rows of one mismatch are fitted alone
        assert f["fit"]["prefactor_beta3"] == pytest.approx(truth[f["density_mismatch"]], rel=0.02)
    paths = gravity_figure(tmp_path / "fig", g4a, g5, static_G=(0.0, 2.0))
    assert {p.rsplit(".", 1)[1] for p in paths} == {"png", "pdf", "json"}
    info = json.loads((tmp_path / "fig" / "gravity.json").read_text())
    assert info["static"]["tip_height"][0] == 0.0 and info["static"]["tip_height"][1] > 0  # floats up
    # flagwrap bacteria reads the density-matched fit back from it
    from flagwrap.cli.bacteria import load_model_boundary

    assert load_model_boundary(tmp_path / "fig" / "gravity.json")["prefactor_beta3"] == pytest.approx(0.3, rel=0.02)


def test_bacteria_model_boundary_errors(tmp_path):
    from flagwrap.cli.bacteria import load_model_boundary

    for text in ("not json", "{}", '{"fit": {"prefactor_beta3": -1}}'):
        p = tmp_path / "b.json"
        p.write_text(text)
        with pytest.raises(UserInputError, match="--model-boundary"):
            load_model_boundary(p)
    with pytest.raises(UserInputError, match="not found"):
        load_model_boundary(tmp_path / "none.json")


def test_static_equilibrium_is_where_the_time_loop_ends():
    # the Newton equilibrium (static_buckling) and the overdamped dynamics with the motor at rest
    # share only the force code: both must end in the same shape (HI off for speed; the end
    # state does not depend on the mobility). 20 turns at M = 1 are ~30 relaxation times of the
    # slowest mode (rate ~1 / turn), so the run is converged to << 1e-6 L; bound 1e-6 L.
    from flagwrap.analysis.static_buckling import static_branch, with_gravity_number
    from flagwrap.simulation import Simulation

    d = make_config(machin=1.0, hi=False).to_dict()
    d["filament"]["n_beads"] = 31
    d["motor"] = {"machin": 1.0, "protocol": [{"direction": "stop", "turns": 20.0}]}
    cfg = config_from_dict(d)
    br = static_branch(cfg, [0.0, 4.0, 8.0])
    assert np.all(np.diff(br.tip_height) > 0) and np.all(br.lowest_eigenvalue > 0)
    traj = Simulation(with_gravity_number(cfg, 8.0)).run()
    assert traj.ok, traj.message
    assert traj.arrays()["x"][-1, -1, 2] == pytest.approx(br.tip_z[-1], abs=1e-6)
