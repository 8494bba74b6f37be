"""Paper figures, one function per figure; each writes ``NAME.png`` and ``NAME.pdf`` into ``outdir``.

Functions take an output folder and numerical knobs, compute what they plot, and return the
paths written. Headless (Agg backend).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from flagwrap.io.atomic import savefig_atomic

__all__ = ["fig3", "fig4", "fig6", "figS7", "plot_fig4", "plot_fig6", "plot_figS7"]

#: SI stretching-test helix (SI "Uniaxial stretching test of a helix"), lengths [m], E [Pa].
FIG3_HELIX = dict(radius=15e-3, pitch=34e-3, length=305e-3, youngs_modulus=1.2 * 1.33e6, poisson_ratio=0.49)


def _save(fig, outdir: Path, name: str) -> list[Path]:
    outdir.mkdir(parents=True, exist_ok=True)
    paths = [outdir / f"{name}.png", outdir / f"{name}.pdf"]
    savefig_atomic(fig, paths[0], dpi=150)
    savefig_atomic(fig, paths[1])
    return paths


def fig3(outdir: str | Path = "out/figures", *, n_beads: int = 201, n_steps: int = 40,
         long_factor: int = 3, z_over_L_max: float = 0.95) -> list[Path]:
    """Main text Fig. 3(b) / SI Fig. S(HelicalForce): force-extension of the stretched helix.

    Left: pulling force ``F`` [mN] against ``z/L`` for the SI helix (2R = 30 mm, P = 34 mm,
    L = 305 mm, E = 1.2 x 1.33 MPa, nu = 0.49): main text Eq. 1 for the round section
    ``a = 1.5 mm`` with ``z/L = cos psi + F/(pi E a^2)``; the SI's elliptic law
    (``2a = 3.19 mm``, ``2b = 2.88 mm``, derived form, see :mod:`flagwrap.theory.stretching`);
    the quasi-static bead simulation (:func:`flagwrap.elasticity.stretching_test.stretch_helix`, round
    section, moment-free ends pulled by their end points) for the helix itself and for one
    ``long_factor`` times longer (same ``R``, ``P``, more turns; the law does not depend on
    ``L`` at fixed ``z/L``). Right: relative deviation of the bead force from Eq. 1.

    Parameters
    ----------
    outdir : str or Path
        output folder (created).
    n_beads : int
        beads of the L = 305 mm helix (the long one gets ``long_factor (n_beads-1) + 1``).
    n_steps : int
        extension steps from rest to ``z_over_L_max``.
    long_factor : int
        length multiplier of the second simulated helix (0: omit it).

    Returns
    -------
    list of Path
        the PNG and PDF written.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from flagwrap.elasticity.stretching_test import law_force_at_extension, stretch_helix
    from flagwrap.theory.stretching import StretchedHelix

    round_h = StretchedHelix(semi_axis_a=1.5e-3, **FIG3_HELIX)
    ellip_h = StretchedHelix(semi_axis_a=3.19e-3 / 2, semi_axis_b=2.88e-3 / 2, **FIG3_HELIX)
    runs = [(round_h, stretch_helix(round_h, n_beads, z_over_L_max, n_steps))]
    if long_factor and long_factor > 1:
        lh = StretchedHelix(semi_axis_a=1.5e-3, **{**FIG3_HELIX, "length": long_factor * FIG3_HELIX["length"]})
        runs.append((lh, stretch_helix(lh, long_factor * (n_beads - 1) + 1, z_over_L_max, n_steps)))

    psi = np.linspace(np.deg2rad(14.0), round_h.psi0, 400)
    fig, (ax, axd) = plt.subplots(1, 2, figsize=(10, 4.2), constrained_layout=True)
    zr, Fr = round_h.force_extension(psi)
    ax.plot(zr, 1e3 * Fr, "C0-", lw=2, label=f"Eq. 1, round a = 1.5 mm ($A\\kappa_0^2$ = {1e3 * round_h.force_scale:.1f} mN)")
    ze, Fe = ellip_h.force_extension(psi)
    ax.plot(ze, 1e3 * Fe, "C2--", lw=1.5,
            label=f"SI law, elliptic 2a = 3.19, 2b = 2.88 mm ($A_2\\kappa_0^2$ = {1e3 * ellip_h.force_scale:.1f} mN)")
    styles = [("C3o", "full"), ("C1s", "none")]
    for (h, r), (st, fill) in zip(runs, styles):
        lab = f"bead model, L = {1e3 * h.length:.0f} mm ({h.turns:.1f} turns, N = {r.n_beads})"
        ax.plot(r.z_over_L, 1e3 * r.force, st, ms=4, fillstyle=fill, label=lab)
        sel = r.z_over_L > r.z_over_L[0] + 0.02
        dev = (r.force[sel] - law_force_at_extension(h, r.z_over_L[sel])) / law_force_at_extension(h, r.z_over_L[sel])
        axd.plot(r.z_over_L[sel], 100 * dev, st + "-", ms=4, fillstyle=fill, label=lab)
    ax.set_xlabel("extension z/L")
    ax.set_ylabel("pulling force F [mN]")
    ax.set_xlim(0.3, 1.0)
    ax.set_ylim(bottom=-1.0)
    ax.legend(fontsize=7, loc="upper left")
    ax.set_title("Fig. 3(b): stretching with moment-free ends", fontsize=10)
    for y in (-3, 3):
        axd.axhline(y, color="0.6", lw=0.8, ls=":")
    axd.axhline(0, color="C0", lw=1)
    axd.axvline(0.9, color="0.6", lw=0.8, ls=":")
    axd.set_xlabel("extension z/L")
    axd.set_ylabel("(F$_{bead}$ - F$_{Eq. 1}$) / F$_{Eq. 1}$ [%]")
    axd.set_xlim(0.3, 1.0)
    axd.legend(fontsize=7, loc="lower right")
    axd.set_title("deviation from Eq. 1 (finite length: ends on the force line)", fontsize=10)
    paths = _save(fig, Path(outdir), "fig3")
    plt.close(fig)
    return paths


