"""Sensitivity of the Fig. 4(a) result to the open modelling and numerical choices.

Each variant changes ONE field of ``examples/fig4a.toml`` (psi = 70 deg, n = 2 coil helix,
HI on); every run is 5 CCW turns (the CCW state settles in ~4 turns) then 10 CW turns at the
Machin number M. Results: max free-end rise above its end-of-CCW level (L), motor torque
N_m R / A at the end of the first CW turn, its CW peak and its median over the last turn, buckled (analysis defaults:
smoothed rise >= 0.15 L held 1 turn), wall time.

    python studies/sensitivity.py                 # whole plan (M = 283, 400, 600 all; 500 subset)
    python studies/sensitivity.py --m 283 400     # only these M
    python studies/sensitivity.py --variants default ramp --m 600
    python studies/sensitivity.py --table-only    # tabulate the runs already on disk

Runs are written to ``out/sensitivity/<variant>_M<M>.nc`` and skipped if the file exists,
so the study can be interrupted and resumed. Runs are sequential (one core).
N = 121 at M = 600 (in the plan) did not finish in 16 min on a loaded core and has no result yet.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import math
import sys
import time
from pathlib import Path

import numpy as np

from flagwrap.analysis.runfile_attrs import analyze_run_file
from flagwrap.io.config import load_config
from flagwrap.io.runfile import read_run, write_run
from flagwrap.params import Phase
from flagwrap.simulation import simulate

ROOT = Path(__file__).resolve().parents[1]
BASE = ROOT / "examples" / "fig4a.toml"
OUT = ROOT / "out" / "sensitivity"
CCW_TURNS, CW_TURNS = 5.0, 10.0


def _fil(cfg, **kw):
    # the resolved Filament holds pitch, pitch_angle_deg and turns; keep only pitch (same helix)
    return cfg.replace(filament=dataclasses.replace(cfg.filament, pitch_angle_deg=None,
                                                    turns=None, **kw))


#: name -> (what changes, function cfg -> cfg); "default" is examples/fig4a.toml itself
VARIANTS = {
    "default": ("examples/fig4a.toml (N=61, a_h=a, kink, range 1, k_s=1000, R/R_cell=0.6, tol 1e-5)",
                lambda c: c),
    "n121": ("filament.n_beads = 121 (b = 2.2 a, a_h = a)", lambda c: _fil(c, n_beads=121)),
    "ah075": ("filament.hydrodynamic_radius = 0.75 a",
              lambda c: _fil(c, hydrodynamic_radius=0.75 * c.filament.cross_section_radius)),
    "ramp": ("clamp.lead = ramp", lambda c: c.replace(clamp=dataclasses.replace(c.clamp, lead="ramp"))),
    "range05": ("contact.range = 0.5",
                lambda c: c.replace(contact=dataclasses.replace(c.contact, range=0.5))),
    "ks100": ("filament.stretch_stiffness = 100 A/b^3", lambda c: _fil(c, stretch_stiffness=100.0)),
    "body12": ("body.radius_ratio = 1.2 (R_cell = 25 mm)",
               lambda c: c.replace(body=dataclasses.replace(c.body, radius_ratio=1.2))),
    "tol1e6": ("numerics.tol = 1e-6",
               lambda c: c.replace(numerics=dataclasses.replace(c.numerics, tol=1e-6))),
}

#: priority order of the plan: (M, variants)
PLAN = [
    (283.0, list(VARIANTS)),
    (400.0, list(VARIANTS)),
    (600.0, ["default", "n121", "ah075", "ramp", "range05", "body12", "ks100", "tol1e6"]),
    (500.0, ["default", "n121", "ah075", "ramp"]),
]


def config_for(variant: str, machin: float):
    cfg = load_config(BASE)
    cfg = VARIANTS[variant][1](cfg)
    motor = dataclasses.replace(cfg.motor, machin=float(machin), frequency=None,
                                protocol=(Phase("ccw", CCW_TURNS), Phase("cw", CW_TURNS)))
    return cfg.replace(motor=motor, name=f"sens_{variant}_M{machin:g}")


def path_for(variant: str, machin: float) -> Path:
    return OUT / f"{variant}_M{machin:g}.nc"


def run_one(variant: str, machin: float) -> Path:
    path = path_for(variant, machin)
    if path.exists():
        return path
    cfg = config_for(variant, machin)
    t0 = time.perf_counter()
    traj = simulate(cfg)
    write_run(traj, path)
    print(f"  ran {path.name}: {traj.status} {traj.message} "
          f"({time.perf_counter() - t0:.0f} s, {traj.n_steps} steps)", flush=True)
    return path


def measure(path: Path) -> dict:
    """The study's numbers for one run file."""
    res = analyze_run_file(path, write=False)
    ds = read_run(path)
    turns = ds["turns"].values
    tq = ds["motor_torque_reduced"].values
    ts = res["switch_turns"]
    t1 = ts + 1.0
    tq1 = float(np.interp(t1, turns, tq)) if turns[-1] >= t1 - 1e-9 else float("nan")
    return {
        "status": str(ds.attrs.get("status", "")),
        "message": str(ds.attrs.get("message", "")),
        "rise": res["max_height"] - res["baseline_height"],
        "torque_ccw": float(np.median(tq[(turns > ts - 1.0) & (turns <= ts)])),
        "torque_cw1": tq1,
        "torque_peak": res["torque_peak_reduced"],
        "torque_last": res["torque_final_reduced"],
        "buckled": bool(res["buckled"]),
        "t_c": res["waiting_time_turns"],
        "state": res["state"],
        "wall_s": float(ds.attrs.get("wall_time_s", float("nan"))),
        "last_turn": float(turns[-1]),
    }


