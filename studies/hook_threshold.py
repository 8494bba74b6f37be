"""A bacterium's linear buckling threshold against its hook's bending stiffness
(docs/bacterium.md, "S. putrefaciens": the hook sweep).

    python studies/hook_threshold.py CONFIG.toml --hook 1e-26 2e-26 ... [--motion free|fixed]
                                     [--m-start M]

CONFIG: a speed-motor bacterium (examples/s_putrefaciens_50hz.toml); ``--hook``: the hook's
bending moduli A_h [N m^2] (Son, Guasto & Stocker 2013 measured 1e-26 relaxed to 1e-25 under
load); ``--motion``: the cell free (force- and torque-free) or held (a fixed no-slip body).
Each modulus prints one JSON line: M_c, the critical motor rate f_c [Hz] (relative to the
body), the crossing, the motor torque of the steady whirl at f_c [pN nm]
(:func:`~flagwrap.stability.threshold.whirl_torque`) and seconds.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import time


def main(argv=None):
    from flagwrap.io.config import load_config
    from flagwrap.stability.threshold import critical_from_config, whirl_torque

    p = argparse.ArgumentParser()
    p.add_argument("config")
    p.add_argument("--hook", type=float, nargs="+", required=True, help="A_h [N m^2]")
    p.add_argument("--motion", choices=("free", "fixed"), default=None)
    p.add_argument("--m-start", type=float, default=100.0)
    args = p.parse_args(argv)
    base = load_config(args.config)
    if args.motion:
        base = base.replace(body=dataclasses.replace(base.body, motion=args.motion))
    A_L = base.filament.bending_modulus / base.filament.length  # the torque unit [N m]
    for A_h in args.hook:
        cfg = base.replace(joint=dataclasses.replace(base.joint, hook_bending_modulus=A_h))
        t0 = time.perf_counter()
        res = critical_from_config(cfg, "cw", m_start=args.m_start)
        print(json.dumps(dict(hook_bending_modulus=A_h, motion=cfg.body.motion,
                              machin_c=res.machin_c, frequency_c=res.frequency_c,
                              torque_c_pn_nm=whirl_torque(res) * A_L * 1e21, crossing=res.crossing,
                              converged=res.converged, seconds=round(time.perf_counter() - t0, 1))),
              flush=True)


if __name__ == "__main__":
    main()
