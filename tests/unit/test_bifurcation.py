"""The far branch and the bifurcation diagram (flagwrap.stability.bifurcation; docs/stability.md,
"Two thresholds")."""

import json
import math

import numpy as np
import pytest

from conftest import system_kinds, tiny_toml
from flagwrap.cli.main import main


@pytest.fixture(scope="module")
def tiny(tmp_path_factory):
    d = tmp_path_factory.mktemp("far")
    (d / "tiny.toml").write_text(tiny_toml())
    return d


@pytest.fixture(scope="module")
def tiny_diagram(tiny):
    from flagwrap.io.config import load_config
    from flagwrap.stability.bifurcation import bifurcation_diagram

    return bifurcation_diagram(load_config(tiny / "tiny.toml"), cycles=(1.05,), m_hi=1500.0,
                               settle=10.0)


def test_far_states_are_stable_fixed_points_away_from_the_whirl(tiny_diagram):
    d = tiny_diagram
    frame = d.hopf.frame
    assert d.hopf.converged and d.hopf.crossing == "hopf"
    assert len(d.far) >= 5
    whirl = d.hopf.state
    for p in d.far:
        st = p.state
        f, _ = frame.velocity(st.z, st.base, st.machin)
        # Newton's floor (rounding in the stiff bonds: module docstring of steady)
        assert np.max(np.abs(f)) < 1e-9
        assert p.leading.real < 0
        # a far state is not the whirl: the free end 0.2 L higher than the whirl's at M_c
        assert p.tip_z - whirl.info.x[-1, 2] > 0.1
    # relaxation found it lost below the lowest far state, not above it
    assert d.far_lost_below < min(p.machin for p in d.far)


def test_hopf_cycle_from_the_time_domain_grows_with_the_distance_from_the_hopf(tiny_diagram):
    (c,) = tiny_diagram.cycles
    assert not c.far and c.tip_min < c.tip_max
    # supercritical: a finite, small cycle just above the Hopf (0.03 L at 5 % here)
    assert 1e-3 < c.amplitude < 0.1


def test_cli_far_json_and_diagram(tiny, capsys):
    png = tiny / "d.png"
    code = main(["stability", str(tiny / "tiny.toml"), "--far", "--json", "--cycles", "none",
                 "--diagram", str(png), "--m-hi", "1500", "--settle", "10"])
    s = json.loads(capsys.readouterr().out)
    # the tiny helix's far branch ends at a contact event, not at a smooth fold: exit 1
    assert code == (0 if s["fold_found"] else 1)
    assert s["machin_hopf"] > 0 and s["far"] and s["files"] == [str(png)]
    assert png.stat().st_size > 10_000
    assert s["torque_hopf_reduced"] > 0 and s["cycles"] == []


@pytest.mark.parametrize("argv, says", [
    (["--far", "--mode", "m.png"], "--mode"),
    (["--far", "--m-lo", "500", "--m-hi", "400"], "--m-lo"),
    (["--far", "--settle", "0"], "--settle"),
    (["--far", "--cycles", "1.02,x"], "--cycles"),
    (["--far", "--cycles", "3"], "--cycles"),
    (["--m-far", "900"], "add --far"),
    (["--far-from", "missing.nc"], "run file not found"),
])
def test_bad_far_options_are_one_line_exit_2(tiny, capsys, argv, says):
    code = main(["stability", str(tiny / "tiny.toml"), *argv])
    err = capsys.readouterr().err.strip()
    assert code == 2 and says in err and "\n" not in err and "Traceback" not in err


def test_no_far_state_where_the_protocol_returns_to_the_whirl_is_exit_1(tiny, capsys):
    code = main(["stability", str(tiny / "tiny.toml"), "--far", "--m-far", "400",
                 "--no-progress", "--cycles", "none"])
    out = capsys.readouterr().out
    assert code == 1 and "NOT FOUND" in out and "ends on the whirl" in out


@pytest.fixture(scope="module")
def far_run(tiny):
    """A lab-frame run of the tiny helix that ends in the far state (M = 1420 > M_Hopf)."""
    d = tiny / "run"
    d.mkdir()
    (d / "far.toml").write_text(tiny_toml(ccw=0.2, cw=8, machin=1420))
    assert main(["run", str(d / "far.toml"), "-o", str(d / "far.nc"), "--quiet",
                 "--frame", "rotating"]) == 0
    (d / "other.toml").write_text(tiny_toml(ccw=0.2, cw=0.2, n_beads=25, machin=1420))
    assert main(["run", str(d / "other.toml"), "-o", str(d / "other.nc"), "--quiet"]) == 0
    return d


def test_far_from_a_run_file_starts_the_branch_there(tiny, far_run, capsys):
    capsys.readouterr()
    code = main(["stability", str(tiny / "tiny.toml"), "--far-from", str(far_run / "far.nc"),
                 "--json", "--cycles", "none", "--m-hi", "1500", "--settle", "10"])
    s = json.loads(capsys.readouterr().out)
    assert code in (0, 1) and "far.nc" in s["far_source"]
    # the same far branch as the protocol finds: the free end within 1e-6 L at the run's M
    m = [p for p in s["far"] if math.isclose(p["machin"], 1420, rel_tol=1e-9)]
    assert m and m[0]["leading_re"] < 0


@pytest.mark.parametrize("argv, says", [
    (["--far-from", "{d}/other.nc"], "another helix"),
    (["--far-from", "{d}/far.nc", "--m-hi", "1300"], "outside the diagram's range"),
])
def test_far_from_another_helix_or_range_is_exit_2(tiny, far_run, capsys, argv, says):
    argv = [a.format(d=far_run) for a in argv]
    code = main(["stability", str(tiny / "tiny.toml"), *argv, "--no-progress", "--cycles",
                 "none"])
    err = capsys.readouterr().err.strip()
    assert code == 2 and says in err and "\n" not in err