# --- issue 4: Fig. 4(c-e), Fig. 6, SI Fig. S7(a) ------------------------------------------------
# Pure plotting of run datasets (flagwrap.io.runfile.read_run); the runs themselves come from
# flagwrap.analysis.paper_runs (cached; `flagwrap figure fig4|fig6|figS7` runs what is missing).
# omega/omega_c is relative to THIS model's measured omega_c (docs/critical.md), not the paper's.


def _mpl():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def save_png_pdf(fig, stem):
    """Write ``stem.png`` (150 dpi) and ``stem.pdf``; return both paths."""
    from pathlib import Path

    stem = Path(stem)
    stem.parent.mkdir(parents=True, exist_ok=True)
    out = []
    for ext in ("png", "pdf"):
        p = stem.with_suffix(f".{ext}")
        savefig_atomic(fig, p, dpi=150)
        out.append(p)
    return out


def _after_switch(ds):
    """``t/T - t_s/T`` and the switch index of a CCW -> CW run."""
    from flagwrap.analysis.buckling import find_switch

    turns = ds["turns"].values
    i = find_switch(turns, ds["omega"].values)
    t_s = turns[i - 1] if i > 0 else turns[0]
    return turns - t_s, i


def _height(ds):
    from flagwrap.observables.tip import free_end_height

    return free_end_height(ds["position"].values, float(ds.attrs["length"]))


