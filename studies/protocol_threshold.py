"""The protocol's outcome threshold beside M_f and M_Hopf: the lowest M at which the paper's
protocol (10 CCW then CW turns, run on to see the return) *ends* in the far state.

    python studies/protocol_threshold.py [--helices fig4a 70:2 57:2.5 ...] [--cw 30]
        [--tol 1e-6] [--rtol 0.005] [--out out/far/protocol.json]

Per helix (``fig4a``, or ``PSI:N`` for a Fig. 5 geometry of examples/sweeps/fig5.toml):
``flagwrap.stability.bifurcation.bifurcation_diagram`` (no Hopf cycles) gives M_Hopf and
M_f; then the protocol is bisected in ``[M_f, M_Hopf]`` (below M_f no far state exists, and
above the Hopf the whirl is unstable) by runs in the turning frame at ``--tol`` (the
protocol threshold of docs/stability.md moves by 2.5 at tol 1e-5 against 1e-6/1e-7). A run
"ends far" when its last state, polished by Newton, is a fixed point more than 0.1 L from
the steady whirl at that M; it "returns" when it ends within 0.02 L of the whirl. Anything
else (still moving after the CW turns) is reported and counts as undecided: the bracket then
stops there. Prints a markdown table for docs/stability.md and writes JSON.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import math
import time



def helix_config(name):
    from flagwrap.cases import get_case

    if name == "fig4a":
        return get_case("fig4a")
    from flagwrap.stability.boundary import fig5_helices

    psi, n = (float(v) for v in name.split(":"))
    for g, cfg in fig5_helices():
        if abs(g["psi_deg"] - psi) < 1e-9 and abs(g["turns"] - n) < 1e-9:
            return cfg.replace(name=f"fig5 psi={psi:g} n={n:g}")
    raise SystemExit(f"no Fig. 5 helix psi = {psi}, n = {n}")


def outcome(cfg, frame, machin, ccw, cw, tol):
    """'far', 'whirl' or 'moving' for the protocol at ``machin`` (turning frame)."""
    from flagwrap.params import Phase
    from flagwrap.stability.bifurcation import _run, distance, frame_config
    from flagwrap.stability.steady import NewtonFailure, branch, newton

    c = frame_config(cfg, machin, (Phase("ccw", ccw), Phase("cw", cw)))
    c = c.replace(numerics=dataclasses.replace(c.numerics, tol=tol))
    tr = _run(c)
    whirl = branch(frame, [machin])[machin]
    z = tr.final_y[:-1].copy()
    d_end = distance(frame, z, whirl.z)
    try:
        st = newton(frame, machin, z, tr.final_frames)
    except NewtonFailure:
        return ("whirl" if d_end < 0.02 else "moving"), d_end, tr.n_steps
    d = distance(frame, st.z, whirl.z)
    return ("far" if d > 0.1 else "whirl" if d < 0.02 else "moving"), d, tr.n_steps


def main(argv=None) -> int:
    from threadpoolctl import threadpool_limits

    from flagwrap.stability.bifurcation import FarStateNotFound, bifurcation_diagram

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--helices", nargs="+", default=["fig4a"])
    ap.add_argument("--ccw", type=float, default=10.0)
    ap.add_argument("--cw", type=float, default=30.0)
    ap.add_argument("--tol", type=float, default=1e-6)
    ap.add_argument("--rtol", type=float, default=0.005)
    ap.add_argument("--out", default="out/far/protocol.json")
    args = ap.parse_args(argv)
    rows = []
    with threadpool_limits(1):
        for name in args.helices:
            t0 = time.perf_counter()
            cfg = helix_config(name)
            try:
                d = bifurcation_diagram(cfg, cycles=())
            except FarStateNotFound as exc:
                print(f"{name}: no far state ({exc})", flush=True)
                rows.append({"helix": name, "far": False, "message": str(exc)})
                continue
            frame = d.hopf.frame
            lo, hi = d.machin_fold if d.fold_found else min(p.machin for p in d.far), d.machin_hopf
            runs = []
            note = ""
            while hi / lo - 1 > args.rtol:
                m = math.sqrt(lo * hi)
                res, dist, steps = outcome(cfg, frame, m, args.ccw, args.cw, args.tol)
                runs.append({"machin": m, "outcome": res, "distance": dist, "steps": steps})
                print(f"  {name} M = {m:.2f}: {res} ({dist:.3f} L from the whirl, {steps} steps)",
                      flush=True)
                if res == "far":
                    hi = m
                elif res == "whirl":
                    lo = m
                else:
                    note = f"undecided at M = {m:.2f} (still moving after {args.cw:g} CW turns)"
                    break
            row = {"helix": name, "far": True, "machin_hopf": d.machin_hopf,
                   "machin_fold": d.machin_fold if d.fold_found else None,
                   "far_message": d.message, "protocol_bracket": [lo, hi], "note": note,
                   "runs": runs, "line": cfg.machin_critical_scaling,
                   "wall_s": time.perf_counter() - t0}
            rows.append(row)
            print(json.dumps({k: v for k, v in row.items() if k != "runs"}), flush=True)
    print("| helix | M_f | protocol (10 CCW + %g CW, tol %g) | M_Hopf | paper's line | M_f / line |"
          % (args.cw, args.tol))
    print("|---|---:|---:|---:|---:|---:|")
    for r in rows:
        if not r["far"]:
            print(f"| {r['helix']} | no far state | - | - | - | - |")
            continue
        mf = r["machin_fold"]
        a, b = r["protocol_bracket"]
        print(f"| {r['helix']} | {mf:.1f} | {a:.1f}-{b:.1f}{' (' + r['note'] + ')' if r['note'] else ''}"
              f" | {r['machin_hopf']:.1f} | {r['line']:.0f} | "
              f"{(mf / r['line']) if mf else float('nan'):.2f} |" if mf else
              f"| {r['helix']} | - ({r['far_message']}) | {a:.1f}-{b:.1f} | {r['machin_hopf']:.1f} "
              f"| {r['line']:.0f} | - |")
    from pathlib import Path

    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    Path(args.out).write_text(json.dumps(rows, indent=1, default=float))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
