"""``flagwrap figure gravity``: the critical Machin number against the buoyancy (docs/gravity.md).

Reads the boundary sweeps over the density mismatch:

* ``out/sweeps/gravity-fig4a`` (``examples/sweeps/gravity-fig4a.toml``): ``M_c`` of the
  Fig. 4(a) helix per mismatch -> panel (a), ``M_c`` against ``G`` with the paper's ``~138``
  (M = 283 is "omega/omega_c ~ 2", SI Movie 4: 2.05) and the density-matched value;
* ``out/sweeps/gravity-fig5`` (``examples/sweeps/gravity-fig5.toml``), if present: the Fig. 5
  geometries per mismatch -> the fit ``M_c = c (R/L)^-beta`` for each mismatch
  (:func:`flagwrap.plotting.diagram.fit_boundary`), panel (c);

and computes panel (b), the static equilibrium of the same helix with the motor at rest
(:func:`flagwrap.analysis.static_buckling.static_branch`): the rise of its free end against
``G``, with the buckling criterion's 0.15 L. Writes ``gravity.png``, ``gravity.pdf`` and
``gravity.json`` (every number drawn).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from flagwrap.errors import UserInputError
from flagwrap.io.atomic import savefig_atomic

PAPER_MACHIN_C_FIG4A = 283.0 / 2.05  # SI Movie 4: M = 283 is omega/omega_c = 2.05
FIG4A_SWEEP = "out/sweeps/gravity-fig4a"
FIG5_SWEEP = "out/sweeps/gravity-fig5"
RISE = 0.15  # free-end rise of the buckling criterion [L] (docs/analysis.md)


def boundary_table(sweep_dir) -> list[dict]:
    """Per mismatch (sorted): ``density_mismatch``, ``gravity_number``, ``machin_c``,
    ``m_lo``, ``m_hi`` (None where one-sided) and ``kind`` ("bracket", "upper": buckled at
    every M tried, "lower": stable at every M tried) from a boundary sweep's summaries."""
    from flagwrap.sweep.boundary import summary_bracket
    from flagwrap.sweep.store import SweepStore

    out = []
    for b in SweepStore(sweep_dir).boundaries():
        if b.get("density_mismatch") is None:
            continue
        out.append({"density_mismatch": b["density_mismatch"], "gravity_number": b.get("gravity_number"),
                    **summary_bracket(b), "converged": b.get("converged"),
                    "monotone": b.get("monotone"), "status": b.get("status"),
                    "psi_deg": b["psi_deg"], "turns": b["turns"], "r_over_l": b["r_over_l"]})
    return sorted(out, key=lambda r: (r["psi_deg"], r["turns"], r["density_mismatch"]))


def diagram_fits(sweep_dir) -> list[dict]:
    """The boundary fit per mismatch of a Fig. 5 boundary sweep over the mismatch."""
    from flagwrap.plotting.diagram import fit_boundary
    from flagwrap.sweep.boundary import brackets_from_rows
    from flagwrap.sweep.store import SweepStore

    groups: dict = {}
    for r in SweepStore(sweep_dir).iter_rows():
        groups.setdefault(r.get("density_mismatch", 0.0), []).append(r)
    out = []
    for dm in sorted(groups):
        br = brackets_from_rows(groups[dm])
        out.append({"density_mismatch": dm, "gravity_number": groups[dm][0].get("gravity_number"),
                    "fit": fit_boundary(br), "brackets": br})
    return out