def plot_fig4(runs, path=None):
    """Paper Fig. 4(c)-(e) for the Fig. 4(a) helix at two speeds, with and without HI.

    Parameters
    ----------
    runs : dict
        ``{(omega_ratio, hydrodynamics): dataset}``; ``omega_ratio = omega / omega_c`` of this
        model (e.g. 0.85 and 2.05), ``hydrodynamics`` a bool. Missing entries are skipped.
    path : path-like, optional
        stem: writes ``path.png`` and ``path.pdf``.

    Panels: (c) reduced motor torque ``N_m R / A`` against ``t/T`` (CCW > 0; the CCW -> CW switch
    at 10 T); (d) free-end height ``[z(L) - z(0)]/L`` at the largest ratio with and without HI;
    (e) 3D trajectory of the free end relative to the clamp, ``[r(L) - r(0)]/L``, for the largest
    ratio with HI, coloured by time after the switch.
    """
    plt = _mpl()
    fig = plt.figure(figsize=(13, 4.2))
    ac = fig.add_subplot(1, 3, 1)
    ad = fig.add_subplot(1, 3, 2)
    ae = fig.add_subplot(1, 3, 3, projection="3d")
    ratios = sorted({r for r, _ in runs})
    colors = {r: f"C{k}" for k, r in enumerate(ratios)}
    for (ratio, hi), ds in sorted(runs.items(), key=lambda kv: (kv[0][0], not kv[0][1])):
        ls = "-" if hi else "--"
        lab = rf"$\omega/\omega_c$ = {ratio:g}, {'with' if hi else 'without'} HI"
        ac.plot(ds["turns"].values, ds["motor_torque_reduced"].values, ls, color=colors[ratio], lw=1, label=lab)
        if ratio == ratios[-1]:
            ad.plot(ds["turns"].values, _height(ds), ls, color="k" if hi else "C3", lw=1,
                    label=f"{'with' if hi else 'without'} HI")
    t_sw = [float(ds["turns"].values[_after_switch(ds)[1] - 1]) for ds in runs.values()][:1]
    for ax in (ac, ad):
        ax.set_xlabel(r"$t/T$ [motor turns] (dotted: CCW$\to$CW switch)")
        for t in t_sw:
            ax.axvline(t, color="0.6", lw=0.8, ls=":")
    ac.axhline(0, color="0.6", lw=0.6)
    ac.set_ylabel(r"motor torque $N_m R/A$ (CCW > 0) [1]")
    ac.set_title("(c) motor torque")
    ac.legend(fontsize=7)
    ad.set_ylabel(r"free-end height $[z(L)-z(0)]/L$ [1]")
    ad.set_title(rf"(d) free end, $\omega/\omega_c$ = {ratios[-1]:g}" if ratios else "(d)")
    ad.legend(fontsize=8)
    key = (ratios[-1], True) if ratios and (ratios[-1], True) in runs else next(iter(runs), None)
    if key is not None:
        ds = runs[key]
        from flagwrap.observables.tip import tip_trajectory

        tip = tip_trajectory(ds["position"].values, float(ds.attrs["length"]))
        ts, i = _after_switch(ds)
        sel = slice(max(i - 1, 0), None)
        ae.plot(tip[:max(i, 1), 0], tip[:max(i, 1), 1], tip[:max(i, 1), 2], color="0.7", lw=0.6, label="CCW")
        sc = ae.scatter(tip[sel, 0], tip[sel, 1], tip[sel, 2], c=ts[sel], cmap="viridis", s=3)
        fig.colorbar(sc, ax=ae, shrink=0.6, pad=0.1, label=r"$(t - t_s)/T$ after switch")
        ae.set_title(rf"(e) free end, $\omega/\omega_c$ = {key[0]:g}, {'with' if key[1] else 'without'} HI", fontsize=9)
    ae.set_xlabel(r"$x/L$")
    ae.set_ylabel(r"$y/L$")
    ae.set_zlabel(r"$z/L$")
    fig.tight_layout()
    if path is not None:
        save_png_pdf(fig, path)
    return fig


def plot_fig6(eps, waiting_time, fit=None, path=None, waiting_time_err=None, c_line=0.5, title="",
              crossing=None, departure=None):
    """Paper Fig. 6: waiting time ``t_c/T`` against ``eps = (omega - omega_c)/omega_c``.

    Parameters
    ----------
    eps, waiting_time : array_like, shape (K,)
        runs that buckled (NaN entries are skipped).
    fit : flagwrap.analysis.waiting_time.PowerLawFit, optional
        drawn as a line with its ``c``, ``beta`` in the legend.
    waiting_time_err : array_like, optional
        error bars of ``t_c/T``.
    c_line : float
        the paper's line ``c_line / eps`` (0.5).
    crossing : array_like, optional
        threshold-crossing times ``(t_x - t_s)/T`` of the same runs (open squares): an upper
        bound of the onset, robust where the rise is oscillatory.
    departure : array_like, optional
        departure times ``(t_d - t_s)/T`` (1-turn mean 0.05 L above the CCW baseline, no hold;
        :func:`flagwrap.analysis.waiting_time.departure_time`), open triangles.

    Main axes linear (as the paper), inset log-log.
    """
    plt = _mpl()
    e = np.asarray(eps, float)
    t = np.asarray(waiting_time, float)
    ok = np.isfinite(e) & np.isfinite(t) & (e > 0)
    fig, ax = plt.subplots(figsize=(5.5, 5.2))
    grid = np.geomspace(max(min(e[ok].min(), 0.05) * 0.8, 1e-3), max(e[ok].max(), 2.0) * 1.1, 200) if ok.any() \
        else np.geomspace(0.04, 2.2, 200)
    ins = ax.inset_axes([0.52, 0.48, 0.44, 0.46])
    for a in (ax, ins):
        err = None if waiting_time_err is None else np.asarray(waiting_time_err, float)[ok]
        a.errorbar(e[ok], t[ok], yerr=err, fmt="o", color="k", ms=4, label=r"flagwrap $t_c$ (onset fit)")
        if crossing is not None:
            cx = np.asarray(crossing, float)
            okx = np.isfinite(cx) & (e > 0) & (cx > 0)
            a.plot(e[okx], cx[okx], "s", mfc="none", mec="C2", ms=5, label=r"flagwrap $t_x$ (0.15 L crossing)")
        if departure is not None:
            dp = np.asarray(departure, float)
            okd = np.isfinite(dp) & (e > 0) & (dp > 0)
            a.plot(e[okd], dp[okd], "^", mfc="none", mec="C4", ms=5, label=r"flagwrap $t_d$ (0.05 L departure)")
        a.plot(grid, c_line / grid, "--", color="C0", label=rf"paper: ${c_line:g}/\epsilon$")
        if fit is not None:
            a.plot(grid, fit.predict(grid), "-", color="C3",
                   label=rf"fit: $({fit.c:.2f}\pm{fit.c_err:.2f})\,\epsilon^{{-({fit.beta:.2f}\pm{fit.beta_err:.2f})}}$")
    ins.set_xscale("log")
    ins.set_yscale("log")
    ins.tick_params(labelsize=7)
    ax.axhline(1.0, color="0.7", lw=0.6, ls=":")
    ax.axvline(1.0, color="0.7", lw=0.6, ls=":")
    ax.set_xlabel(r"$\epsilon = (\omega-\omega_c)/\omega_c$ [1] ($\omega_c$ of this model)")
    ax.set_ylabel(r"waiting time $t_c/T$ [motor turns]")
    top = np.nanmax(t[ok]) if ok.any() else 10.0
    if crossing is not None and np.isfinite(np.asarray(crossing, float)).any():
        top = max(top, np.nanmax(np.asarray(crossing, float)))
    ax.set_ylim(0, 1.15 * max(top, 1.0))
    ax.set_xlim(0, grid.max())
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.14), ncol=2, fontsize=7)
    if title:
        ax.set_title(title, fontsize=9)
    fig.tight_layout()
    if path is not None:
        save_png_pdf(fig, path)
    return fig


