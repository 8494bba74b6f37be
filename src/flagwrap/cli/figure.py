"""Draw a paper figure (PNG + PDF) into an output folder.

Figures (registry FIGURES, extended as figures are added):
  fig3  force-extension of the stretched helix: Eq. 1, the SI elliptic law and the
        quasi-static bead simulation with moment-free ends (main text Fig. 3(b))
  fig4  torque (c), free-end height with/without HI (d), 3D tip path (e) of the Fig. 4(a)
        helix at omega/omega_c = 0.85, 2.05 (this model's omega_c; docs/critical.md)
  fig5  stability diagram (R/L)^3 vs M from the sweep table (flagwrap sweep
        examples/sweeps/fig5.toml or fig5-quick.toml), scaling line 0.06 and our fit, bacteria
  fig6  waiting time t_c/T against eps with 0.5/eps, the fit and a log-log inset (the
        Fig. 4(a) helix, n = 2: flagwrap.analysis.paper_runs.FIG6_GEOMETRY)
  figS7 free-end height for several omega with t_c marked (SI Fig. S7(a), same helix)
  gravity  M_c of the Fig. 4(a) helix against the buoyancy G (flagwrap sweep
        examples/sweeps/gravity-fig4a.toml), its static rise at M = 0, and the Fig. 5 fit per
        density mismatch (examples/sweeps/gravity-fig5.toml); docs/gravity.md
  hook  M_c against the hook stiffness for three helices, and their final states
        (flagwrap sweep examples/sweeps/hook.toml and hook-grid.toml); docs/hook.md

Example::

    flagwrap figure fig3 -o out/figures
"""

from __future__ import annotations

import argparse

def _fig3(outdir):
    from flagwrap.plotting.figures import fig3

    return fig3(outdir)


def _fig5(outdir):
    from flagwrap.plotting.diagram import fig5

    return fig5(outdir)


def _gravity(outdir):
    from flagwrap.plotting.gravity import gravity_figure

    return gravity_figure(outdir)


def _hook(outdir):
    from flagwrap.plotting.hook import hook_figure

    return hook_figure(outdir)


def _show_run(label, r):
    print(f"  {label:<28} M = {r.machin:9.2f}  {'BUCKLED' if r.buckled else 'stable ':7s}  "
          f"{'reused' if r.reused else 'simulated'}", flush=True)


def _paper(name):
    def build(outdir):
        from flagwrap.plotting import figures

        return getattr(figures, name)(outdir, on_run=_show_run)

    return build


#: what each figure computes (printed before it starts, and by --dry-run)
PLANS = {
    "fig3": "the quasi-static stretching of the Fig. 3 helix (seconds)",
    "fig4": "the critical search of the Fig. 4(a) helix (cache out/critical), then 4 full runs at "
            "0.85 and 2.05 x its omega_c, HI on and off (cache out/paper)",
    "fig6": "the critical search of the Fig. 4(a) helix (cache out/critical), then 5 runs at "
            "eps = 0.1 .. 2 above it (cache out/waiting)",
    "figS7": "the same runs as fig6 (cache out/critical, out/waiting)",
    "fig5": "nothing: drawn from the sweep rows in out/sweeps/fig5 (or fig5-quick + fig5-boundary)",
    "gravity": "the static equilibria of the Fig. 4(a) helix (~40 s); the rest from the sweep rows "
               "in out/sweeps/gravity-fig4a and gravity-fig5",
    "hook": "nothing: drawn from the sweep rows in out/sweeps/hook (and hook-grid if present)",
}
#: sweep folders a figure is drawn from (names of shipped sweeps: `flagwrap sweep NAME`)
SWEEPS = {"fig5": ("fig5", "fig5-quick", "fig5-boundary"),
          "gravity": ("gravity-fig4a", "gravity-fig5"), "hook": ("hook", "hook-grid")}
#: cache folders a figure reads its runs from
CACHES = {"fig4": ("out/critical", "out/paper"), "fig6": ("out/critical", "out/waiting"),
          "figS7": ("out/critical", "out/waiting")}


# figure name -> callable(outdir) -> list of written paths (import heavy modules inside it)
FIGURES = {
    "fig3": _fig3,
    # issue 4: built from cached runs (out/critical, out/paper, out/waiting); missing runs are made
    "fig4": _paper("fig4"),
    "fig6": _paper("fig6"),
    "figS7": _paper("figS7"),
    # issue 5: stability diagram from the sweep rows (out/sweeps/fig5, else fig5-quick)
    "fig5": _fig5,
    # issue 18: the threshold against the buoyancy, from the gravity sweeps
    "gravity": _gravity,
    # issue 15: the threshold and the final state against the hook's stiffness
    "hook": _hook,
}


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("name", choices=sorted(FIGURES), metavar="NAME", help=f"figure: {', '.join(sorted(FIGURES))}")
    p.add_argument("-o", "--outdir", default="out/figures", help="output folder (default out/figures)")
    p.add_argument("--dry-run", action="store_true",
                   help="say what the figure would compute and which cached runs exist; run nothing")


def run(args: argparse.Namespace) -> int:
    from pathlib import Path

    from flagwrap.io.outputs import check_output_dir

    check_output_dir(args.outdir, "figure folder (-o)")
    cached = ", ".join(f"{d}: {len(list(Path(d).glob('*.nc')))} cached runs" for d in CACHES.get(args.name, ()))
    print(f"figure {args.name}: {PLANS[args.name]}" + (f" [{cached}]" if cached else "")
          + ("; a run not cached takes ~40 s" if args.name in CACHES else ""), flush=True)
    if args.name in SWEEPS:  # which sweep results exist, and how to make those that do not
        for name in SWEEPS[args.name]:
            rows = Path("out/sweeps") / name / "rows"
            n = len(list(rows.glob("*.json"))) if rows.is_dir() else 0
            print(f"  out/sweeps/{name}: " + (f"{n} rows" if n else
                  f"no results (make them with `flagwrap sweep {name}`, a shipped sweep; "
                  f"`--dry-run` prices it)"), flush=True)
    if args.dry_run:
        return 0
    try:
        paths = FIGURES[args.name](args.outdir)
    except KeyboardInterrupt:
        import sys

        print(f"flagwrap figure: interrupted; the runs finished so far are cached and are reused "
              f"by the next `flagwrap figure {args.name}`", file=sys.stderr)
        return 130
    for path in paths:
        print(path)
    return 0
