"""TOML configs: round trip and clean errors."""

import pytest

from flagwrap.errors import UserInputError
from flagwrap.io.config import config_from_dict, config_to_toml, load_config


def test_examples_load_and_round_trip(tmp_path):
    import glob

    files = sorted(glob.glob("examples/*.toml"))
    assert len(files) >= 7
    for f in files:
        cfg = load_config(f)
        p = tmp_path / "c.toml"
        p.write_text(config_to_toml(cfg))
        again = load_config(p)
        assert again.to_dict() == {**cfg.to_dict(), "name": cfg.name}


def test_unit_table_rescales():
    d = {
        "units": {"length": "mm", "pressure": "MPa"},
        "filament": {"length": 400, "helix_radius": 30, "turns": 2, "cross_section_radius": 1.5,
                     "youngs_modulus": 1.5},
        "motor": {"machin": 283},
    }
    cfg = config_from_dict(d)
    assert cfg.filament.length == pytest.approx(0.4)
    assert cfg.filament.youngs_modulus == pytest.approx(1.5e6)


@pytest.mark.parametrize(
    "text,needle",
    [
        ("[filament]\nlenght = 1\n[motor]\nmachin=1", "unknown key filament.lenght"),
        ("[filament\n", "malformed TOML"),
        ("[motor]\nmachin = 10\n", "missing required section \\[filament\\]"),
        ("[filament]\nlength = 0.4\n[motor]\nmachin = 10\n", "missing required value"),
        ("[filament]\nlength = 'long'\nhelix_radius=0.03\nturns=2\ncross_section_radius=0.0015\n"
         "youngs_modulus=1.5e6\n[motor]\nmachin = 10\n", "filament.length must be a number"),
        ("[filament]\nlength = inf\nhelix_radius=0.03\nturns=2\ncross_section_radius=0.0015\n"
         "youngs_modulus=1.5e6\n[motor]\nmachin = 10\n", "finite"),
        ("[bogus]\n", "unknown section"),
        ("[units]\nlength='furlong'\n", "units.length"),
    ],
)
def test_bad_configs_give_one_line_errors(tmp_path, text, needle):
    p = tmp_path / "bad.toml"
    p.write_text(text)
    with pytest.raises(UserInputError, match=needle):
        load_config(p)


def test_missing_file():
    with pytest.raises(UserInputError, match="not found"):
        load_config("does/not/exist.toml")


_BASE = {"filament": {"length": 0.4, "helix_radius": 0.03, "turns": 2,
                      "cross_section_radius": 0.0015, "youngs_modulus": 1.5e6},
         "motor": {"machin": 283}}


@pytest.mark.parametrize("section,key", [("filament", "length"), ("filament", "youngs_modulus"),
                                         ("filament", "density"), ("fluid", "viscosity"),
                                         ("fluid", "density")])
def test_booleans_are_rejected_where_unit_scaled_numbers_are_expected(section, key):
    # the [units] scaling must not turn true into 1.0 before validation sees it
    d = {**_BASE, section: {**_BASE.get(section, {}), key: True}}
    with pytest.raises(UserInputError, match=f"{key} must be a number"):
        config_from_dict(d)


def test_stored_toml_escapes_control_characters(tmp_path):
    # a run file stores config_to_toml(cfg) as "the full input, re-loadable"
    cfg = config_from_dict({**_BASE, "name": 'tiny\nrun\t"q" \\ \x7f\x01'})
    p = tmp_path / "c.toml"
    p.write_text(config_to_toml(cfg))
    assert load_config(p).name == cfg.name


def test_stored_toml_reads_back_numpy_scalars(tmp_path):
    # configs built in Python take numpy scalars (a study's tube length from array arithmetic);
    # numpy 2 prints them as "np.float64(...)", which no TOML reader takes
    import dataclasses

    import numpy as np

    from flagwrap.params import TubeWall

    cfg = config_from_dict(_BASE)
    tube = TubeWall(radius=np.float64(0.5), length=np.float64(0.4), center=(0.0, 0.0, -0.2),
                    blob_spacing=np.float64(0.05))
    cfg = cfg.replace(tubes=(tube,), fluid=dataclasses.replace(cfg.fluid,
                                                                viscosity=np.float64(1.5)))
    text = config_to_toml(cfg)
    assert "np." not in text
    p = tmp_path / "c.toml"
    p.write_text(text)
    again = load_config(p)
    assert again.tubes[0].length == 0.4 and again.fluid.viscosity == 1.5
    assert again.to_dict() == {**cfg.to_dict(), "name": again.name}
