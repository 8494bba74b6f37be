"""The initial state from the config (issue 15, item 5): [initial] perturbation, mode, seed."""

import numpy as np
import pytest

from flagwrap.errors import UserInputError
from flagwrap.geometry.perturbation import displacement
from flagwrap.io.config import config_from_dict, config_to_toml, load_config
from flagwrap.system.rod_system import RodSystem

from conftest import make_config


def _cfg(**initial):
    d = make_config(machin=283.0).to_dict()
    if initial:
        d["initial"] = initial
    return config_from_dict(d)


def test_default_is_the_rest_shape_and_keeps_every_key():
    from flagwrap.analysis.critical import config_key

    cfg = _cfg()
    s = RodSystem(cfg)
    assert np.array_equal(s.initial_y(), s.pack(s.x0, s.theta0, 0.0))
    # results stored before [initial] existed keep their keys
    assert "initial" not in cfg.to_dict(for_hash=True)
    assert "[initial]" not in config_to_toml(cfg, for_hash=True)
    assert config_key(cfg) != config_key(_cfg(perturbation=1e-4))


@pytest.mark.parametrize("mode", ["random", "lateral"])
def test_perturbation_has_the_asked_amplitude_and_spares_the_clamp(mode):
    cfg = _cfg(perturbation=2e-3, mode=mode, seed=5)
    s = RodSystem(cfg)
    x, theta, phi = s.unpack(s.initial_y())
    dx = (x - s.x0) * cfg.filament.length
    assert np.linalg.norm(dx, axis=1).max() == pytest.approx(2e-3, rel=1e-12)
    assert np.array_equal(x[: s.nc], s.x0[: s.nc])  # the clamp holds its beads
    assert np.array_equal(theta, s.theta0) and phi == 0.0
    if mode == "lateral":
        assert np.all(dx[:, 1:] == 0.0)


def test_random_perturbation_is_reproducible_and_depends_on_the_seed():
    a = displacement(61, 1.0, "random", seed=1)
    assert np.array_equal(a, displacement(61, 1.0, "random", seed=1))
    assert not np.allclose(a, displacement(61, 1.0, "random", seed=2))
    # smooth: it grows as (s/L)^2 from the clamp, no bead-to-bead noise
    assert np.linalg.norm(a[1]) < 1e-3 and np.abs(np.diff(a, 2, axis=0)).max() < 0.05


def test_toml_round_trip_and_bad_values(tmp_path):
    cfg = _cfg(perturbation=1e-3, mode="lateral", seed=7)
    p = tmp_path / "c.toml"
    p.write_text(config_to_toml(cfg))
    assert load_config(p).initial == cfg.initial
    for bad, needle in (({"perturbation": -1.0}, "initial.perturbation"),
                        ({"perturbation": float("nan")}, "initial.perturbation"),
                        ({"mode": "wiggle"}, "initial.mode"), ({"seed": -1}, "initial.seed"),
                        ({"seed": 1.5}, "initial.seed"), ({"amplitude": 1.0}, "initial.amplitude")):
        with pytest.raises(UserInputError, match=needle):
            _cfg(**bad)


def test_units_table_scales_the_perturbation():
    # [units] length = "mm" applies to initial.perturbation like every other length
    d = make_config(machin=283.0).to_dict()
    d["units"] = {"length": "mm"}
    for k in ("length", "helix_radius", "pitch", "cross_section_radius"):
        d["filament"][k] = d["filament"][k] * 1e3
    d["initial"] = {"perturbation": 2.0}
    assert config_from_dict(d).initial.perturbation == pytest.approx(2e-3)


def test_cli_perturb_options(tmp_path, capsys):
    from flagwrap.cli.main import main
    from flagwrap.io.runfile import config_of, read_run

    from conftest import tiny_toml

    cfgp = tmp_path / "t.toml"
    cfgp.write_text(tiny_toml())
    out = tmp_path / "p.nc"
    assert main(["run", str(cfgp), "-o", str(out), "--quiet", "--perturb", "1e-3", "--seed", "4",
                 "--perturb-mode", "lateral"]) == 0
    ini = config_of(read_run(out)).initial
    assert (ini.perturbation, ini.seed, ini.mode) == (1e-3, 4, "lateral")
    capsys.readouterr()
    assert main(["run", str(cfgp), "-o", str(tmp_path / "q.nc"), "--quiet", "--perturb", "-1"]) == 2
    assert "--perturb must be >= 0" in capsys.readouterr().err


def test_straight_rest_shape_from_toml_and_cli(tmp_path):
    import argparse

    from flagwrap.cli.run import add_arguments, load
    from flagwrap.io.config import config_to_toml, load_config
    from flagwrap.system.rod_system import RodSystem

    p = argparse.ArgumentParser()
    add_arguments(p)
    cfg = load(p.parse_args(["examples/fig4a.toml", "--shape", "straight", "--self-contact"]))
    assert cfg.filament.shape == "straight" and cfg.contact.self_contact
    s = RodSystem(cfg)
    assert np.allclose(s.x0[:, :2], 0.0) and np.allclose(s.x0[-1], [0.0, 0.0, -1.0])
    info = s.forces(s.initial_y(), s.frames0)  # stress-free
    assert np.abs(info.G).max() < 1e-10
    path = tmp_path / "straight.toml"
    path.write_text(config_to_toml(cfg))
    assert load_config(path).filament.shape == "straight"
    # the default keeps the keys of results stored before the option existed
    assert "shape" not in load_config("examples/fig4a.toml").to_dict(for_hash=True)["filament"]
