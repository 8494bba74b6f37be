"""docs/bundle.md's table from the run files of studies/bundle_vs_equivalent.py.

    python studies/bundle_table.py out/bundle/*.nc

One markdown row per run file (its stored analysis is recomputed, nothing is written): the
case, viscosity, M of one filament, the verdict (first flagellum to buckle) with t_c after
the reversal, the final state and winding, each flagellum's state, the bundle's separation
over the last turn (several flagella), the swimming speed per phase (CCW, CW, the last
turn), the largest CW motor torque (all motors together, and per motor) in pN nm, steps and
wall time.
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path


def row(path: Path) -> str:
    import numpy as np

    from flagwrap.analysis.runfile_attrs import analyze_run_file
    from flagwrap.io.runfile import config_of, read_run

    ds = read_run(path)
    cfg = config_of(ds)
    om = ds["omega"].values
    if not (om < 0).any():
        return f"| {path.stem} | (CCW only: see the bundle lines) |"
    res = analyze_run_file(path, write=False)
    cw = om < 0
    tq = np.abs(ds["motor_torque"].values[cw]).max() * 1e21  # N m -> pN nm
    per = ""
    if "motor_torques" in ds.variables:
        per = " (" + ", ".join(f"{v:.0f}" for v in
                               np.abs(ds["motor_torques"].values[cw]).max(axis=0) * 1e21) + ")"
    sw = {p["direction"]: p["speed"] * 1e6 for p in res["swimming"]}
    tc = res["waiting_time_turns"]
    states = ", ".join(f["state"] for f in res.get("filaments", [])) or res["state"]
    sep = res.get("bundle", {}).get("separation")
    return (f"| {path.stem} | {cfg.fluid.viscosity * 1e3:g} | {cfg.machin:.0f} | "
            f"{'buckled' if res['buckled'] else 'stable'}"
            f"{'' if tc is None or tc != tc else f' at {tc:.1f}'} | {states} | "
            f"{res['winding_turns']:.2f} | {'-' if sep is None else f'{sep:.2f}'} | "
            f"{sw.get('ccw', math.nan):+.2f} / {sw.get('cw', math.nan):+.2f} / "
            f"{sw.get('final', math.nan):+.2f} | {tq:.0f}{per} | {int(ds.attrs['n_steps'])} | "
            f"{float(ds.attrs['wall_time_s']) / 60:.0f} |")


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("runs", nargs="+", type=Path)
    args = p.parse_args(argv)
    print("| run | eta [mPa s] | M (its filament) | verdict, t_c/T after reversal | state "
          "(each flagellum) | winding [turns] | separation [R] | swimming CCW / CW / last turn "
          "[um/s] | CW motor torque max [pN nm] (each) | steps | wall [min] |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for path in args.runs:
        print(row(path), flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
