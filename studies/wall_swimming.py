"""The extended and the wrapped S. putrefaciens cell swimming beside a no-slip plane wall:
does it circle, and does it stay, approach or leave (docs/confinement.md, "A free cell
beside a wall").

Run: ``python studies/wall_swimming.py [--modes extended wrapped] [--gaps 0.5 1 2]
[--turns 60] [--settle 0] [--out out/wall_swimming]``

1. The two swimming states of ``studies/tube_swimming.py`` (the end of the wrap case's 4 CCW
   turns, and of its whole protocol), with ``--settle`` turns in free space first.
2. Each state at the origin, unturned (its axis along z), then ``--turns`` reference turns
   beside the wall ``x = -(r + gap)``, normal +x: parallel to the cell's axis, ``gap`` um
   from the cylinder of radius ``r`` about the body's axis that holds the whole cell (body and
   filament) over the free run's last turn. The wall screens the flow (Rotne-Prager-Blake)
   and repels the beads; the turning frame (exact beside any wall).
3. From each run file, per turn: the body centre's height above the wall, its axis' tilt
   towards the wall, and the heading: the angle in the wall's plane of the body's axis,
   averaged over the turn. The circling rate is the heading's turn about the normal per
   reference turn over the last ``--fit`` turns (a least-squares line, with its standard
   error; + = counter-clockwise seen from the fluid looking at the wall) and the circle's
   radius the speed along the wall over that rate. (Not the direction of the centre's
   displacement over each turn: the body's precession about its path swings that chord by
   +-30 degrees from turn to turn, where the turn-averaged axis holds to 0.3 degrees.)

Prints one row per (state, gap) and keeps each run file in ``--out``.
"""

from __future__ import annotations

import argparse
import itertools
import math
import time
from pathlib import Path

import one_thread  # noqa: F401  (one thread per process, before numpy loads)

import numpy as np
import tube_swimming as ts


def envelope_radius(path) -> float:
    """The radius [m] about the body's axis of the smallest cylinder that holds the cell
    (bead surfaces and the body's blob shell) over the run file's last reference turn."""
    from flagwrap.body.multiblob import cell_body_blobs
    from flagwrap.io.runfile import config_of, read_run
    from flagwrap.observables.swimming import body_frame

    ds = read_run(path)
    cfg = config_of(ds)
    t = ds["time"].values
    k = t >= t[-1] - 2 * math.pi / cfg.scales.omega * (1 - 1e-9)
    xb = body_frame(ds["position"].values[k], ds["body_position"].values[k],
                    ds["body_orientation"].values[k])
    L = cfg.filament.length
    blobs, ab = cell_body_blobs(cfg)
    a = cfg.filament.bead_radius
    r_beads = float(np.hypot(xb[..., 0], xb[..., 1]).max()) + a
    r_body = float((np.hypot(blobs[:, 0], blobs[:, 1]) + ab).max()) * L
    return max(r_beads, r_body)


def with_wall(cfg, x_wall):
    from flagwrap.params import Wall

    return cfg.replace(walls=(Wall(point=(x_wall, 0.0, 0.0), normal=(1.0, 0.0, 0.0)),))


def per_turn_track(path):
    """Per reference turn (arrays over turns): the body centre's height above the wall [m],
    its axis' tilt towards the wall [deg] (+ = pointing at the fluid), the heading, the
    angle of the body's axis in the wall's plane averaged over the turn [rad, unwrapped,
    about the normal], and the centre's displacement along the wall over the turn [m] (3
    components) with the turn's duration [s]."""
    from flagwrap.io.runfile import config_of, read_run
    from flagwrap.observables.wall import body_centres

    ds = read_run(path)
    cfg = config_of(ds)
    w = cfg.walls[0]
    n, p = w.unit_normal, np.asarray(w.point, float)
    t = ds["time"].values
    R, c = body_centres(ds, cfg)
    T = 2 * math.pi / cfg.scales.omega
    edges = [int(np.argmin(abs(t - k * T))) for k in range(round(t[-1] / T) + 1)]
    e1 = np.cross(n, [0.0, 0.0, 1.0])
    e1 = e1 / np.linalg.norm(e1) if np.linalg.norm(e1) > 1e-9 else np.array([0.0, 1.0, 0.0])
    e2 = np.cross(n, e1)  # (e1, e2, n) right-handed: angles + about n
    axis = R[:, :, 2]  # the body's axis in the lab, per record
    angle = np.unwrap(np.arctan2(axis @ e2, axis @ e1))
    h, tilt, heading, disp, dt = [], [], [], [], []
    for i, j in itertools.pairwise(edges):
        d = c[j] - c[i]
        disp.append(d - (d @ n) * n)
        dt.append(t[j] - t[i])
        h.append(float((0.5 * (c[i] + c[j]) - p) @ n))
        tilt.append(math.degrees(math.asin(float(np.clip(R[j][:, 2] @ n, -1, 1)))))
        heading.append(float(np.mean(angle[i:j + 1])))
    return np.array(h), np.array(tilt), np.array(heading), np.array(disp), np.array(dt)


