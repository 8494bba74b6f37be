"""Segment crossings of the buckled Fig. 4(a) case with and without filament self-contact
(issue 15; docs/model.md, "Filament self-contact").

    python studies/self_contact.py [--machin 600] [--turns 10 10]

Runs examples/fig4a.toml at M = 600 (above this model's M_c = 581; 10 CCW + 10 CW turns)
twice, ``contact.self_contact`` off and on, into out/self-contact/ (cached: existing run files
are reused), and prints for each: the crossings counted between saved frames
(:func:`flagwrap.interactions.self_contact.count_crossings`), the smallest distance between
non-neighbouring segments over the frames [a], steps, rejections and wall time.
"""

from __future__ import annotations

import argparse
import dataclasses
from pathlib import Path

import numpy as np


def segment_min_distance(X, sc) -> float:
    """Smallest non-neighbour segment distance over frames ``X`` (F, N, 3) [core units]."""
    best = np.inf
    for x in X:
        _, d = sc.energy_grad(x, np.zeros_like(x))
        best = min(best, d)
    return best


def main(argv=None):
    from flagwrap.interactions.self_contact import SelfContact, count_crossings
    from flagwrap.io.config import load_config
    from flagwrap.io.runfile import read_run, write_run
    from flagwrap.params import Phase
    from flagwrap.simulation import simulate

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--machin", type=float, default=600.0)
    ap.add_argument("--turns", type=float, nargs=2, default=(10.0, 10.0))
    args = ap.parse_args(argv)
    root = Path(__file__).resolve().parents[1]
    base = load_config(root / "examples" / "fig4a.toml")
    base = base.replace(motor=dataclasses.replace(
        base.motor, machin=args.machin,
        protocol=(Phase("ccw", args.turns[0]), Phase("cw", args.turns[1]))))
    out = root / "out" / "self-contact"
    out.mkdir(parents=True, exist_ok=True)
    fil = base.filament
    a, b = fil.cross_section_radius / fil.length, fil.bond_length / fil.length
    probe = SelfContact(a, b, range=base.contact.range)
    print(f"Fig. 4(a), M = {args.machin:g}, {args.turns[0]:g} CCW + {args.turns[1]:g} CW turns")
    print("| self-contact | status | crossings | min segment distance [a] | steps | rejected | wall [s] |")
    print("|---|---|---:|---:|---:|---:|---:|")
    for on in (False, True):
        cfg = base.replace(contact=dataclasses.replace(base.contact, self_contact=on),
                           name=f"fig4a-M{args.machin:g}-self{int(on)}")
        path = out / f"{cfg.name}.nc"
        if not path.exists():
            write_run(simulate(cfg, progress=True), path)
        ds = read_run(path)
        X = ds["position"].values / fil.length
        n = count_crossings(X, exclude=probe.exclude)
        dmin = segment_min_distance(X, probe) / a
        print(f"| {'on' if on else 'off'} | {ds.attrs['status']} | {n} | {dmin:.3f} | "
              f"{ds.attrs['n_steps']} | {ds.attrs['n_rejected']} | {ds.attrs['wall_time_s']:.0f} |")


if __name__ == "__main__":
    main()
