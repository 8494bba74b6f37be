"""Does CW motor torque alone switch a normal filament to semicoiled, and where does the
switch start? (docs/polymorph.md, "The model's switching torque")

    python studies/polymorph_switch.py CONFIG.toml --hz 100 200 ... [--turns 8]
                                       [--direction cw] [--n-beads N]
                                       [--wall-scale F] [--rate-scale F]

CONFIG: a polymorph case (examples/ecoli_polymorph.toml); its motor becomes a speed motor
turning ``--direction`` at each ``--hz`` for ``--turns`` turns from the configured initial
state. Each speed prints one JSON line: the motor torque over the last turn [pN nm] (mean),
the largest torque before the first vertex crossed phi = 0 (all of the run's if none did), the
fraction of the transforming vertices with phi > 0 at the end, the first such vertex's
contour position from the motor [um] and the first time any vertex crossed phi = 0 [s], and
seconds of wall time. The switch is a threshold in motor torque between the last speed that
keeps A and the first that makes B.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import time

import numpy as np


def main(argv=None):
    from flagwrap.io.config import load_config
    from flagwrap.params import Phase
    from flagwrap.simulation import Simulation

    p = argparse.ArgumentParser()
    p.add_argument("config")
    p.add_argument("--hz", type=float, nargs="+", required=True)
    p.add_argument("--turns", type=float, default=8.0)
    p.add_argument("--direction", choices=("cw", "ccw"), default="cw")
    p.add_argument("--n-beads", type=int, default=None)
    p.add_argument("--wall-scale", type=float, default=1.0,
                   help="the domain wall's width times this (stiffness times its square)")
    p.add_argument("--rate-scale", type=float, default=1.0,
                   help="the relaxation rate times this (of the default when unset)")
    args = p.parse_args(argv)
    base = load_config(args.config)
    pm = base.polymorph
    changes = {}
    if args.wall_scale != 1.0:  # the wall's width times F: the stiffness times F^2
        if pm.transition is not None:
            changes["domain_wall_width"] = pm.wall_width() * args.wall_scale
        else:
            changes["stiffness"] = pm.stiffness * args.wall_scale**2
    if args.rate_scale != 1.0:  # of the rate the system uses (the default when unset)
        from flagwrap.simulation import make_system

        g = make_system(base).order_rate * args.rate_scale  # core
        changes["rate"] = g * base.scales.omega / base.scales.force  # -> 1/(N s)
    base = base.replace(polymorph=dataclasses.replace(pm, **changes))
    for hz in args.hz:
        motor = dataclasses.replace(base.motor, kind="speed", frequency=hz, machin=None,
                                    stall_torque=None, zero_load_speed=None,
                                    protocol=(Phase(args.direction, args.turns),))
        cfg = base.replace(motor=motor)
        t0 = time.perf_counter()
        sim = Simulation(cfg)
        tr = sim.run()
        s = sim.system
        order = np.asarray(tr.order)[:, s.order_changes]
        t = np.asarray(tr.t) / cfg.scales.omega
        s_um = np.concatenate([[0.0], np.cumsum(s.order_bonds)])[s.order_changes] * cfg.filament.length * 1e6
        crossed = np.flatnonzero((order > 0).any(axis=1))
        last = np.asarray(tr.t) >= tr.t[-1] - 2 * np.pi
        torque = np.asarray(tr.motor_torque) * cfg.scales.torque * 1e21
        tq = torque[last]
        before = torque[:crossed[0] + 1] if crossed.size else torque
        end = order[-1] > 0
        print(json.dumps({
            "hz": hz, "status": tr.status, "motor_torque_pn_nm": round(float(tq.mean()), 1),
            "peak_torque_before_switch_pn_nm": round(float(before[np.argmax(np.abs(before))]), 1),
            "fraction_b": round(float(end.mean()), 3),
            "first_b_from_motor_um": round(float(s_um[np.argmax(end)]), 3) if end.any() else None,
            "first_cross_s": round(float(t[crossed[0]]), 5) if crossed.size else None,
            "phi_min_max": [round(float(order[-1].min()), 3), round(float(order[-1].max()), 3)],
            "steps": tr.n_steps, "seconds": round(time.perf_counter() - t0, 1)}), flush=True)


if __name__ == "__main__":
    main()
