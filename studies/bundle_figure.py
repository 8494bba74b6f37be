"""The bundle's separation and each flagellum's free-end height against time, for the run
files of studies/bundle_vs_equivalent.py (docs/bundle.md's figure).

    python studies/bundle_figure.py RUN.nc [RUN.nc ...] -o docs/img/bundle_separation.png

Top: the separation of the centroids of the flagella's last helical turns in helix radii
(< 1: bundled,
:mod:`flagwrap.observables.bundle`), one line per run of several flagella. Bottom: the free
end's height in the body's frame, (z(L) - z(0))/L, of every flagellum of every run (one
flagellum runs included), against motor turns; the CCW -> CW switch dotted.
"""

from __future__ import annotations

import argparse
from pathlib import Path


def main(argv=None) -> int:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    from flagwrap.io.atomic import savefig_atomic
    from flagwrap.io.runfile import config_of, filament_slices, read_run
    from flagwrap.observables.bundle import bundle_separation, last_turn
    from flagwrap.observables.swimming import body_frame
    from flagwrap.observables.tip import free_end_heights

    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("runs", nargs="+")
    p.add_argument("-o", "--output", default="out/bundle_separation.png")
    args = p.parse_args(argv)
    fig, (a1, a2) = plt.subplots(2, 1, figsize=(7, 6), sharex=True)
    for k, path in enumerate(args.runs):
        ds = read_run(path)
        cfg = config_of(ds)
        x = ds["position"].values
        if "body_position" in ds.variables:
            x = body_frame(x, ds["body_position"].values, ds["body_orientation"].values)
        turns = ds["turns"].values
        sl = filament_slices(ds)
        label = Path(path).stem.replace("p_putida_bundle_", "")
        if len(sl) > 1:
            fil = cfg.filament
            a1.plot(turns, bundle_separation(x, sl, fil.helix_radius, last_turn(
                fil.helix_radius, fil.pitch, fil.length)), color=f"C{k}", label=label)
        h = free_end_heights(x, float(ds.attrs["length"]), sl)
        for j in range(h.shape[1]):
            a2.plot(turns, h[:, j], color=f"C{k}", lw=0.8, alpha=1.0 if j == 0 else 0.5,
                    label=label if j == 0 else None)
        cw = np.nonzero(ds["omega"].values < 0)[0]
        if len(cw):
            for ax in (a1, a2):
                ax.axvline(turns[cw[0]], color="0.5", ls=":", lw=0.8)
    a1.axhline(1.0, color="0.6", ls="--", lw=0.8)
    a1.set_ylabel("separation / R\n(last-turn centroids)")
    a1.set_yscale("log")
    a1.legend(fontsize=8)
    a2.set_ylabel("free-end height (body frame) / L")
    a2.set_xlabel("motor turns t/T")
    a2.legend(fontsize=8)
    fig.tight_layout()
    out = Path(args.output)
    out.parent.mkdir(parents=True, exist_ok=True)
    savefig_atomic(fig, out, dpi=130)
    print(f"wrote {out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