@pytest.mark.parametrize("kind", list(system_kinds()))
def test_every_kind_is_followed_or_refused_by_name(tiny, capsys, kind):
    numerics, tables = system_kinds()[kind]
    text = tiny_toml().replace("[numerics]\n", "[numerics]\n" + numerics) + tables
    path = tiny / f"kind_{kind.replace(' ', '_')}.toml"
    path.write_text(text)
    code = main(["stability", str(path), "--far", "--json", "--cycles", "none",
                 "--m-hi", "1450", "--m-lo", "1150", "--settle", "10"])
    out, err = capsys.readouterr()
    if "free cell" in kind:
        assert code == 2 and "free-swimming" in err and "\n" not in err.strip()
        return
    if "no-slip" in kind:
        assert code == 2 and "no-slip body" in err and "\n" not in err.strip()
        return
    assert code in (0, 1), err
    s = json.loads(out)
    assert s["machin_hopf"] > 0 and s["far"]


@pytest.mark.parametrize("extra", [
    # the lumped hook of examples/hook.toml scaled to this helix (k_h = 0.6)
    "[joint]\nkind = 'hook'\nhook_length = 0.004\nhook_bending_modulus = 3.58e-8\n",
    "",  # buoyancy: the filament 0.5 % heavier than the fluid (below)
], ids=["hook", "buoyancy"])
def test_hook_and_buoyancy_are_accepted_and_answered(tiny, capsys, extra):
    # the kinds the diagram takes besides the clamp: it runs and answers with what it found
    # (for this coarse helix neither has a far state at rest after the reversal: exit 1 with
    # the whirl's threshold and the reason), never a refusal or a traceback
    text = tiny_toml() + extra
    if not extra:
        text = text.replace("n_beads = 21", "n_beads = 21\ndensity_mismatch = 0.005")
    path = tiny / f"kind_{'hook' if extra else 'buoyant'}.toml"
    path.write_text(text)
    # --m-hi just above each one's whirl threshold (hook 307, buoyant 1210): one reversal tried
    m_hi = "340" if extra else "1300"
    code = main(["stability", str(path), "--far", "--json", "--cycles", "none", "--settle", "10",
                 "--m-hi", m_hi])
    out, err = capsys.readouterr()
    s = json.loads(out)
    assert code in (0, 1), err
    assert s["machin_hopf"] > 0 and s["hopf_crossing"] in ("hopf", "fold")
    if s["found"]:
        assert s["far"] and all(p["leading_re"] < 0 for p in s["far"])
    else:
        assert "does not end at rest" in s["message"] or "ends on the whirl" in s["message"]


@pytest.mark.slow
def test_fig4a_far_state_at_660_and_its_fold():
    """Acceptance: the Fig. 4(a) far state at M = 660 is a fixed point of the turning-frame
    equations (residual < 1e-10) and linearly stable; its branch ends in a fold where one
    real eigenvalue crosses zero, between the relaxation's last far state and its loss."""
    from flagwrap.cases import get_case
    from flagwrap.stability.bifurcation import bifurcation_diagram

    d = bifurcation_diagram(get_case("fig4a"), m_far=660.0, m_hi=700.0, cycles=(), factor=1.15)
    start = min(d.far, key=lambda p: abs(p.machin - 660.0))
    assert start.machin == pytest.approx(660.0)
    assert start.state.residual < 1e-10 and start.leading.real < 0
    assert d.fold_found
    before, after = d.fold_eigenvalues
    assert before < 0 < after
    # the fold lies where the time domain loses the far state, and below the whirl's Hopf
    assert d.far_lost_below < d.machin_fold < min(p.machin for p in d.far)
    assert d.machin_fold < d.machin_hopf


def test_sweep_far_adds_each_helix_fold(tiny, capsys):
    spec = tiny / "swf.toml"
    spec.write_text('name = "swf"\nmode = "grid"\n[grid]\npsi_deg = [70.0]\nturns = [2.0]\n'
                    'machin = 100.0\n[base.filament]\nn_beads = 21\n[base.numerics]\ntol = 1e-3\n')
    out = tiny / "swf.json"
    code = main(["stability", str(spec), "--sweep", "--far", "--workers", "1", "--out", str(out)])
    text = capsys.readouterr().out
    (row,) = json.loads(out.read_text())["rows"]
    assert code == 0, text
    assert row["converged"] and row["far_found"]
    assert ("far state's fold" in text) == (row["machin_fold"] is not None)
    # where the branch ends without a smooth fold the row says so, with where it ended
    assert row["machin_fold"] is not None or (row["far_lowest"] > row["far_lost_below"]
                                              and "no fold" in text)
    # --sweep --far refuses the options of one helix's diagram
    assert main(["stability", str(spec), "--sweep", "--far", "--diagram", "x.png"]) == 2
    assert "apply to one helix" in capsys.readouterr().err


def test_frame_config_takes_a_config_whose_speed_is_a_frequency():
    """A config that gives the reference speed in Hz (the bacteria's) is stepped at the
    diagram's M: its frequency gives way (the two are exclusive; before, every --far on such
    a config stopped with 'give exactly one of frequency or machin')."""
    from flagwrap.io.config import config_from_dict, tomllib
    from flagwrap.params import Phase
    from flagwrap.stability.bifurcation import frame_config

    cfg = config_from_dict(tomllib.loads(tiny_toml().replace("machin = 100", "frequency = 0.05")))
    out = frame_config(cfg, 1234.0, (Phase("cw", 2.0),))
    assert out.motor.frequency is None and out.machin == pytest.approx(1234.0)
    assert out.numerics.frame == "rotating"