def plot_figS7(runs, path=None, title=""):
    """SI Fig. S7(a): free-end height against time after the switch for several speeds, ``t_c`` marked.

    Parameters
    ----------
    runs : list of (omega_ratio, dataset, t_c) tuples
        ``t_c/T`` after the switch (NaN: not buckled, nothing marked).
    """
    plt = _mpl()
    fig, ax = plt.subplots(figsize=(6, 4.2))
    for k, (ratio, ds, tc) in enumerate(sorted(runs, key=lambda r: r[0])):
        ts, i = _after_switch(ds)
        h = _height(ds)
        sel = ts >= -1.0
        ax.plot(ts[sel], h[sel], color=f"C{k}", lw=1, label=rf"$\omega/\omega_c$ = {ratio:.3g}")
        if np.isfinite(tc):
            j = int(np.argmin(np.abs(ts - tc)))
            ax.plot(ts[j], h[j], "v", color=f"C{k}", ms=8, mec="k")
    ax.axvline(0, color="0.6", lw=0.8, ls=":")
    ax.set_xlabel(r"$(t - t_s)/T$ after the CCW$\to$CW switch [motor turns]")
    ax.set_ylabel(r"free-end height $[z(L)-z(0)]/L$ [1]")
    ax.set_title(r"SI Fig. S7(a) ($\blacktriangledown$ = $t_c$) " + title, fontsize=9)
    ax.legend(fontsize=7)
    fig.tight_layout()
    if path is not None:
        save_png_pdf(fig, path)
    return fig


def _geometry_title(root, mc):
    from flagwrap.analysis import paper_runs

    fil = paper_runs._config(paper_runs.FIG6_GEOMETRY, root).filament
    return rf"$\psi$ = {fil.pitch_angle_deg:.0f}$^\circ$, n = {fil.turns:g}, this model's $M_c$ = {mc:.0f}"


def _n_fittable(times) -> int:
    """Times a power-law fit uses: finite and > 0 (PowerLawFit drops t_c = 0, which a run
    buckled at the switch has)."""
    t = np.asarray(times, dtype=float)
    return int((np.isfinite(t) & (t > 0)).sum())


def _fig6_data(root=None, on_run=None):
    """Critical search of :data:`flagwrap.analysis.paper_runs.FIG6_GEOMETRY`, the sweep, the fit."""
    from flagwrap.analysis import paper_runs
    from flagwrap.analysis.waiting_time import PowerLawFit

    report = on_run or (lambda *a: None)
    mc = paper_runs.critical(paper_runs.FIG6_GEOMETRY, root=root,
                             on_run=lambda r: report("critical search", r)).machin_c
    rows = paper_runs.fig6_runs(mc, on_run=lambda eps, r: report(f"eps = {eps:g}", r), root=root)
    eps = np.array([r["eps"] for r in rows])
    tc = np.array([r["waiting_time"] for r in rows])
    fit = PowerLawFit().compute(eps, tc) if _n_fittable(tc) >= 3 else None
    return mc, rows, eps, tc, fit


