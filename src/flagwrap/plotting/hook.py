"""``flagwrap figure hook``: M_c and the final state against the hook's stiffness (docs/hook.md).

Reads the sweeps of examples/sweeps/hook.toml (boundary search of ``M_c`` per helix and hook
stiffness ``k_h = A_h L/(A l_h)``, the clamp as ``k_h = None``) and, if present,
examples/sweeps/hook-grid.toml (every helix and joint at M = 1, 2, 4, 8 x the paper's scaling
line: the state map). Panel (a): ``M_c`` against ``k_h`` per helix, the clamp's ``M_c`` as a
dashed line, the bacterial range of ``k_h`` shaded. Panel (b): stable / folding / wrapping at
each (k_h, M / M_c of the clamp). Writes ``hook.png``, ``hook.pdf`` and ``hook.json``.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from flagwrap.errors import UserInputError
from flagwrap.io.atomic import savefig_atomic

BOUNDARY_SWEEP = "out/sweeps/hook"
GRID_SWEEP = "out/sweeps/hook-grid"
#: k_h of bacterial hooks, A_h = 1e-26 .. 1e-25 N m^2 over l_h = 55 nm, for a filament of
#: A = 3.5 pN um^2 and L = 7 um (docs/hook.md, "Bacterial values")
BACTERIAL_KH = (1e-26 * 7e-6 / (3.5e-24 * 55e-9), 1e-25 * 7e-6 / (3.5e-24 * 55e-9))


def _helix(r) -> tuple:
    return (round(float(r["psi_deg"]), 3), round(float(r["turns"]), 3))


def boundary_table(sweep_dir=BOUNDARY_SWEEP) -> list[dict]:
    """Per helix and joint: ``machin_c`` (None unless bracketed), ``m_lo``, ``m_hi``, ``kind``,
    and the states of the search's test runs (``runs``: machin, buckled, state)."""
    from flagwrap.sweep.boundary import summary_bracket
    from flagwrap.sweep.store import SweepStore

    out = []
    for b in SweepStore(sweep_dir).boundaries():
        out.append({"psi_deg": b["psi_deg"], "turns": b["turns"], "r_over_l": b["r_over_l"],
                    "hook_stiffness": b.get("hook_stiffness"), **summary_bracket(b),
                    "status": b.get("status"),
                    "runs": sorted(b.get("runs") or [], key=lambda r: r["machin"])})
    return sorted(out, key=lambda r: (_helix(r), -(r["hook_stiffness"] or math.inf)))


def state_rows(sweep_dir=GRID_SWEEP) -> list[dict]:
    """The grid sweep's finished rows: helix, ``hook_stiffness``, ``machin``, ``state``."""
    from flagwrap.sweep.store import SweepStore

    if not Path(sweep_dir).is_dir():
        return []
    rows = [r for r in SweepStore(sweep_dir).iter_rows() if r.get("status") == "ok"]
    return [{"psi_deg": r["psi_deg"], "turns": r["turns"], "r_over_l": r["r_over_l"],
             "hook_stiffness": r.get("hook_stiffness"), "machin": r["machin"],
             "state": r.get("state"), "buckled": r.get("buckled"),
             "waiting_time_turns": r.get("waiting_time_turns")} for r in rows]


def hook_figure(outdir, boundary_dir=BOUNDARY_SWEEP, grid_dir=GRID_SWEEP) -> list[Path]:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    table = boundary_table(boundary_dir) if Path(boundary_dir).is_dir() else []
    if not table:
        raise UserInputError(f"no hook sweep results in {boundary_dir}: run `flagwrap sweep "
                             "examples/sweeps/hook.toml` first")
    grid = state_rows(grid_dir)
    helices = sorted({_helix(r) for r in table})
    clamp_mc = {_helix(r): r["machin_c"] for r in table if r["hook_stiffness"] is None}
    colors = dict(zip(helices, ("C0", "C1", "C2", "C3", "C4")))
    fig, axes = plt.subplots(1, 1 + len(helices), figsize=(4.2 * (1 + len(helices)), 4.0),
                             gridspec_kw={"width_ratios": [1.4] + [1.0] * len(helices)})
    ax = axes[0]
    ax.axvspan(*BACTERIAL_KH, color="0.9", zorder=0, label="bacterial hooks")
    for h in helices:
        rs = [r for r in table if _helix(r) == h and r["hook_stiffness"] is not None]
        rl = rs[0]["r_over_l"] if rs else float("nan")
        lab = f"psi {h[0]:.3g}, n {h[1]:g} (R/L {rl:.3f})"
        k = np.array([r["hook_stiffness"] for r in rs if r["machin_c"] is not None])
        m = np.array([r["machin_c"] for r in rs if r["machin_c"] is not None])
        err = np.array([[r["machin_c"] - r["m_lo"], r["m_hi"] - r["machin_c"]]
                        for r in rs if r["machin_c"] is not None]).T
        if len(k):
            ax.errorbar(k, m, yerr=err if err.size else None, fmt="o-", color=colors[h], label=lab)
        for r in rs:
            if r["machin_c"] is None and r["m_lo"] is not None:
                ax.plot([r["hook_stiffness"]], [r["m_lo"]], "^", color=colors[h])
        if clamp_mc.get(h):
            ax.axhline(clamp_mc[h], color=colors[h], ls="--", lw=1)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlim(0.02, 200)
    ax.set_xlabel(r"hook stiffness $k_h = A_h L / (A\,l_h)$")
    ax.set_ylabel(r"$M_c$")
    ax.set_title("(a) threshold; dashed: the clamp")
    ax.legend(fontsize=7)
    markers = {"stable": ("o", "none"), "folding": ("o", None), "wrapping": ("s", None)}
    for ax, h in zip(axes[1:], helices):
        ref = clamp_mc.get(h)
        pts = [r for r in grid if _helix(r) == h] or [
            {"hook_stiffness": r["hook_stiffness"], **run} for r in table if _helix(r) == h
            for run in r["runs"]]
        for p in pts:
            kh = p["hook_stiffness"]
            x = 1e3 if kh is None else kh
            y = p["machin"] / ref if ref else p["machin"]
            mk, face = markers.get(p.get("state"), ("x", None))
            ax.plot([x], [y], mk, color=colors[h], mfc=face if face else colors[h], ms=7)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlim(0.02, 3e3)
        ax.set_title(f"(b) psi {h[0]:.3g}, n {h[1]:g}: o stable, ● fold, ■ wrap", fontsize=8)
        ax.set_xlabel(r"$k_h$ (1e3: the clamp)")
        ax.set_ylabel(r"$M / M_c^{clamp}$" if ref else "M")
        if ref:
            ax.axhline(1.0, color="0.6", lw=0.8)
    fig.tight_layout()
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    paths = []
    for ext in ("png", "pdf"):
        p = outdir / f"hook.{ext}"
        savefig_atomic(fig, p, dpi=150)
        paths.append(p)
    plt.close(fig)
    from flagwrap.sweep.store import write_json_atomic

    jpath = outdir / "hook.json"
    write_json_atomic({"boundary": table, "grid": grid, "bacterial_kh": BACTERIAL_KH}, jpath)
    paths.append(jpath)
    return paths
