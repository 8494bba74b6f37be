"""A rigid sphere on the axis of a blob tube against Haberman & Sayre's wall-correction factor
(docs/confinement.md, "Tubes"): the table of the blob tube's convergence.

    python studies/tube_haberman_sayre.py --spacing 0.2 0.1 --length 4 8 [--ratio 1.0]
                                          [--open] [--lam 0.1 0.2 0.3 0.4 0.5 0.6]

Tube radius R_t = 1, blobs ``--spacing`` apart with radii ``--ratio`` times it, length
``--length`` (closed by discs unless ``--open``); the sphere is a 162-blob icosphere of
geometric radius ``--lam`` (blob radius half its spacing), its radius ``a`` its own
free-space drag radius. One line per case: a/R_t, K = F / (6 pi a U), Haberman & Sayre's K,
the relative error, the number of tube blobs and seconds.
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np
from scipy.spatial import cKDTree

from flagwrap.body.multiblob import effective_radii, icosphere
from flagwrap.confinement.tube import Tube, rigid_body_drag
from flagwrap.theory.wall_drag import haberman_sayre


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--spacing", type=float, nargs="+", default=[0.2, 0.1])
    ap.add_argument("--length", type=float, nargs="+", default=[4.0])
    ap.add_argument("--ratio", type=float, default=1.0)
    ap.add_argument("--open", action="store_true")
    ap.add_argument("--lam", type=float, nargs="+", default=[0.1, 0.2, 0.3, 0.4, 0.5, 0.6])
    ap.add_argument("--level", type=int, default=2)
    args = ap.parse_args()
    u = icosphere(args.level)
    d, _ = cKDTree(u).query(u, k=2)
    print(f"{'spacing':>7} {'ratio':>5} {'length':>6} {'ends':>6} {'a/R_t':>6} {'K':>8} "
          f"{'HS':>8} {'error':>7} {'blobs':>6} {'s':>6}")
    for h in args.spacing:
        for length in args.length:
            t = Tube(1.0, length, closed=not args.open)
            tb = t.blob_shell(h, args.ratio * h)
            for lam in args.lam:
                ab = 0.5 * lam * d[:, 1].mean()
                sb = lam * u
                a = effective_radii(sb, ab)[0]
                t0 = time.perf_counter()
                F = rigid_body_drag(tb, args.ratio * h, sb, ab, (0.0, 0.0, 1.0))
                K = -F[2] / (6 * math.pi * a)
                hs = haberman_sayre(a)
                print(f"{h:7.3f} {args.ratio:5.2f} {length:6.1f} "
                      f"{'open' if args.open else 'closed':>6} {a:6.4f} {K:8.4f} {hs:8.4f} "
                      f"{K / hs - 1:+7.2%} {len(tb):6d} {time.perf_counter() - t0:6.1f}",
                      flush=True)


if __name__ == "__main__":
    main()
