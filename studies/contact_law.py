"""Cost of the contact law in a post-buckling run: plain WCA against "wca-c2" (the default).

Run: ``python studies/contact_law.py`` (about 30 s + 130 s on one core). The case is the
full Fig. 5 sweep's psi = 45 deg, n = 2, omega/omega_c(line) = 16 (M = 5388), HI on, 5 CCW +
7 CW turns: it folds and slides over the cell body after ~5 CW turns. Prints, per law, the
accepted and rejected steps, the wall time and the final free-end position (m); documented in
docs/model.md ("Contact law with the cell body").
"""

from __future__ import annotations

import dataclasses
import time

import numpy as np
from threadpoolctl import threadpool_limits

from flagwrap.params import Phase
from flagwrap.simulation import simulate
from flagwrap.sweep.spec import spec_from_dict


def case_config():
    spec = spec_from_dict({"grid": {"psi_deg": 45.0, "turns": 2.0, "omega_ratio_scaling": 16.0}})
    cfg = spec.cases[0].config()
    motor = dataclasses.replace(cfg.motor, protocol=(Phase("ccw", 5.0), Phase("cw", 7.0)))
    return cfg.replace(motor=motor)


def main():
    base = case_config()
    print(f"case: M = {base.machin:.5g}, N = {base.filament.n_beads}, 5 CCW + 7 CW turns")
    with threadpool_limits(1):
        for law in ("wca-c2", "wca"):
            cfg = base.replace(contact=dataclasses.replace(base.contact, potential=law))
            t0 = time.perf_counter()
            tr = simulate(cfg)
            wall = time.perf_counter() - t0
            contact = int((np.asarray(tr.contact_energy) > 0).sum())
            tip = np.asarray(tr.x)[-1][-1] * cfg.filament.length
            print(f"{law:7s}: {tr.status}, {tr.n_steps} steps, {tr.n_rejected} rejected, "
                  f"{wall:.1f} s, frames in contact {contact}/{len(tr.t)}, "
                  f"free end {np.array2string(tip, precision=7)} m", flush=True)


if __name__ == "__main__":
    main()