def fmt(x, spec="+.3f"):
    return "-" if x is None or (isinstance(x, float) and math.isnan(x)) else format(x, spec)


def table(rows) -> str:
    head = ("| variant | M | CCW torque | CW torque, end of 1st CW turn | CW peak | CW last turn "
            "| max rise (L) | buckled | t_c/T | wall (s) |\n"
            "|---|---:|---:|---:|---:|---:|---:|---|---:|---:|")
    lines = [head]
    for v, m, r in rows:
        note = "" if r["status"] == "completed" else f" ({r['status']} at t/T={r['last_turn']:.2f})"
        lines.append(
            f"| {v} | {m:g} | {fmt(r['torque_ccw'])} | {fmt(r['torque_cw1'])} | "
            f"{fmt(r['torque_peak'])} | {fmt(r['torque_last'])} | {fmt(r['rise'])} | {'yes' if r['buckled'] else 'no'}{note} | "
            f"{fmt(r['t_c'], '.2f')} | {fmt(r['wall_s'], '.0f')} |")
    return "\n".join(lines)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--m", type=float, nargs="+", help="Machin numbers (default: the plan)")
    p.add_argument("--variants", nargs="+", choices=list(VARIANTS), help="variants (default: plan)")
    p.add_argument("--table-only", action="store_true", help="do not run, tabulate existing files")
    args = p.parse_args(argv)
    OUT.mkdir(parents=True, exist_ok=True)
    plan = PLAN
    if args.m:
        plan = [(m, next((vs for pm, vs in PLAN if pm == m), list(VARIANTS))) for m in args.m]
    if args.variants:
        plan = [(m, [v for v in args.variants]) for m, _ in plan]
    rows = []
    for m, vs in plan:
        for v in vs:
            path = path_for(v, m)
            if not args.table_only:
                print(f"{v} M={m:g}: {VARIANTS[v][0]}", flush=True)
                run_one(v, m)
            if path.exists():
                r = measure(path)
                rows.append((v, m, r))
                print(f"  -> rise {r['rise']:+.3f} L, CW torque {r['torque_cw1']:+.3f}, "
                      f"peak {r['torque_peak']:+.3f}, buckled {r['buckled']}", flush=True)
    text = table(rows)
    print(text)
    (OUT / "table.md").write_text(text + "\n")
    (OUT / "results.json").write_text(json.dumps(
        [{"variant": v, "machin": m, **{k: (None if isinstance(x, float) and math.isnan(x) else x)
                                         for k, x in r.items()}} for v, m, r in rows], indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
