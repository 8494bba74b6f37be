"""Draw a paper figure (PNG + PDF) into an output folder.

Figures (registry FIGURES, extended as figures are added):
  fig3  force-extension of the stretched helix: Eq. 1, the SI elliptic law and the
        quasi-static bead simulation with moment-free ends (main text Fig. 3(b))

Example::

    flagwrap figure fig3 -o out/figures
"""

from __future__ import annotations

import argparse

def _fig3(outdir):
    from flagwrap.plotting.figures import fig3

    return fig3(outdir)


# figure name -> callable(outdir) -> list of written paths (import heavy modules inside it)
FIGURES = {
    "fig3": _fig3,
}


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("name", choices=sorted(FIGURES), metavar="NAME", help=f"figure: {', '.join(sorted(FIGURES))}")
    p.add_argument("-o", "--outdir", default="out/figures", help="output folder (default out/figures)")


def run(args: argparse.Namespace) -> int:
    for path in FIGURES[args.name](args.outdir):
        print(path)
    return 0
