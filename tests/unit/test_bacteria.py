"""Bacteria database (SI "Parameter values of flagellar-wrapping bacteria"): oracle = hand
calculation from the SI's printed inputs and the schema's own rules."""

import math

import pytest

from flagwrap.bacteria import default_species, format_table, load_species_file
from flagwrap.errors import UserInputError


@pytest.fixture(scope="module")
def species():
    return {s.key: s for s in default_species()}


def test_all_entries_and_provenance(species):
    assert set(species) == {"c_insecticola_coil", "c_insecticola_normal", "s_putrefaciens", "p_putida"}
    for s in species.values():
        for f in ("radius_um", "length_um", "frequency_hz", "viscosity_pa_s", "n_flagella"):
            assert s.provenance[f].source, f"{s.key}.{f} lacks a source"
    # values not printed in the seed are marked as assumptions or gaps, never as seed values
    assert species["c_insecticola_coil"].provenance["radius_um"].status == "assumption"
    assert species["c_insecticola_coil"].provenance["pitch_um"].status == "gap"
    assert species["c_insecticola_coil"].pitch_um is None
    assert species["c_insecticola_coil"].provenance["n_flagella"].status == "assumption"


def test_s_putrefaciens_hand_calculation(species):
    # oracle: M = eta 2 pi f L^4 / (pi E a^4 / 4) by hand with the SI's numbers; tolerance: round-off
    s = species["s_putrefaciens"]
    A = math.pi * 4.5e8 * (10e-9) ** 4 / 4
    M = 5e-3 * 2 * math.pi * 50 * (6.5e-6) ** 4 / A
    assert s.machin == pytest.approx(M, rel=1e-12)
    assert s.radius_over_length_cubed == pytest.approx((0.473 / 6.5) ** 3, rel=1e-12)
    assert s.instability_ratio() == pytest.approx(M * (0.473 / 6.5) ** 3 / 0.06, rel=1e-12)
    assert s.side() == "unstable"


def test_sides_against_paper(species):
    # oracle: the paper's statement; P. putida lands stable with the SI's own numbers (reported)
    assert species["c_insecticola_coil"].side() == "unstable"
    assert species["c_insecticola_normal"].side() == "stable"
    assert species["s_putrefaciens"].side() == "unstable"
    assert species["p_putida"].side() == "stable"
    assert species["p_putida"].paper_side == "unstable"
    need = species["p_putida"].crossing_inputs()
    assert need["viscosity_pa_s"] == pytest.approx(2e-4 / species["p_putida"].instability_ratio(), rel=1e-12)


def test_crossing_inputs_land_on_boundary(species):
    # oracle: M/M_c = 1 after replacing one input; tolerance: round-off
    from dataclasses import replace

    s = species["p_putida"]
    need = s.crossing_inputs()
    for f in ("viscosity_pa_s", "frequency_hz", "length_um", "radius_um"):
        assert replace(s, **{f: need[f]}).instability_ratio() == pytest.approx(1.0, rel=1e-10)


def test_table_marks_disagreement(species):
    text = format_table(list(species.values()))
    assert "unstable!" in text and "Pseudomonas putida" in text


def test_user_file(tmp_path):
    p = tmp_path / "mine.toml"
    p.write_text(
        '[[species]]\nkey = "v_fischeri"\nname = "Aliivibrio fischeri"\nradius_um = 0.5\nlength_um = 6.0\n'
        'frequency_hz = 100.0\nviscosity_pa_s = { value = 1e-3, status = "assumption", source = "water" }\n'
        "n_flagella = 3\n"
    )
    (s,) = load_species_file(p)
    assert s.youngs_modulus_pa == 4.5e8 and s.filament_radius_nm == 10.0
    assert s.provenance["viscosity_pa_s"].status == "assumption"


