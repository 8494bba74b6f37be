"""``flagwrap stability``: output, exit codes, the sweep mode (a 21-bead helix: seconds)."""

import json

import pytest

from conftest import tiny_toml


@pytest.fixture(scope="module")
def tiny(tmp_path_factory):
    d = tmp_path_factory.mktemp("stab")
    (d / "tiny.toml").write_text(tiny_toml())
    return d


def test_json_result_names_the_threshold_and_the_crossing(tiny, capsys):
    from flagwrap.cli.main import main

    code = main(["stability", str(tiny / "tiny.toml"), "--json", "--vtk", str(tiny / "m.vtp"),
                 "--mode", str(tiny / "m.png")])
    s = json.loads(capsys.readouterr().out)
    assert code == 0 and s["converged"]
    lo, hi = s["bracket"]
    assert lo < s["machin_c"] < hi and hi / lo - 1 <= 1e-3
    assert s["crossing"] in ("hopf", "fold", "steady")
    # omega_c is M_c in SI units: omega_c / M_c = A / (eta L^4) of the config
    from flagwrap.io.config import load_config

    cfg = load_config(tiny / "tiny.toml")
    assert s["omega_c"] == pytest.approx(cfg.omega * s["machin_c"] / cfg.machin, rel=1e-12)
    assert (tiny / "m.vtp").stat().st_size > 0 and (tiny / "m.png").stat().st_size > 0
    assert "mode_real" in (tiny / "m.vtp").read_text()


def test_no_crossing_in_the_range_is_exit_1_with_what_was_found(tiny, capsys):
    from flagwrap.cli.main import main

    code = main(["stability", str(tiny / "tiny.toml"), "--m-max", "40"])
    out = capsys.readouterr().out
    assert code == 1 and "NOT FOUND: stable up to M = 40" in out and "raise --m-max" in out


def test_unreachable_start_is_exit_1(tiny, capsys):
    from flagwrap.cli.main import main

    # so far from the rest shape that Newton cannot start (halved 8 times: still 2e4)
    code = main(["stability", str(tiny / "tiny.toml"), "--m-start", "5e6", "--m-max", "1e7"])
    out = capsys.readouterr().out
    assert code == 1 and "NOT FOUND" in out


def test_sweep_mode_writes_one_row_per_geometry_and_a_fit(tiny, capsys):
    from flagwrap.cli.main import main

    spec = tiny / "sw.toml"
    spec.write_text('name = "sw"\nmode = "grid"\n[grid]\npsi_deg = [70.0]\nturns = [2.0, 3.0, 3.5]\n'
                    'machin = 100.0\n[base.filament]\nn_beads = 21\n')
    out = tiny / "sw.json"
    code = main(["stability", str(spec), "--sweep", "--workers", "1", "--out", str(out)])
    text = capsys.readouterr().out
    res = json.loads(out.read_text())
    assert code == 0, text
    assert len(res["rows"]) == 3 and all(r["converged"] for r in res["rows"])
    assert res["fit"]["n"] == 3 and res["fit"]["exponent"] > 0
    assert "fit over 3 helices" in text


def test_a_torque_speed_motor_is_judged_against_the_whirls_torque(tiny, capsys):
    # the same threshold as the speed motor's, plus the verdict: a line whose stall torque is
    # 1.5x / 0.7x the one the whirl needs buckles / does not, and the text says which
    from flagwrap.cli.main import main

    main(["stability", str(tiny / "tiny.toml"), "--json"])
    ref = json.loads(capsys.readouterr().out)
    assert ref["motor"] is None
    need = None
    for k, word in ((None, None), (1.5, "it buckles"), (0.7, "stops short")):
        stall = 1.0 if k is None else k * need  # the first pass only measures the need
        motor = f"machin = 100\nkind = 'torque-speed'\nstall_torque = {stall!r}\nzero_load_speed = 1e3"
        (tiny / "ts.toml").write_text(tiny_toml().replace("machin = 100", motor))
        if k is None:
            assert main(["stability", str(tiny / "ts.toml"), "--json"]) == 0
            s = json.loads(capsys.readouterr().out)
            assert s["machin_c"] == pytest.approx(ref["machin_c"], rel=1e-12)
            need = s["motor"]["stall_torque_needed"]
            continue
        assert main(["stability", str(tiny / "ts.toml")]) == 0
        assert word in capsys.readouterr().out


def test_progress_from_the_first_second_off_a_terminal(tiny, capsys):
    # issue 34, item 1: a batch job (stderr not a TTY) sees what the command is doing before
    # the first state is found, then one line per steady state; --no-progress and --json none
    from flagwrap.cli.main import main

    code = main(["stability", str(tiny / "tiny.toml"), "--m-max", "40"])
    err = capsys.readouterr().err.splitlines()
    assert code == 1
    assert err[0].startswith("flagwrap stability") and "from M = 10 up to 40" in err[0]
    states = [line for line in err if line.lstrip().startswith("M = ")]
    assert len(states) >= 3 and "leading eigenvalue" in states[0]
    for quiet in (["--no-progress"], ["--json"]):
        main(["stability", str(tiny / "tiny.toml"), "--m-max", "40", *quiet])
        assert capsys.readouterr().err == ""


def test_the_threshold_torque_and_onset_prefactor_are_reported(tiny, capsys):
    # issue 29, items 3-4: the whirl's motor torque at M_c in A/R and SI, and the linear
    # waiting-time prefactor, in the JSON and the text, consistent with each other
    import math

    from flagwrap.cli.main import main
    from flagwrap.io.config import load_config

    assert main(["stability", str(tiny / "tiny.toml"), "--json"]) == 0
    s = json.loads(capsys.readouterr().out)
    fil = load_config(tiny / "tiny.toml").filament
    assert s["torque_c"] == pytest.approx(s["torque_c_reduced"] * fil.bending_modulus
                                          / fil.helix_radius, rel=1e-12)
    assert s["growth_slope"] > 0 and s["onset_prefactor"] == pytest.approx(
        math.log(150) / (2 * math.pi * s["growth_slope"]))
    assert main(["stability", str(tiny / "tiny.toml"), "--no-progress"]) == 0
    out = capsys.readouterr().out
    assert f"motor torque of the whirl at M_c: {s['torque_c_reduced']:.3f} A/R" in out
    assert f"t_c/T ~ {s['onset_prefactor']:.2f}/eps" in out
