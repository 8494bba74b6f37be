"""`flagwrap figure`: registry, argument parsing, files written (small N for speed)."""

import argparse
import functools

from flagwrap.cli import figure as cli_figure
from flagwrap.cli import main as cli_main


def test_registered():
    assert cli_main.COMMANDS["figure"] == "figure"
    assert "fig3" in cli_figure.FIGURES


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