@pytest.mark.parametrize(
    "body, match",
    [
        ('[[species]]\nkey = "x"\nradius_um = -1\nlength_um = 6\nfrequency_hz = 1\nviscosity_pa_s = 1\nn_flagella = 1\n', "radius_um"),
        ('[[species]]\nkey = "x"\nradius_um = 1\nlength_um = 6\nfrequency_hz = 1\nviscosity_pa_s = 1\nn_flagella = 1.5\n', "n_flagella"),
        ('[[species]]\nkey = "x"\nradius_um = 1\nlength_um = 6\nfrequency_hz = 1\nn_flagella = 1\n', "viscosity_pa_s"),
        ("not toml = = 1", "invalid TOML"),
    ],
)
def test_user_file_errors(tmp_path, body, match):
    p = tmp_path / "bad.toml"
    p.write_text(body)
    with pytest.raises(UserInputError, match=match):
        load_species_file(p)


def test_species_filament_config_has_the_species_machin_number_and_geometry():
    from flagwrap.bacteria.species import default_species
    from flagwrap.bacteria.stability import species_config

    sp = next(s for s in default_species() if s.key == "s_putrefaciens")
    cfg = species_config(sp)
    # A = n pi E a^4 / 4 either way: the bundle as one filament of Young's modulus n E
    assert cfg.machin == pytest.approx(sp.machin, rel=1e-12)
    assert cfg.filament.helix_radius / cfg.filament.length == pytest.approx(sp.radius_um / sp.length_um)
    assert cfg.filament.pitch == pytest.approx(sp.pitch_um * 1e-6)
    # beads at the rig's spacing: a / b = 1.5 / (400 / 60)
    b = cfg.filament.length / (cfg.filament.n_beads - 1)
    assert cfg.filament.cross_section_radius / b == pytest.approx(0.225, rel=0.01)


def test_species_without_a_pitch_is_refused_by_name():
    from flagwrap.bacteria.species import default_species
    from flagwrap.bacteria.stability import species_config
    from flagwrap.errors import UserInputError

    sp = next(s for s in default_species() if s.key == "c_insecticola_coil")
    with pytest.raises(UserInputError, match="c_insecticola_coil.*pitch_um"):
        species_config(sp)


def test_c_insecticola_example_is_the_data_files_coil(species):
    # the example's sourced numbers are the data file's (so they cannot drift apart), its bundle
    # stiffness is n A_1, its M is the one `flagwrap bacteria` prints, and its assumed cell fits
    # inside the coil it wraps with (radius below R - a) and below the ~1 um channel it passes
    from flagwrap.io.config import load_config

    s = species["c_insecticola_coil"]
    cfg = load_config("examples/c_insecticola.toml")
    f = cfg.filament
    assert f.length == pytest.approx(s.length_um * 1e-6, rel=1e-12)
    assert f.helix_radius == pytest.approx(s.radius_um * 1e-6, rel=1e-12)
    assert f.bending_modulus == pytest.approx(s.bending_stiffness, rel=1e-12)
    assert cfg.fluid.viscosity == pytest.approx(s.viscosity_pa_s, rel=1e-12)
    assert cfg.machin == pytest.approx(s.machin, rel=1e-9)
    assert f.handedness == "left"
    assert cfg.body.radius < f.helix_radius - f.cross_section_radius
    assert 2 * cfg.body.radius < 1e-6


def test_c_insecticola_torque_speed_example_is_the_example_but_its_motor():
    # the torque-speed variant brackets the motor (docs/bacterium.md): everything but [motor]
    # and the name must be the example's, or the comparison between them means nothing
    from flagwrap.io.config import load_config

    a = load_config("examples/c_insecticola.toml").to_dict()
    b = load_config("examples/c_insecticola_torque_speed.toml").to_dict()
    for d in (a, b):
        d.pop("name")
        d.pop("motor")
    assert a == b
    m = load_config("examples/c_insecticola_torque_speed.toml").motor
    assert m.kind == "torque-speed" and m.frequency == 40.0
