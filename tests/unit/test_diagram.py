"""Fig. 5 diagram (issue 5): the boundary fit recovers a known power law (oracle: synthetic
brackets around M_c = c (R/L)^-beta), brackets from rows, and the figure is drawn from rows."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from flagwrap.plotting.diagram import classify, fit_boundary, fig5
from flagwrap.sweep.boundary import brackets_from_rows


def _rows(c=0.2, beta=3.0, ratios=(0.5, 0.9, 1.1, 2.0), rls=(0.03, 0.045, 0.06, 0.08, 0.1), psi=70.0):
    rows = []
    for rl in rls:
        mc = c * rl ** -beta
        for q in ratios:
            m = q * mc
            rows.append({"key": f"{rl}-{q}", "status": "ok", "psi_deg": psi, "turns": 2.0,
                         "r_over_l": rl, "r_over_l_cubed": rl ** 3, "r_over_rcell": 0.6, "hi": True,
                         "n_beads": 31, "ccw_turns": 5.0, "cw_turns": 10.0, "machin": m,
                         "buckled": m > mc, "state": ("wrapping" if rl > 0.05 else "folding") if m > mc else "stable"})
    return rows


def test_brackets_from_rows():
    br = brackets_from_rows(_rows())
    assert len(br) == 5
    for b in br:
        mc = 0.2 * b["r_over_l"] ** -3
        assert b["kind"] == "bracket" and b["m_lo"] < mc < b["m_hi"]
        assert b["machin_c"] == pytest.approx(mc, rel=0.01)
        assert b["sigma_ln"] == pytest.approx(0.5 * math.log(1.1 / 0.9))
    only_stable = brackets_from_rows([r for r in _rows() if not r["buckled"]])
    assert {b["kind"] for b in only_stable} == {"lower"}
    failed = [dict(r, status="failed", buckled=None) for r in _rows()]
    assert brackets_from_rows(failed) == []


@pytest.mark.parametrize("c,beta", [(0.06, 3.0), (0.25, 2.5)])
def test_fit_recovers_power_law(c, beta):
    fit = fit_boundary(brackets_from_rows(_rows(c, beta)))
    assert fit["n"] == 5
    assert fit["exponent"] == pytest.approx(beta, rel=1e-3)
    assert fit["prefactor"] == pytest.approx(c * 0.99, rel=2e-2)  # sqrt(0.9 * 1.1) = 0.995
    if beta == 3.0:
        assert fit["prefactor_beta3"] == pytest.approx(c, rel=1e-2)


def test_fit_uncertainty_covers_noisy_truth():
    rng = np.random.default_rng(1)
    hits = 0
    for _ in range(40):
        rls = np.exp(rng.uniform(np.log(0.025), np.log(0.1), 12))
        br = []
        for rl in rls:
            mc = 0.1 * rl ** -3 * math.exp(rng.normal(0, 0.2))
            br.append({"kind": "bracket", "r_over_l": rl, "machin_c": mc, "sigma_ln": 0.2 * math.sqrt(3)})
        fit = fit_boundary(br)
        hits += abs(fit["exponent"] - 3.0) < 2 * fit["exponent_err"]
    assert hits >= 33  # ~95 % expected within 2 sigma


def test_fit_degenerate_inputs():
    fit = fit_boundary([])
    assert fit["n"] == 0 and math.isnan(fit["exponent"])
    two = brackets_from_rows(_rows(rls=(0.05, 0.08)))
    assert math.isnan(fit_boundary(two)["exponent"]) and math.isfinite(fit_boundary(two)["prefactor_beta3"])


def test_classify():
    assert classify({"status": "ok", "buckled": False}) == "stable"
    assert classify({"status": "ok", "buckled": True, "state": "wrapping"}) == "wrapping"
    assert classify({"status": "ok", "buckled": True, "state": "folding"}) == "folding"
    assert classify({"status": "failed", "buckled": None}) == "failed"


def test_fig5_from_sweep_rows(tmp_path):
    from flagwrap.sweep.store import SweepStore

    store = SweepStore(tmp_path / "sw")
    rows = _rows() + [dict(_rows()[0], key="bad", status="failed", buckled=None, state="failed")]
    for r in rows:
        store.write_row(r)
    paths = fig5(tmp_path / "fig", sweep_dirs=[tmp_path / "empty", tmp_path / "sw"])
    assert [p.rsplit(".", 1)[1] for p in paths] == ["png", "pdf", "json"]
    info = json.loads((tmp_path / "fig" / "fig5.json").read_text())
    assert info["n_rows"] == 21 and info["classes"]["failed"] == 1
    assert info["fit"]["exponent"] == pytest.approx(3.0, rel=1e-3)
    with pytest.raises(Exception, match="no sweep results"):
        fig5(tmp_path / "fig", sweep_dirs=[tmp_path / "empty"])


def test_fig5_names_each_star_and_puts_the_bracket_bars_in_the_legend(tmp_path):
    # a reader must tell which star is which bacterium and what the grey bars are
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from flagwrap.bacteria import default_species
    from flagwrap.plotting.diagram import diagram, species_labels

    species = default_species()
    names = species_labels(species)
    assert "S. putrefaciens" in names and "P. putida" in names
    assert {"C. insecticola (coil)", "C. insecticola (normal)"} <= set(names)
    assert len(set(names)) == len(species)
    rows = _rows()
    fig, ax = plt.subplots()
    diagram(rows, ax=ax, brackets=brackets_from_rows(rows), species=species)
    texts = {t.get_text(): t.xy for t in ax.texts}
    for sp, name in zip(species, names):
        assert texts[name] == (sp.radius_over_length_cubed, sp.machin)
    legend = [t.get_text() for t in ax.get_legend().get_texts()]
    assert any(t.startswith("bracket:") for t in legend) and "bacteria (SI)" in legend
    plt.close(fig)
    fig, ax = plt.subplots()  # no brackets drawn: none in the legend
    diagram(rows, ax=ax, species=[])
    assert not any(t.get_text().startswith("bracket") for t in ax.get_legend().get_texts())
    assert not ax.texts
    plt.close(fig)
