"""Built-in cases: every example config ships with the package and works by name from any
folder (a wheel install has no examples/ folder)."""

from pathlib import Path

import pytest

from flagwrap.cases import CASES, CASES_DIR, case_files, get_case
from flagwrap.cli.main import main
from flagwrap.errors import UserInputError
from flagwrap.io.config import load_config, load_config_or_case

ROOT = Path(__file__).parents[2]


def test_examples_are_the_shipped_case_files():
    # one copy: examples/<name>.toml is the package's data/cases/<name>.toml (a link, or at
    # least the same bytes where a checkout turned links into copies), and nothing only in one
    examples = {p.stem: p for p in (ROOT / "examples").glob("*.toml")}
    shipped = case_files()
    assert set(examples) == set(shipped) and len(shipped) >= 16
    for name, p in examples.items():
        assert p.read_bytes() == shipped[name].read_bytes(), name
        if p.is_symlink():
            assert p.resolve() == shipped[name].resolve()
    assert CASES_DIR.is_relative_to(ROOT / "src" / "flagwrap")


def test_case_names_match_their_files():
    for name in CASES:
        assert get_case(name).name == name


# the paper's numbers the built-in paper cases must carry (SI movie list, Fig. 4 captions):
# length [m], helix radius [m], helical turns, and the Machin number or the motor frequency [Hz]
PAPER = {
    "fig4a": (0.400, 0.030, 2.0, {"machin": 283.0}),
    "fig4b": (0.359, 0.0125, 2.5, {"machin": 2348.0}),
    "movie2": (0.358, 0.0225, 2.35, {"frequency": 0.01}),
    "movie3": (0.400, 0.030, 2.0, {"frequency": 0.006}),
    "movie5": (0.358, 0.0225, 2.35, {"frequency": 0.02}),
    "movie6": (0.359, 0.0125, 2.5, {"frequency": 0.10}),
    "movie7": (0.300, 0.015, 3.0, {"frequency": 0.10}),
}


@pytest.mark.parametrize("name", sorted(PAPER))
def test_paper_cases_carry_the_papers_numbers(name):
    L, R, n, motor = PAPER[name]
    cfg = get_case(name)
    fil = cfg.filament
    assert (fil.length, fil.helix_radius, fil.turns) == pytest.approx((L, R, n))
    assert (fil.cross_section_radius, fil.youngs_modulus, fil.poisson_ratio) == \
        pytest.approx((1.5e-3, 1.5e6, 0.49))
    assert cfg.fluid.viscosity == pytest.approx(1.1)
    for key, value in motor.items():
        assert getattr(cfg.motor, key) == pytest.approx(value)


def test_every_case_by_name_from_any_folder(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    for name in ("hook", "s_putrefaciens", "p_putida_bundle", "c_insecticola", "fig4a"):
        assert load_config_or_case(name) == load_config(case_files()[name])


def test_an_example_path_outside_a_checkout_names_the_case(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert main(["run", "examples/hook.toml", "--dry-run"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "built-in case 'hook'" in err[0] and "give hook instead" in err[0]
    with pytest.raises(UserInputError, match="--list-cases"):
        load_config_or_case("no_such_case")


def test_list_cases(capsys):
    assert main(["run", "--list-cases"]) == 0
    out = capsys.readouterr().out.splitlines()
    assert [line.split()[0] for line in out[:-1]] == sorted(CASES)
    assert out[0].startswith("c_insecticola ") and "Caballeronia" in out[0]
    assert str(CASES_DIR) in out[-1]
    assert main(["run", "hook", "--list-cases"]) == 2
