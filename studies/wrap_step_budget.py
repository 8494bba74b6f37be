"""Where a wrapping run's steps go (docs/speed.md, "The wrapped phase"): every step attempt of
a run, accepted or rejected, with the unknown that set its error and that bead's distance to
the body.

    python studies/wrap_step_budget.py [CASE] [--turns CCW CW] [--bin 0.5] [--contact 2.0]
                                       [--frame lab|rotating]

``CASE`` (default ``s_putrefaciens_wrap``) runs as ``flagwrap run`` would, with the local
error's max-norm (``DofLayout.scaled_error``) decomposed at each attempt: the unknown with the
largest ``|err_i| / w_i`` and its block (``x``: a bead's position, ``theta``: a twist angle,
``body_x``/``body_q``: the pose, ...). For a bead, its centre's distance to the body's surface
in units of the filament radius ``a`` (body frame for a free cell; in the motor's frame
(``--frame rotating``) the same, the body being axisymmetric): "at the body" when below
``--contact`` a (the contact law's range is ``a (1 + range)``), "near the body" below 10 a,
"at the filament" when another bead of the chain (not one of its three neighbours each side)
is within twice ``--contact`` a (self-contact), "free" otherwise.

Prints, per ``--bin`` reference turns: attempts, rejections, the median step size and the
share of attempts whose error was set by a bead at the body, a free bead, a twist angle or the
pose; then the same for the whole CCW phase, the CW phase before and after the filament first
comes to the body.
"""

from __future__ import annotations

import argparse
import math

import numpy as np


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("case", nargs="?", default="s_putrefaciens_wrap")
    ap.add_argument("--turns", type=float, nargs=2, default=None, metavar=("CCW", "CW"))
    ap.add_argument("--bin", type=float, default=0.5)
    ap.add_argument("--contact", type=float, default=2.0)
    ap.add_argument("--frame", choices=("lab", "rotating"), default=None,
                    help="numerics.frame (default: the case's)")
    args = ap.parse_args(argv)

    import dataclasses

    from flagwrap.body.shapes import config_shape
    from flagwrap.cases import case_files
    from flagwrap.integrators import base as ib
    from flagwrap.io.config import load_config
    from flagwrap.params import Phase
    from flagwrap.simulation import Simulation, make_system

    path = case_files().get(args.case, args.case)
    cfg = load_config(path)
    if args.turns is not None:
        cfg = cfg.replace(motor=dataclasses.replace(cfg.motor, protocol=(
            Phase("ccw", args.turns[0]), Phase("cw", args.turns[1]))))
    if args.frame is not None:
        cfg = cfg.replace(numerics=dataclasses.replace(cfg.numerics, frame=args.frame))
    system = make_system(cfg)
    shape = config_shape(cfg)  # core units (lengths in L), the body's frame
    a = cfg.filament.cross_section_radius / cfg.filament.length
    w = system.layout.error_weights(cfg.numerics.tol)
    xb = system.layout.block("x")
    log = []  # (h, err, accepted, category)
    state = {}

    original_scaled = ib.scaled_error

    def scaled_error(system_, err, tol):
        r = np.abs(err) / w
        i = int(np.argmax(r))
        state["i"] = i
        return original_scaled(system_, err, tol)

    original_conclude = ib.AdaptiveMixin.conclude

    def conclude(self, system_, base, y_new, err, h, estimate_order):
        res = original_conclude(self, system_, base, y_new, err, h, estimate_order)
        i = state.get("i", -1)
        cat = "other"
        for b in system_.layout.blocks:
            if b.start <= i < b.start + b.size:
                cat = b.name
        if cat == "x":
            k = (i - xb.start) // 3
            xs = y_new[xb.slice].reshape(-1, 3)
            d = float(shape.distance(xs[k][None])[0]) / a
            far = np.abs(np.arange(len(xs)) - k) > 3  # not its chain neighbours
            dself = (float(np.min(np.linalg.norm(xs[far] - xs[k], axis=1))) / a
                     if far.any() else np.inf)
            if d < args.contact:
                cat = "bead at the body"
            elif d < 10.0:
                cat = "bead near the body"
            elif dself < 2 * args.contact:
                cat = "bead at the filament"
            else:
                cat = "free bead"
        log.append((h, err, res.accepted, cat))
        return res

    import flagwrap.integrators.rosenbrock as ros

    ros.scaled_error = scaled_error
    ib.AdaptiveMixin.conclude = conclude
    sim = Simulation(cfg, system=system)
    traj = sim.run()
    print(f"{cfg.name}: {traj.n_steps} steps, {traj.n_rejected} rejected, {traj.wall_time:.0f} s; "
          f"{len(log)} attempts decomposed (the others were rejected before an error estimate)")
    t, ts = 0.0, []
    for h, _, acc, _ in log:
        ts.append(t)
        if acc:
            t += h
    ts = np.array(ts) / (2 * math.pi)
    hs = np.array([h for h, *_ in log]) / (2 * math.pi)
    acc = np.array([r[2] for r in log])
    cats = np.array([r[3] for r in log])
    names = ["bead at the body", "bead near the body", "bead at the filament", "free bead",
             "theta", "body_x", "body_q", "phi", "other"]
    names = [n for n in names if (cats == n).any()]

    def row(label, m):
        if not m.any():
            return
        share = "  ".join(f"{n} {100 * np.mean(cats[m] == n):3.0f}%" for n in names)
        print(f"{label:>16} {m.sum():>7} {np.sum(~acc[m]):>7} {np.median(hs[m & acc]) if (m & acc).any() else float('nan'):>10.2e}  {share}")

    print(f"{'turns':>16} {'attempts':>7} {'rejected':>7} {'median h/T':>10}  error set by")
    edges = np.arange(0.0, ts.max() + args.bin, args.bin)
    for lo in edges:
        row(f"{lo:.1f}-{lo + args.bin:.1f}", (ts >= lo) & (ts < lo + args.bin))
    ccw = cfg.motor.protocol[0].turns
    first = ts[(cats == "bead at the body") & (ts >= ccw)]
    t_touch = float(first.min()) if len(first) else float("inf")
    print(f"first error set by a bead at the body after the reversal: turn {t_touch:.2f}")
    row("CCW", ts < ccw)
    row("CW, before", (ts >= ccw) & (ts < t_touch))
    row("CW, from it", ts >= t_touch)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