def fig4(outdir: str | Path = "out/figures", root=None, on_run=None) -> list[Path]:
    """Fig. 4(c)-(e) from the cached runs of :func:`flagwrap.analysis.paper_runs.fig4_runs`
    (the critical search of the Fig. 4(a) helix and the four runs are made if missing).
    ``on_run(label, CriticalRun)`` is called for every run as it is known."""
    from flagwrap.analysis import paper_runs
    from flagwrap.io.runfile import read_run

    report = on_run or (lambda *a: None)
    search = paper_runs.critical("fig4a", root=root, on_run=lambda r: report("critical search", r))
    mc = search.machin_c
    files = paper_runs.fig4_runs(mc, root=root, on_run=lambda k, r: report(
        f"omega/omega_c = {k[0]:g}, HI {'on' if k[1] else 'off'}", r))
    runs = {k: read_run(p) for k, p in files.items()}
    fig = plot_fig4(runs)
    paths = _save(fig, Path(outdir), "fig4")
    _mpl().close(fig)
    numbers = {"machin_c": mc, "bracket": list(search.bracket),
               "runs": [{"omega_ratio": r, "file": str(files[(r, hi)]),
                         **paper_runs.torque_summary(runs[(r, hi)])} for r, hi in sorted(runs)]}
    paths.append(_write_json(numbers, Path(outdir) / "fig4.json"))
    return paths


def _write_json(obj, path: Path) -> Path:
    import json
    import math

    def clean(v):
        if isinstance(v, float) and math.isnan(v):
            return None
        if isinstance(v, dict):
            return {k: clean(x) for k, x in v.items()}
        if isinstance(v, (list, tuple)):
            return [clean(x) for x in v]
        if isinstance(v, np.generic):
            return clean(v.item())
        return v

    path.parent.mkdir(parents=True, exist_ok=True)
    from flagwrap.io.atomic import atomic_write

    text = json.dumps(clean(obj), indent=1, sort_keys=True)
    atomic_write(path, lambda tmp: tmp.write_text(text))
    return path


def fig6(outdir: str | Path = "out/figures", root=None, on_run=None) -> list[Path]:
    """Fig. 6 (waiting time against eps, 0.5/eps, fit, log-log inset) from cached sweep runs."""
    from flagwrap.analysis.waiting_time import PowerLawFit

    mc, rows, eps, tc, fit = _fig6_data(root, on_run)
    from flagwrap.analysis.waiting_time import departure_time
    from flagwrap.io.runfile import read_run

    cross = np.array([r["crossing"] for r in rows])
    depart = np.array([departure_time(read_run(r["path"])) for r in rows])
    for r, d in zip(rows, depart):
        r["departure"] = float(d)
    fig = plot_fig6(eps, tc, fit, title=_geometry_title(root, mc), crossing=cross, departure=depart)
    paths = _save(fig, Path(outdir), "fig6")
    _mpl().close(fig)
    fits = {}
    n_ok = _n_fittable(tc)
    if fit is not None:
        fits["free_beta"] = fit.summary()
    if n_ok >= 2:
        fits["beta_1"] = PowerLawFit(fix_beta=1.0).compute(eps, tc).summary()
    if _n_fittable(cross) >= 3:
        fits["crossing_free_beta"] = PowerLawFit().compute(eps, cross).summary()
    if _n_fittable(depart) >= 3:
        fits["departure_free_beta"] = PowerLawFit().compute(eps, depart).summary()
    if n_ok >= 4:
        m = np.array([r["machin"] for r in rows])
        try:
            fits["free_beta_free_Mc"] = PowerLawFit().compute(waiting_time=tc, machin=m, machin_c0=mc).summary()
        except Exception as exc:  # report, do not fail the figure
            fits["free_beta_free_Mc"] = {"error": str(exc)}
    paths.append(_write_json({"machin_c": mc, "rows": rows, "fits": fits}, Path(outdir) / "fig6.json"))
    return paths


def figS7(outdir: str | Path = "out/figures", root=None, on_run=None) -> list[Path]:
    """SI Fig. S7(a) (free-end height for several omega, t_c marked) from the Fig. 6 sweep runs."""
    from flagwrap.io.runfile import read_run

    mc, rows, _, _, _ = _fig6_data(root, on_run)
    runs = [(r["omega_ratio"], read_run(r["path"]), r["waiting_time"]) for r in rows]
    fig = plot_figS7(runs, title=_geometry_title(root, mc))
    paths = _save(fig, Path(outdir), "figS7")
    _mpl().close(fig)
    return paths