def gravity_figure(outdir="out/figures", fig4a_sweep=FIG4A_SWEEP, fig5_sweep=FIG5_SWEEP,
                   static_G=None) -> list:
    """Draw the figure; returns the written paths. Needs at least the Fig. 4(a) sweep."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from flagwrap.analysis.static_buckling import static_branch
    from flagwrap.cases import get_case
    from flagwrap.sweep.store import jsonable, write_json_atomic

    table = boundary_table(fig4a_sweep) if Path(fig4a_sweep).is_dir() else []
    if not table:
        raise UserInputError(f"no boundary results in {fig4a_sweep}: run `flagwrap sweep "
                             "examples/sweeps/gravity-fig4a.toml` first")
    fits = diagram_fits(fig5_sweep) if Path(fig5_sweep).is_dir() else []
    G_static = np.arange(0.0, 30.01, 1.0) if static_G is None else np.asarray(static_G, float)
    branch = static_branch(get_case("fig4a"), G_static)
    G_rise = branch.crossing(RISE)

    ncol = 3 if fits else 2
    fig, axes = plt.subplots(1, ncol, figsize=(4.6 * ncol, 4.2))
    ax = axes[0]
    for r in table:
        G = r["gravity_number"]
        if r["kind"] == "bracket":
            ax.errorbar([G], [r["machin_c"]], yerr=[[r["machin_c"] - r["m_lo"]], [r["m_hi"] - r["machin_c"]]],
                        fmt="o", color="C0", ms=5, capsize=2)
        elif r["kind"] == "upper":
            ax.plot([G], [r["m_hi"]], "v", color="C3", ms=6)
        else:
            ax.plot([G], [r["m_lo"]], "^", color="C2", ms=6)
    ax.axhline(PAPER_MACHIN_C_FIG4A, color="k", ls="--", lw=1,
               label=rf"paper: $M_c \approx {PAPER_MACHIN_C_FIG4A:.0f}$")
    if math.isfinite(G_rise):
        ax.axvline(G_rise, color="0.5", ls=":", lw=1, label=rf"static rise = {RISE} L at M=0 (G = {G_rise:.1f})")
    ax.set_yscale("log")
    ax.set_xlabel(r"gravity number $G = (\rho_f-\rho)\,g\,\pi a^2 L^3/A$  (> 0: buoyant)")
    ax.set_ylabel(r"$M_c$ (this model, rise criterion)")
    ax.set_title("(a) Fig. 4(a) helix: $M_c$ vs buoyancy", fontsize=9)
    ax.plot([], [], "o", color="C0", label="bracket (rtol 0.05)")
    ax.plot([], [], "v", color="C3", label="buckled at every M tried (upper bound)")
    ax.legend(fontsize=7)
    sec = ax.secondary_xaxis("top", functions=(lambda g: -100 * g / _per_percent(table),
                                               lambda p: -p * _per_percent(table) / 100))
    sec.set_xlabel("density mismatch (rho - rho_f)/rho_f [%]", fontsize=8)

    ax = axes[1]
    ax.plot(branch.G, branch.tip_height, "-", color="C1", label="free-end rise (static, M = 0)")
    ax.plot(branch.G, branch.tip_offset, "--", color="C4", label="free end's distance from the axis")
    ax.axhline(RISE, color="0.5", ls=":", lw=1)
    ax.set_xlabel("G")
    ax.set_ylabel("[L]")
    ax.set_title("(b) same helix, motor at rest: static equilibrium", fontsize=9)
    ax.legend(fontsize=7)

    if fits:
        ax = axes[2]
        for k, f in enumerate(fits):
            pts = [b for b in f["brackets"] if b.get("kind") == "bracket"]
            if not pts:
                continue
            x = np.array([b["r_over_l_cubed"] for b in pts])
            ax.plot(x, [b["machin_c"] for b in pts], "o", color=f"C{k}",
                    label=f"{100 * f['density_mismatch']:+.0f} % (G = {f['gravity_number']:.3g}): "
                          f"c = {f['fit']['prefactor']:.3g}, beta = {f['fit']['exponent']:.2f}")
            if math.isfinite(f["fit"]["prefactor"]):
                xx = np.geomspace(x.min(), x.max(), 20)
                ax.plot(xx, f["fit"]["prefactor"] * xx ** (-f["fit"]["exponent"] / 3), "-", color=f"C{k}", lw=1)
        xx = np.geomspace(1e-5, 1.2e-3, 20)
        ax.plot(xx, 0.06 * xx ** -1.0, "k--", lw=1, label="paper: 0.06 (R/L)^-3")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel(r"$(R/L)^3$")
        ax.set_ylabel(r"$M_c$")
        ax.set_title("(c) Fig. 5 geometries (reduced resolution) per mismatch", fontsize=9)
        ax.legend(fontsize=6)
    fig.tight_layout()
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    paths = [outdir / "gravity.png", outdir / "gravity.pdf"]
    savefig_atomic(fig, paths[0], dpi=150)
    savefig_atomic(fig, paths[1])
    plt.close(fig)
    info = {"fig4a": table, "paper_machin_c": PAPER_MACHIN_C_FIG4A,
            "static": {"G": branch.G.tolist(), "tip_height": branch.tip_height.tolist(),
                       "tip_offset": branch.tip_offset.tolist(),
                       "lowest_eigenvalue": branch.lowest_eigenvalue.tolist(), "G_rise_0.15": G_rise,
                       "message": branch.message},
            "fig5": [{k: v for k, v in f.items() if k != "brackets"} | {"brackets": f["brackets"]} for f in fits],
            "sources": [str(fig4a_sweep)] + ([str(fig5_sweep)] if fits else [])}
    paths.append(write_json_atomic(jsonable(info), outdir / "gravity.json"))
    return [str(p) for p in paths]


def _per_percent(table) -> float:
    """G per unit mismatch (negative: G = -k mismatch) from the table's own rows."""
    for r in table:
        if r["density_mismatch"] and r["gravity_number"] is not None:
            return -r["gravity_number"] / r["density_mismatch"]
    return 929.8
