"""A tuft of n flagella against the paper's equivalent single filament (B_n = n B_1), on one
free no-slip cell (docs/bundle.md; issue 28's science).

    python studies/bundle_vs_equivalent.py [CONFIG] [--cases bundle2 equiv2 ...]
                                           [--viscosity MPA_S] [--turns CCW CW]
                                           [--out out/bundle]

CONFIG (default examples/p_putida_bundle.toml) gives the filament, cell, hook, motor and
protocol. The cases, each a run file ``<out>/<case>.nc`` (resumed from its checkpoint, kept
when complete) analysed by ``flagwrap analyze``:

* ``single``: one flagellum at the pole (the config without its [[flagellum]] tables);
* ``bundleN``: N flagella at the config's polar angle, spread evenly in azimuth;
* ``equivN``: the paper's reduction, one flagellum at the pole with Young's modulus N E, so
  bending and twist stiffness N B_1, N C_1 (the paper's SI: "B_n = n B_1").

Prints one JSON line per case: the verdict (the first flagellum to buckle), t_c, final
state and winding, the bundle's separation and phase lags over the last turn, the swimming
speed per phase, steps and wall time.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import math
import time
from pathlib import Path


def case_config(base, case: str, viscosity=None, turns=None):
    """The config of ``case`` (module docstring) from ``base``; ``turns``: (CCW, CW) motor
    turns instead of the config's protocol (a CW of 0: CCW only)."""
    from flagwrap.params import Flagellum, Phase

    cfg = base
    if turns is not None:
        ccw, cw = turns
        phases = (Phase("ccw", ccw),) + ((Phase("cw", cw),) if cw > 0 else ())
        cfg = cfg.replace(motor=dataclasses.replace(cfg.motor, protocol=phases))
    if viscosity is not None:
        cfg = cfg.replace(fluid=dataclasses.replace(cfg.fluid, viscosity=viscosity * 1e-3))
    polar = base.flagella[0].polar_deg if base.flagella else 20.0
    if case == "single":
        cfg = cfg.replace(flagella=())
    elif case.startswith("bundle"):
        n = int(case[6:])
        cfg = cfg.replace(flagella=tuple(Flagellum(polar_deg=polar, azimuth_deg=360.0 * k / n)
                                         for k in range(n)))
    elif case.startswith("equiv"):
        n = int(case[5:])
        fil = cfg.filament
        fil = dataclasses.replace(fil, youngs_modulus=n * fil.youngs_modulus, pitch=fil.pitch,
                                  pitch_angle_deg=None, turns=None)
        cfg = cfg.replace(filament=fil, flagella=())
    else:
        raise SystemExit(f"unknown case {case!r}: single, bundleN, equivN")
    tag = "" if viscosity is None else f"_eta{viscosity:g}"
    if turns is not None:
        tag += f"_{turns[0]:g}+{turns[1]:g}"
    return cfg.replace(name=f"{base.name}_{case}{tag}")


def run_case(cfg, out: Path) -> dict:
    from flagwrap.analysis.runfile_attrs import analyze_run_file, jsonable
    from flagwrap.io.runfile import read_run, write_run
    from flagwrap.simulation import simulate

    path = out / f"{cfg.name}.nc"
    t0 = time.perf_counter()
    if not path.is_file():
        ck = out / f"{cfg.name}.ckpt.h5"
        traj = simulate(cfg, resume=ck if ck.is_file() else None, checkpoint_path=ck,
                        checkpoint_every_seconds=60)
        write_run(traj, path)
        ck.unlink(missing_ok=True)
    ds = read_run(path)
    if not (ds["omega"].values < 0).any():  # CCW only: the bundle, no buckling verdict
        return jsonable(_ccw_only(cfg, ds, time.perf_counter() - t0))
    res = analyze_run_file(path)
    row = {"case": cfg.name, "machin": cfg.machin, "status": res["run_status"],
           "buckled": res["buckled"], "state": res["state"],
           "waiting_time_turns": res["waiting_time_turns"], "winding_turns": res["winding_turns"],
           "final_height": res["final_height"], "torque_peak_reduced": res["torque_peak_reduced"],
           "n_steps": int(ds.attrs["n_steps"]), "wall_time_s": float(ds.attrs["wall_time_s"]),
           "swimming_um_s": [(p["direction"], p["speed"] * 1e6) for p in res["swimming"]],
           "seconds_here": time.perf_counter() - t0}
    if "filaments" in res:
        row["n_buckled"] = res["n_buckled"]
        row["states"] = [f["state"] for f in res["filaments"]]
        row["bundle"] = res["bundle"]
        row["phase_lag_deg"] = [math.degrees(v) for v in res["bundle"]["phase_lag"]]
    return jsonable(row)


def _ccw_only(cfg, ds, seconds) -> dict:
    from flagwrap.io.runfile import filament_slices
    from flagwrap.observables.bundle import bundle_summary, last_turn
    from flagwrap.observables.swimming import body_frame

    x = ds["position"].values
    if "body_position" in ds.variables:
        x = body_frame(x, ds["body_position"].values, ds["body_orientation"].values)
    fil = cfg.filament
    b = bundle_summary(ds["turns"].values, x, filament_slices(ds), fil.helix_radius,
                       distal=last_turn(fil.helix_radius, fil.pitch, fil.length))
    return {"case": cfg.name, "machin": cfg.machin, "status": str(ds.attrs["status"]),
            "n_steps": int(ds.attrs["n_steps"]), "wall_time_s": float(ds.attrs["wall_time_s"]),
            "bundle": {k: v for k, v in b.items() if not k.endswith("_series")},
            "separation_by_turn": [float(v) for v in b["separation_series"][::10]],
            "seconds_here": seconds}


def main(argv=None) -> int:
    from flagwrap.io.config import load_config

    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("config", nargs="?", default="examples/p_putida_bundle.toml")
    p.add_argument("--cases", nargs="+", default=["single", "equiv2", "bundle2"])
    p.add_argument("--viscosity", type=float, help="fluid viscosity [mPa s] (default: config's)")
    p.add_argument("--turns", type=float, nargs=2, metavar=("CCW", "CW"),
                   help="motor turns of each phase (default: the config's protocol)")
    p.add_argument("--out", default="out/bundle")
    args = p.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    base = load_config(args.config)
    for case in args.cases:
        cfg = case_config(base, case, args.viscosity, args.turns)
        print(json.dumps(run_case(cfg, out)), flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
