"""`flagwrap figure`: registry, argument parsing, files written (small N for speed)."""

import argparse
import functools

import pytest

from flagwrap.cli import figure as cli_figure
from flagwrap.cli import main as cli_main


def test_every_registered_figure_is_reachable_and_an_unknown_one_refused(tmp_path, capsys):
    # the registry, the parser and the plans agree: each name parses, has a plan and a
    # callable, and its --dry-run says what it would do without running anything
    assert cli_main.COMMANDS["figure"] == "figure"
    names = set(cli_figure.FIGURES)
    assert {"fig3", "fig4", "fig5", "fig6"} <= names and names == set(cli_figure.PLANS)
    p = argparse.ArgumentParser()
    cli_figure.add_arguments(p)
    for name in sorted(names):
        assert callable(cli_figure.FIGURES[name])
        args = p.parse_args([name, "-o", str(tmp_path / name), "--dry-run"])
        assert cli_figure.run(args) == 0
        assert f"figure {name}: {cli_figure.PLANS[name]}" in capsys.readouterr().out
        assert not list((tmp_path / name).glob("*.png"))  # a dry run writes no figure
    with pytest.raises(SystemExit) as exit_:
        cli_main.main(["figure", "fig99"])
    assert exit_.value.code == 2 and "invalid choice: 'fig99'" in capsys.readouterr().err


def test_fig3_writes_png_and_pdf(tmp_path, monkeypatch, capsys):
    from flagwrap.plotting import figures

    small = functools.partial(figures.fig3, n_beads=41, n_steps=6, long_factor=2)
    monkeypatch.setitem(cli_figure.FIGURES, "fig3", small)
    p = argparse.ArgumentParser()
    cli_figure.add_arguments(p)
    args = p.parse_args(["fig3", "-o", str(tmp_path)])
    assert cli_figure.run(args) == 0
    for ext in ("png", "pdf"):
        f = tmp_path / f"fig3.{ext}"
        assert f.exists() and f.stat().st_size > 1000
    assert "fig3.png" in capsys.readouterr().out


def test_dry_run_says_which_sweep_results_exist(tmp_path, monkeypatch, capsys):
    # issue 34, item 9: `figure fig5 --dry-run` names each sweep folder it reads, with its row
    # count or the command that makes it (a shipped sweep's name, valid from any folder)
    from flagwrap.cli.main import main

    monkeypatch.chdir(tmp_path)
    rows = tmp_path / "out" / "sweeps" / "fig5-quick" / "rows"
    rows.mkdir(parents=True)
    for k in range(3):
        (rows / f"k{k}.json").write_text("{}")
    assert main(["figure", "fig5", "--dry-run", "-o", str(tmp_path / "figs")]) == 0
    out = capsys.readouterr().out
    assert "out/sweeps/fig5-quick: 3 rows" in out
    assert "out/sweeps/fig5: no results (make them with `flagwrap sweep fig5`" in out
    assert main(["figure", "fig5", "-o", str(tmp_path / "figs")]) == 2  # rows are not valid
