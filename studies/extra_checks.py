"""Two more open choices for the Fig. 4(a) helix at M = 283 (5 CCW + 10 CW turns, HI on).

Run: ``python studies/extra_checks.py`` (about 2 x 100 s + 100 s on one core). Writes
out/sensitivity/extra_*.nc and prints, per run, the free-end height at the end of CCW, the
highest free-end height during CW and the buckling verdict of ``flagwrap analyze``.

* bead hydrodynamic radius b/2 (touching beads, 3.33 mm, i.e. 2.2 a) instead of a;
* filament density 2 % below / above glycerin (the paper's 1-2 % mismatch, sign unknown).
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np

from flagwrap.analysis.runfile_attrs import analyze_run_file
from flagwrap.io.config import load_config
from flagwrap.io.runfile import write_run
from flagwrap.params import Phase
from flagwrap.simulation import simulate

VARIANTS = {
    "extra_ah_touching": dict(hydrodynamic_radius=3.33e-3),  # ~ b/2 = 0.4 m / 60 / 2
    "extra_density_1225": dict(density=1225.0),
    "extra_density_1275": dict(density=1275.0),
}


def main(machin=283.0):
    out = Path("out/sensitivity")
    out.mkdir(parents=True, exist_ok=True)
    base = load_config("examples/fig4a.toml")
    for name, change in VARIANTS.items():
        path = out / f"{name}_M{machin:g}.nc"
        fil = dataclasses.replace(base.filament, turns=None, pitch_angle_deg=None, **change)
        cfg = base.replace(filament=fil, motor=dataclasses.replace(
            base.motor, machin=machin, protocol=(Phase("ccw", 5), Phase("cw", 10))))
        if not path.exists():
            write_run(simulate(cfg), path)
        r = analyze_run_file(path, write=False)
        import xarray as xr

        ds = xr.load_dataset(path, engine="h5netcdf")
        h = (ds.position.values[:, -1, 2] - ds.position.values[:, 0, 2]) / ds.attrs["length"]
        t = ds.turns.values
        print(f"{name:22s} M={machin:g}: end-of-CCW height {h[np.argmin(abs(t - 5))]:+.3f} L, "
              f"max CW height {h[t > 5].max():+.3f} L, buckled {r['buckled']}, state {r['state']}")


if __name__ == "__main__":
    main()
