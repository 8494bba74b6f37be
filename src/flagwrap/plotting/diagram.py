"""The stability diagram (paper Fig. 5) from sweep results, and the fit of its boundary.

Axes as in the paper: ``(R/L)^3`` (abscissa) against ``M = eta omega L^4 / A`` (ordinate),
both logarithmic. Symbols are THIS model's measured classes (docs/sweeps.md): open circle =
stable (no buckling within the K CW turns), filled square = wrapping, filled circle = folding
(buckled, not wrapped at the end of the run), colour = pitch angle psi; grey crosses = failed
cases. Lines: the paper's scaling law ``M_c = 0.06 (R/L)^-3`` and our fit
``M_c = c (R/L)^-beta`` to the per-geometry brackets (:func:`fit_boundary`); stars: the
bacteria of the SI (``flagwrap.bacteria``).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from flagwrap.errors import UserInputError
from flagwrap.io.atomic import savefig_atomic

PAPER_PREFACTOR = 0.06
#: sweep folders read by ``flagwrap figure fig5``: the first group that has rows
DEFAULT_SWEEPS = (("out/sweeps/fig5",), ("out/sweeps/fig5-quick", "out/sweeps/fig5-boundary"))


def fit_boundary(brackets) -> dict:
    """Fit ``ln M_c = ln c - beta ln(R/L)`` to geometries with a two-sided bracket.

    Each point is ``M_c = sqrt(M_lo M_hi)``; its standard deviation in ``ln M`` is the bracket's
    log half-width over sqrt(3) (``M_c`` uniform in ``ln M`` inside the bracket), floored at
    0.01. Weighted least squares (``scipy.optimize.curve_fit``) with the covariance scaled by
    the reduced chi^2 (``absolute_sigma=False``): the scatter between geometries of equal R/L
    but different psi, n is larger than the bracket widths, and this lets it set the errors.
    Also the one-parameter fit with the paper's ``beta = 3``.

    Parameters
    ----------
    brackets : list of dict
        :func:`flagwrap.sweep.boundary.brackets_from_rows` output (other kinds are skipped).

    Returns
    -------
    dict
        ``n`` points; ``prefactor``, ``prefactor_err``, ``exponent`` (beta; the paper: 3),
        ``exponent_err``, ``cov_lnc_beta``; ``prefactor_beta3``, ``prefactor_beta3_err``;
        ``n_lower``/``n_upper`` (one-sided geometries, not fitted). nan where undefined
        (beta needs >= 3 points at >= 2 distinct R/L).
    """
    from scipy.optimize import curve_fit

    pts = [b for b in brackets if b.get("kind") == "bracket"]
    out = {"n": len(pts), "n_lower": sum(b.get("kind") == "lower" for b in brackets),
           "n_upper": sum(b.get("kind") == "upper" for b in brackets),
           "prefactor": math.nan, "prefactor_err": math.nan, "exponent": math.nan,
           "exponent_err": math.nan, "cov_lnc_beta": math.nan,
           "prefactor_beta3": math.nan, "prefactor_beta3_err": math.nan}
    if not pts:
        return out
    x = np.log([b["r_over_l"] for b in pts])
    y = np.log([b["machin_c"] for b in pts])
    s = np.maximum(np.array([b["sigma_ln"] for b in pts]) / math.sqrt(3), 0.01)
    # beta = 3 fixed: ln c = weighted mean of y + 3 x
    w = 1 / s**2
    z = y + 3 * x
    lnc3 = float(np.sum(w * z) / np.sum(w))
    out["prefactor_beta3"] = math.exp(lnc3)
    if len(pts) >= 2:
        chi2 = float(np.sum(w * (z - lnc3) ** 2)) / (len(pts) - 1)
        out["prefactor_beta3_err"] = math.exp(lnc3) * math.sqrt(max(chi2, 1e-300) / np.sum(w))
    if len(pts) >= 3 and np.ptp(x) > 0:
        (lnc, beta), cov = curve_fit(lambda xx, a, b: a - b * xx, x, y, p0=(lnc3, 3.0), sigma=s,
                                     absolute_sigma=False)
        out.update(prefactor=math.exp(lnc), prefactor_err=math.exp(lnc) * math.sqrt(cov[0, 0]),
                   exponent=float(beta), exponent_err=math.sqrt(cov[1, 1]),
                   cov_lnc_beta=float(cov[0, 1]))
    return out


def load_rows(sweep_dirs=None) -> tuple[list[dict], list[str]]:
    """Rows of the sweep folders ``sweep_dirs`` (union, one row per key). Default: the full
    sweep out/sweeps/fig5 if it has rows, else out/sweeps/fig5-quick together with
    out/sweeps/fig5-boundary (same reduced resolution). Returns ``(rows, [folders used])``."""
    from flagwrap.sweep.store import SweepStore

    groups = [list(sweep_dirs)] if sweep_dirs is not None else [list(g) for g in DEFAULT_SWEEPS]
    for dirs in groups:
        rows, used = {}, []
        for d in dirs:
            found = list(SweepStore(d).iter_rows())
            if found:
                used.append(str(d))
            for r in found:
                rows.setdefault(r["key"], r)
        if rows:
            return [rows[k] for k in sorted(rows)], used
    raise UserInputError(f"no sweep results in {', '.join(map(str, sum(groups, [])))}: run "
                         "`flagwrap sweep fig5-quick` (a shipped sweep, from any folder) first")


def classify(row: dict) -> str:
    """``stable`` / ``wrapping`` / ``folding`` / ``failed`` for a diagram symbol."""
    if row.get("status") != "ok" or row.get("buckled") is None:
        return "failed"
    if not row["buckled"]:
        return "stable"
    return "wrapping" if row.get("state") == "wrapping" else "folding"


def diagram(rows, ax=None, species=None, fit=None, brackets=None, psi_range=(30.0, 72.0),
            stability=None):
    """Draw the diagram of ``rows`` on ``ax`` (new figure if None); returns the axes.

    Parameters
    ----------
    rows : list of dict
        sweep rows (``r_over_l_cubed``, ``machin``, ``psi_deg``, ``buckled``, ``state``).
    species : list of flagwrap.bacteria.Species, optional
        stars (default: the shipped table; ``[]`` for none).
    fit : dict, optional
        :func:`fit_boundary` result: its line is drawn if finite.
    brackets : list of dict, optional
        per-geometry brackets; two-sided ones are drawn as black bars (M_lo..M_hi).
    stability : dict, optional
        ``flagwrap stability --sweep`` result: its linear thresholds (:func:`draw_stability`).
    """
    import matplotlib.pyplot as plt
    from matplotlib.colors import Normalize

    if ax is None:
        _, ax = plt.subplots(figsize=(6.4, 5.0))
    cmap, norm = plt.get_cmap("viridis"), Normalize(*psi_range)
    styles = {"stable": dict(marker="o", filled=False), "wrapping": dict(marker="s", filled=True),
              "folding": dict(marker="o", filled=True)}
    labelled = set()
    for r in rows:
        kind = classify(r)
        x, y = r["r_over_l_cubed"], r["machin"]
        if kind == "failed":
            ax.scatter([x], [y], marker="x", c="0.5", s=30, zorder=3,
                       label=None if "failed" in labelled else "failed")
        else:
            col = cmap(norm(r["psi_deg"]))
            st = styles[kind]
            ax.scatter([x], [y], marker=st["marker"], s=36, zorder=3, linewidths=1.2,
                       facecolors=col if st["filled"] else "none", edgecolors=col,
                       label=None if kind in labelled else kind)
        labelled.add(kind)
    xs = np.array([r["r_over_l_cubed"] for r in rows] or [1e-5, 1e-3])
    if species is None:
        from flagwrap.bacteria import default_species

        species = default_species()
    names = species_labels(species)
    for i, sp in enumerate(species):
        ax.scatter([sp.radius_over_length_cubed], [sp.machin], marker="*", s=140, c="tab:red",
                   edgecolors="k", linewidths=0.5, zorder=4, label="bacteria (SI)" if i == 0 else None)
        xs = np.append(xs, sp.radius_over_length_cubed)
    mid = 0.5 * (np.log10(xs.min()) + np.log10(xs.max()))
    for name, sp in zip(names, species):  # named beside the star, towards the middle
        right = np.log10(sp.radius_over_length_cubed) > mid
        ax.annotate(name, (sp.radius_over_length_cubed, sp.machin),
                    xytext=(-7 if right else 7, -3), ha="right" if right else "left",
                    textcoords="offset points", fontsize=7, color="darkred", style="italic",
                    zorder=6, bbox=dict(boxstyle="round,pad=0.15", fc="white", ec="none", alpha=0.75))
    xline = np.logspace(np.log10(xs.min()) - 0.15, np.log10(xs.max()) + 0.15, 50)
    ax.plot(xline, PAPER_PREFACTOR / xline, "k-", lw=1.5, label=r"paper: $M_c = 0.06\,(R/L)^{-3}$")
    if brackets:
        first = True
        for b in brackets:
            if b.get("kind") == "bracket":
                ax.plot([b["r_over_l_cubed"]] * 2, [b["m_lo"], b["m_hi"]], "k-", lw=3, alpha=0.35,
                        zorder=2, label="bracket: last stable to first buckled M" if first else None)
                first = False
    if fit is not None:
        if math.isfinite(fit.get("exponent", math.nan)):
            c, be = fit["prefactor"], fit["exponent"]
            ax.plot(xline, c * xline ** (-be / 3), "--", color="tab:red", lw=1.5,
                    label=rf"fit: $M_c = {c:.3g}\,(R/L)^{{-{be:.2f}\pm{fit['exponent_err']:.2f}}}$")
        if math.isfinite(fit.get("prefactor_beta3", math.nan)):
            c3 = fit["prefactor_beta3"]
            ax.plot(xline, c3 / xline, ":", color="tab:red", lw=1.5,
                    label=rf"fit, exponent $-3$: $M_c = {c3:.3g}\,(R/L)^{{-3}}$")
    if stability is not None:
        draw_stability(ax, stability)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel(r"$(R/L)^3$")
    ax.set_ylabel(r"$M = \eta\omega L^4/A$")
    sm = plt.cm.ScalarMappable(norm=norm, cmap=cmap)
    ax.figure.colorbar(sm, ax=ax, label=r"pitch angle $\psi$ [deg]")
    # class symbols in neutral grey in the legend (their colour is psi)
    from matplotlib.lines import Line2D

    handles, labels = ax.get_legend_handles_labels()
    proxy = {"stable": Line2D([], [], ls="", marker="o", mfc="none", mec="0.3"),
             "wrapping": Line2D([], [], ls="", marker="s", mfc="0.3", mec="0.3"),
             "folding": Line2D([], [], ls="", marker="o", mfc="0.3", mec="0.3")}
    handles = [proxy.get(lab, h) for h, lab in zip(handles, labels)]
    ax.legend(handles, labels, fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.12), ncol=3)
    return ax


def species_labels(species) -> list[str]:
    """Short names for the stars: genus initial and species ("S. putrefaciens"), the filament
    form added where one species has two ("C. insecticola (coil)")."""
    short = []
    for sp in species:
        words = sp.name.split()
        short.append(f"{words[0][0]}. {words[1]}" if len(words) >= 2 else sp.name)
    return [f"{n} ({sp.form})" if short.count(n) > 1 else n for n, sp in zip(short, species)]


DEFAULT_STABILITY = "out/stability/fig5.json"
#: ``flagwrap stability examples/sweeps/fig5.toml --sweep --far``: M_c and the far state's
#: fold M_f per helix; read instead of DEFAULT_STABILITY when it exists
DEFAULT_STABILITY_FAR = "out/stability/fig5_far.json"


def load_stability(path):
    """The rows of ``flagwrap stability --sweep`` (None if the file is absent)."""
    import json

    p = Path(path) if path else None
    if p is None or not p.is_file():
        return None
    try:
        return json.loads(p.read_text())
    except (OSError, ValueError) as exc:
        raise UserInputError(f"{p} is not a readable stability result ({exc}); re-create it with "
                             f"`flagwrap stability examples/sweeps/fig5.toml --sweep`") from None


def draw_stability(ax, stab):
    """The linear thresholds (diamonds, red edge; colour = psi) and their power-law fit."""
    import matplotlib.pyplot as plt
    from matplotlib.colors import Normalize

    cmap, norm = plt.get_cmap("viridis"), Normalize(30.0, 72.0)
    pts = [r for r in stab.get("rows", []) if r.get("machin_c")]
    for i, r in enumerate(pts):
        ax.scatter([r["r_over_l"] ** 3], [r["machin_c"]], marker="D", s=34, zorder=5,
                   facecolors=cmap(norm(r["psi_deg"])), edgecolors="tab:red", linewidths=1.2,
                   label="linear M_c (flagwrap stability)" if i == 0 else None)
    folds = [r for r in stab.get("rows", []) if r.get("machin_fold")]
    for i, r in enumerate(folds):
        # the far (wrapped/folded) state's fold: below it every run returns to the whirl
        ax.scatter([r["r_over_l"] ** 3], [r["machin_fold"]], marker="v", s=34, zorder=5,
                   facecolors=cmap(norm(r["psi_deg"])), edgecolors="k", linewidths=1.0,
                   label="far state's fold M_f (flagwrap stability --far)" if i == 0 else None)
        if r.get("machin_c"):
            ax.plot([r["r_over_l"] ** 3] * 2, [r["machin_fold"], r["machin_c"]], color="0.4",
                    lw=0.8, zorder=4)
    fit = stab.get("fit") or {}
    be = fit.get("exponent")  # None (JSON's NaN) when there was nothing to fit
    if pts and be is not None and math.isfinite(be):
        xs = np.array([r["r_over_l"] ** 3 for r in pts])
        xline = np.logspace(np.log10(xs.min()) - 0.1, np.log10(xs.max()) + 0.1, 30)
        c = fit["prefactor"]
        ax.plot(xline, c * xline ** (-be / 3), "-.", color="tab:red", lw=1.2,
                label=rf"linear: $M_c = {c:.3g}\,(R/L)^{{-{be:.2f}}}$")


def fig5(outdir="out/figures", sweep_dirs=None, stability=DEFAULT_STABILITY) -> list:
    """``flagwrap figure fig5``: the diagram from the sweep table (PNG + PDF) and the fit (JSON).

    Reads the rows of out/sweeps/fig5 (or, if it has none, out/sweeps/fig5-quick and
    out/sweeps/fig5-boundary; :func:`load_rows`); writes
    ``fig5.png``, ``fig5.pdf`` and ``fig5.json`` (fit, per-geometry brackets, sources).
    If ``stability`` (out/stability/fig5.json, from ``flagwrap stability
    examples/sweeps/fig5.toml --sweep``) exists, its linear thresholds and their fit are drawn
    beside the time-domain classes and stored in fig5.json under ``stability``; with
    ``--far`` (out/stability/fig5_far.json, read first when it exists) also each helix's far
    state's fold M_f, joined to its M_c: the bistable range of the helix.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from flagwrap.sweep.boundary import brackets_from_rows
    from flagwrap.sweep.store import jsonable, write_json_atomic

    rows, used = load_rows(sweep_dirs)
    brackets = brackets_from_rows(rows)
    fit = fit_boundary(brackets)
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    fig, ax = plt.subplots(figsize=(6.8, 6.4))
    if stability == DEFAULT_STABILITY and Path(DEFAULT_STABILITY_FAR).is_file():
        stability = DEFAULT_STABILITY_FAR
    stab = load_stability(stability)
    diagram(rows, ax=ax, fit=fit, brackets=brackets, stability=stab)
    n_beads = sorted({r.get("n_beads") for r in rows})
    ax.set_title(f"stability diagram, this model ({len(rows)} runs, N = "
                 f"{', '.join(map(str, n_beads))}; {' + '.join(Path(u).name for u in used)})",
                 fontsize=9)
    fig.tight_layout()
    paths = [outdir / "fig5.png", outdir / "fig5.pdf"]
    savefig_atomic(fig, paths[0], dpi=150)
    savefig_atomic(fig, paths[1])
    plt.close(fig)
    counts = {}
    for r in rows:
        counts[classify(r)] = counts.get(classify(r), 0) + 1
    info = {"sources": used, "n_rows": len(rows), "classes": counts, "fit": fit,
            "paper": {"prefactor": PAPER_PREFACTOR, "exponent": 3.0}, "brackets": brackets}
    if stab is not None:
        info["stability"] = {"source": str(stability), "fit": stab.get("fit"),
                             "rows": stab.get("rows")}
    paths.append(write_json_atomic(jsonable(info), outdir / "fig5.json"))
    return [str(p) for p in paths]


def format_fit(fit: dict) -> str:
    """One line: the fitted prefactor and exponent against the paper's 0.06 and 3."""
    return (f"M_c = c (R/L)^-beta: c = {fit['prefactor']:.3g} +- {fit['prefactor_err']:.2g}, "
            f"beta = {fit['exponent']:.3g} +- {fit['exponent_err']:.2g} (paper: 0.06, 3); "
            f"beta = 3 fixed: c = {fit['prefactor_beta3']:.3g} +- {fit['prefactor_beta3_err']:.2g}; "
            f"{fit['n']} geometries with a bracket")

