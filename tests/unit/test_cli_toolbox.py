"""CLI entries of the toolbox: oracle = the library functions they wrap; exit code 2 on user errors."""

import numpy as np
import pytest

from flagwrap.cli import main as cli_main

MINE = ("theory", "triangulate", "viscosity", "density", "bacteria")


def _run(argv, capsys):
    """Drive a subcommand module the way main() does, without importing the other commands."""
    import argparse
    import importlib

    from flagwrap.errors import UserInputError

    mod = importlib.import_module(f"flagwrap.cli.{cli_main.COMMANDS[argv[0]]}")
    parser = argparse.ArgumentParser()
    mod.add_arguments(parser)
    args = parser.parse_args(argv[1:])
    try:
        rc = mod.run(args)
    except UserInputError as exc:
        rc, _ = 2, print(exc)
    out = capsys.readouterr()
    return rc, out.out, out.err


def test_registered():
    for name in MINE:
        assert cli_main.COMMANDS[name] == name


def test_bacteria_table(capsys):
    rc, out, _ = _run(["bacteria"], capsys)
    assert rc == 0 and "Shewanella" in out and "p_putida: lands stable" in out


def test_bacteria_csv_and_user_file(tmp_path, capsys):
    p = tmp_path / "u.toml"
    p.write_text('[[species]]\nkey = "u"\nradius_um = 0.5\nlength_um = 6\nfrequency_hz = 100\nviscosity_pa_s = 1e-3\nn_flagella = 1\n')
    rc, out, _ = _run(["bacteria", "--csv", "--file", str(p)], capsys)
    assert rc == 0 and out.count("\n") == 6


def test_theory(capsys):
    rc, out, _ = _run(["theory", "numbers"], capsys)
    assert rc == 0 and "754.3" in out and "2500 pN nm" in out
    rc, out, _ = _run(["theory", "stretch", "--points", "5"], capsys)
    assert rc == 0 and out.splitlines()[0] == "psi_deg,z_over_L,F_N,F_reduced" and len(out.splitlines()) == 6


def test_triangulate_csv(tmp_path, capsys):
    from flagwrap.experiment.triangulation import StereoRig, project

    rig = StereoRig(1.0, 1.2, 1680.0, wall_1=0.82, wall_2=1.0)
    P = np.array([[0.01, -0.05, 0.1], [0.05, 0.02, -0.03]])
    img = project(rig, P)
    f = tmp_path / "img.csv"
    np.savetxt(f, img, delimiter=",", header="x1,y1,x2,y2", comments="")
    k = tmp_path / "known.csv"
    np.savetxt(k, np.hstack([P, img]), delimiter=",", header="X,Y,Z,x1,y1,x2,y2", comments="")
    rc, out, _ = _run(["triangulate", str(f), "--d1", "1.0", "--d2", "1.2", "--wall1", "0.82", "--wall2", "1.0"], capsys)
    got = np.loadtxt(out.splitlines()[1:], delimiter=",")[:, :3]
    # tolerance: 12 significant digits written to the CSV
    assert rc == 0 and np.allclose(got, P, atol=1e-10)
    rc, out, err = _run(["triangulate", str(f), "--d1", "1.01", "--d2", "1.19", "--wall1", "0.82", "--wall2", "1.0",
                         "--calibrate", str(k)], capsys)
    assert rc == 0 and "calibrated distance_1" in err


def test_viscosity(tmp_path, capsys):
    rc, out, _ = _run(["viscosity", "sphere", "--velocity", "0.0737", "--velocity-error", "0.0008"], capsys)
    assert rc == 0 and "eta = 1.14" in out
    T = np.linspace(285, 305, 6)
    from flagwrap.experiment.viscosity import andrade_viscosity

    f = tmp_path / "t.csv"
    np.savetxt(f, np.column_stack([T, andrade_viscosity(T)]), delimiter=",", header="T,eta", comments="")
    rc, out, _ = _run(["viscosity", "andrade", str(f)], capsys)
    assert rc == 0 and "U = 8.559e-20" in out
    rc, out, _ = _run(["viscosity", "at", "--temperature", "20", "--celsius"], capsys)
    assert rc == 0 and "293.15 K" in out
    # a forgotten --celsius (25 "K") printed eta = 3e98 Pa s; now a one-line error
    rc, out, _ = _run(["viscosity", "at", "--temperature", "25", "--machin", "283"], capsys)
    assert rc == 2 and "below 200 K" in out and "--celsius" in out  # (_run prints errors)


def test_density(tmp_path, capsys):
    rc, out, _ = _run(["density", "--polymer-mass", "100"], capsys)
    assert rc == 0 and "11.1165" in out
    f = tmp_path / "b.csv"
    f.write_text("m_base,m_cat,m_feo\n50,50,11.1165\n")
    rc, out, _ = _run(["density", str(f)], capsys)
    assert rc == 0 and "1250" in out


@pytest.mark.parametrize(
    "argv",
    [["triangulate", "/nonexistent.csv", "--d1", "1", "--d2", "1"], ["density"], ["bacteria", "--file", "/nope.toml"]],
)
def test_user_errors_exit_2(argv, capsys):
    rc, out, _ = _run(argv, capsys)
    assert rc == 2 and len(out.strip().splitlines()) == 1
