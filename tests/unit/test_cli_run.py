"""``flagwrap run`` end to end on a tiny case; bad input exits 2 without a traceback."""

import subprocess
import sys

import numpy as np

from flagwrap.cli.main import main
from flagwrap.io.runfile import config_of, read_run

from conftest import tiny_toml

TINY = tiny_toml(ccw=0.2, cw=0.5)


def test_run_writes_self_describing_file(tmp_path):
    cfgp = tmp_path / "tiny.toml"
    cfgp.write_text(TINY)
    out = tmp_path / "tiny.nc"
    fig = tmp_path / "tiny.png"
    rc = main(["run", str(cfgp), "-o", str(out), "--figure", str(fig), "--quiet"])
    assert rc == 0 and out.exists() and fig.stat().st_size > 1000
    ds = read_run(out)
    assert ds.attrs["status"] == "completed"
    assert ds.attrs["flagwrap_version"]
    assert ds["position"].shape[1:] == (21, 3)
    np.testing.assert_allclose(ds["turns"].values[-1], 0.7, rtol=1e-9)
    # the stored config reproduces the run's parameters
    cfg = config_of(ds)
    assert cfg.filament.n_beads == 21 and cfg.machin == np.float64(ds.attrs["machin"])
    # torque sign follows the motor: CCW positive; negative once the CW phase has undone the
    # twist stored during CCW (a few hundredths of a turn)
    tq = ds["motor_torque"].values
    om = ds["omega"].values
    assert np.all(tq[1:][om[1:] > 0] > 0) and np.all(tq[-3:] < 0) and np.all(om[-3:] < 0)


def test_bad_config_exit_code_2_no_traceback(tmp_path):
    p = tmp_path / "bad.toml"
    p.write_text("[filament]\nlength = -1\n")
    r = subprocess.run([sys.executable, "-m", "flagwrap.cli.main", "run", str(p)],
                       capture_output=True, text=True)
    assert r.returncode == 2
    assert "Traceback" not in r.stderr and "error:" in r.stderr


def test_truncated_run_file_is_reported(tmp_path):
    import pytest

    from flagwrap.errors import UserInputError

    p = tmp_path / "t.nc"
    p.write_bytes(b"\x89HDF\r\n\x1a\n" + b"\0" * 100)
    with pytest.raises(UserInputError, match="not a readable run file"):
        read_run(p)


def test_turns_shortens_the_protocol_and_dry_run_runs_nothing(tmp_path, capsys):
    cfgp = tmp_path / "tiny.toml"
    cfgp.write_text(TINY)
    out = tmp_path / "short.nc"
    assert main(["run", str(cfgp), "-o", str(out), "--quiet", "--turns", "0.1", "0.05"]) == 0
    ds = read_run(out)
    np.testing.assert_allclose(ds["turns"].values[-1], 0.15, rtol=1e-9)
    assert [(p.direction, p.turns) for p in config_of(ds).motor.protocol] == [("ccw", 0.1),
                                                                             ("cw", 0.05)]
    capsys.readouterr()
    dry = tmp_path / "dry.nc"
    assert main(["run", str(cfgp), "-o", str(dry), "--dry-run", "--turns", "3", "0"]) == 0
    said = capsys.readouterr().out
    assert "(dry run)" in said and "3 motor turns" in said and "ms per step" in said
    assert "nothing was run" in said and not dry.exists()
    assert not list(tmp_path.glob("dry.nc*"))  # no checkpoint, no lock
    for bad in (["0", "0"], ["-1", "2"], ["nan", "1"]):
        assert main(["run", str(cfgp), "-o", str(dry), "--turns", *bad]) == 2
        assert "--turns must be two numbers >= 0" in capsys.readouterr().err
    assert not dry.exists()


def test_every_command_takes_a_case_name_where_it_takes_a_config(tmp_path, capsys):
    # issue 34: `flagwrap stability fig4a` said "config file not found" where the API took it
    from flagwrap.io.config import load_config_or_case

    assert load_config_or_case("fig4a").name == "fig4a"
    own = tmp_path / "fig4a"  # a file of a case's name wins: it is what the user pointed at
    own.write_text(TINY)
    assert load_config_or_case(str(own)).filament.n_beads == 21
    assert main(["run", "fig4a", "--dry-run", "--turns", "0.01", "0", "-o",
                 str(tmp_path / "f.nc")]) == 0
    assert "fig4a (dry run)" in capsys.readouterr().out
    for cmd in (["run"], ["stability"], ["critical"]):
        assert main([*cmd, "no-such-case"]) == 2
        err = capsys.readouterr().err
        assert "config file not found: no-such-case (a built-in case instead: " in err
        assert all(f" {name}," in err for name in ("fig4a", "hook", "s_putrefaciens"))


def test_a_header_above_the_scaling_line_says_where_this_models_threshold_is(tmp_path, capsys):
    # issue 34: `--case movie3` reads omega/omega_c = 1.25 and ends stable, unexplained
    assert main(["run", "--case", "fig4a", "--turns", "0.01", "0", "--quiet",
                 "-o", str(tmp_path / "a.nc")]) == 0
    err = capsys.readouterr().err
    assert "omega/omega_c (scaling) = 1.99 is against the paper's scaling line" in err
    assert "flagwrap stability" in err and "docs/stability.md" in err
    cfgp = tmp_path / "slow.toml"
    cfgp.write_text(TINY)  # M = 100: below the line, no note
    assert main(["run", str(cfgp), "--quiet", "--turns", "0.01", "0", "-o",
                 str(tmp_path / "b.nc")]) == 0
    assert "against the paper's scaling line" not in capsys.readouterr().err


def test_precise_is_the_rates_preset_in_the_command_and_the_api(tmp_path, capsys):
    # --precise tightens numerics.tol to 1e-6 (never loosens it), stored with the run; the
    # API's run(precise=True) is the same
    import flagwrap
    from flagwrap.cli.main import main
    from flagwrap.io.runfile import config_of, read_run

    cfg = tmp_path / "t.toml"
    cfg.write_text(tiny_toml(ccw=0.1, cw=0.05))
    assert main(["run", str(cfg), "--quiet", "--precise", "-o", str(tmp_path / "p.nc")]) == 0
    assert config_of(read_run(tmp_path / "p.nc")).numerics.tol == 1e-6
    tight = tmp_path / "tight.toml"
    tight.write_text(tiny_toml(ccw=0.1, cw=0.05).replace("tol = 1e-3", "tol = 1e-8"))
    assert main(["run", str(tight), "--quiet", "--precise", "-o", str(tmp_path / "q.nc")]) == 0
    assert config_of(read_run(tmp_path / "q.nc")).numerics.tol == 1e-8
    r = flagwrap.run(str(cfg), output=tmp_path / "a.nc", precise=True)
    assert config_of(read_run(tmp_path / "a.nc")).numerics.tol == 1e-6 and r is not None