def circling_rate(heading) -> tuple[float, float]:
    """``(rate, standard error)`` [rad per turn] of a least-squares line through ``heading``
    (one value per turn); the error ``nan`` below three turns."""
    k = np.arange(len(heading), dtype=float)
    if len(k) < 2:
        return math.nan, math.nan
    rate, c0 = np.polyfit(k, heading, 1)
    if len(k) < 3:
        return float(rate), math.nan
    resid = heading - (rate * k + c0)
    se = math.sqrt(float(resid @ resid) / (len(k) - 2) / float(((k - k.mean()) ** 2).sum()))
    return float(rate), se


def main(argv=None):
    q = argparse.ArgumentParser()
    q.add_argument("--modes", nargs="+", default=["extended", "wrapped"])
    q.add_argument("--gaps", type=float, nargs="+", default=[0.5, 1.0, 2.0])
    q.add_argument("--turns", type=float, default=60.0)
    q.add_argument("--fit", type=int, default=20, help="last turns of the heading's fit")
    q.add_argument("--settle", type=float, default=0.0)
    q.add_argument("--out", default="out/wall_swimming")
    args = q.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    found = ts.states(out)
    um = 1e-6
    print("| state | gap at start [um] | steps | s | height at start -> end [um] | tilt end "
          "[deg] | net speed along the wall [um/s] | circling [deg/turn] | circle radius [um] |")
    print("|---|---:|---:|---:|---|---:|---:|---:|---:|")
    for mode in args.modes:
        y0, base = found[mode]
        direction = "ccw" if mode == "extended" else "cw"
        if args.settle > 0:
            tr, _ = ts.run_one(ts.base_config(args.settle, direction), y0, base,
                               out / f"{mode}_settle{args.settle:g}.nc")
            y0, base = tr.final_y, tr.final_frames
        free = out / f"{mode}_free.nc"
        ts.run_one(ts.base_config(1.0, direction), y0, base, free)
        r = envelope_radius(free)
        for gap in args.gaps:
            cfg = with_wall(ts.base_config(args.turns, direction), -(r + gap * um))
            path = out / f"{mode}_gap{gap:g}.nc"
            start = time.perf_counter()
            tr, _ = ts.run_one(cfg, y0, base, path)
            h, tilt, head, disp, dt = per_turn_track(path)
            m = min(args.fit, len(head))
            rate, se = circling_rate(head[-m:])
            # net: each turn's chord swings with the body's precession about its path
            v = float(np.linalg.norm(disp[-m:].sum(axis=0))) / float(dt[-m:].sum())
            radius = v * 2 * math.pi / cfg.scales.omega / abs(rate) if rate else math.inf
            print(f"| {mode} | {gap:g} | {tr.n_steps} | {time.perf_counter() - start:.0f} | "
                  f"{h[0] / um:.2f} -> {h[-1] / um:.2f} | {tilt[-1]:+.1f} | {v / um:.3f} | "
                  f"{math.degrees(rate):+.3f} +- {math.degrees(se):.3f} | {radius / um:.0f} |",
                  flush=True)
            print("  height per 5 turns [um]: "
                  + " ".join(f"{x / um:.2f}" for x in h[::5]), flush=True)


if __name__ == "__main__":
    main()
