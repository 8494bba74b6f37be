"""The Fig. 4(a) helix's linear threshold with (i) the fixed transparent body (the paper's rig),
(ii) a fixed no-slip body and (iii) a free no-slip body (docs/bacterium.md, "The science").

    python studies/bacterium_threshold.py CASE [CASE ...] [--direction cw|ccw] [--spacing S]
    CASE: transparent | fixed | free | fixed-turned | free-turned

Each case prints one JSON line (M_c, the crossing's kind and frequency, the states used,
seconds). ``--spacing``: blob spacing in units of R_cell (default 1/3, the config default).
"*-turned*": the blob shell turned about the motor axis by half the angle between the blobs of
its widest ring. In the turning frame the shell is held at one angle, where it really turns;
the spread between the two angles bounds that approximation.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))


def config(case: str, spacing: float):
    from conftest import make_config

    cfg = make_config()
    if case == "transparent":
        return cfg
    R_cell = cfg.body.resolved_radius(cfg.filament.helix_radius)
    body = dict(surface="no-slip", blob_spacing=spacing * R_cell,
                motion="free" if case.startswith("free") else "fixed")
    return cfg.replace(body=dataclasses.replace(cfg.body, **body))


def turned_frame(cfg, omega: float):
    """The frame of ``cfg`` with its blob shell turned by half the widest ring's blob angle."""
    from flagwrap.body.multiblob import cell_body_blobs
    from flagwrap.body.fixed_mobility import FixedBodyMobility
    from flagwrap.system.rod_system import RodSystem
    from flagwrap.system.rotating import RotatingFrame, rotation
    from flagwrap.system.swimmer import SwimmerFrame, SwimmerSystem

    blobs, radii = cell_body_blobs(cfg)
    r = np.hypot(blobs[:, 0], blobs[:, 1])
    ring = np.isclose(r, r.max())
    angle = np.pi / ring.sum()
    blobs = blobs @ rotation((0.0, 0.0, 1.0), angle).T
    fil = cfg.filament
    a = fil.bead_radius / fil.length
    if cfg.body.free:
        from flagwrap.hydrodynamics.mobility import RPYMobility

        return SwimmerFrame(SwimmerSystem(RodSystem(cfg, mobility=RPYMobility(a)), blobs, radii),
                            omega)
    return RotatingFrame(RodSystem(cfg, mobility=FixedBodyMobility(a, blobs, radii)), omega,
                         blob_body=True)


def main(argv=None):
    from flagwrap.stability.threshold import (DIRECTIONS, critical_from_config, find_critical,
                                              resolve_m_max)

    p = argparse.ArgumentParser()
    p.add_argument("cases", nargs="+",
                   choices=["transparent", "fixed", "free", "fixed-turned", "free-turned"])
    p.add_argument("--direction", default="cw", choices=["cw", "ccw"])
    p.add_argument("--spacing", type=float, default=1.0 / 3.0)
    args = p.parse_args(argv)
    for case in args.cases:
        cfg = config(case, args.spacing)
        t0 = time.perf_counter()
        if case.endswith("turned"):
            frame = turned_frame(cfg, DIRECTIONS[args.direction])
            res = find_critical(frame, m_start=10.0, m_max=resolve_m_max(cfg, 10.0, None),
                                omega_si=cfg.omega, machin_si=cfg.machin)
        else:
            res = critical_from_config(cfg, direction=args.direction)
        print(json.dumps(dict(case=case, direction=args.direction, spacing=args.spacing,
                              machin_c=res.machin_c, crossing=res.crossing,
                              frequency=res.mode_frequency, converged=res.converged,
                              states=len(res.branch), seconds=round(time.perf_counter() - t0, 1))),
              flush=True)


if __name__ == "__main__":
    main()
