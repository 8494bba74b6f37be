"""Does a tube move the buckling threshold? The held S. putrefaciens cell's linear stability
(``flagwrap stability``) in free space and inside straight open tubes about its motor axis
(docs/confinement.md, "The threshold in a tube").

Run: ``python studies/tube_threshold.py [--radii 3 2 1.5 1] [--spacing 0.2] [--free]``

The s_putrefaciens_50hz_held case (the cell held still, a speed motor) linearised in the
turning frame, CW: the critical M_c of its whirl, the crossing (Hopf or fold), the mode's
frequency, the critical motor frequency and torque in SI, without a tube (``--free``) and
in tubes 10 um long, centred 2 um below the motor, of each radius R_t [um], blobs
``--spacing`` R_t apart (0.2 R_t: Haberman & Sayre within 0.4 %). The tube's blobs are held
at one angle in the turning frame, as the body's are (checked against the lab frame in
tests/unit/test_tube_system.py). Prints one JSON line per case.
"""

from __future__ import annotations

import argparse
import json
import math
import time

import one_thread  # noqa: F401  (one thread per process, before numpy loads)

from flagwrap.cases import case_files
from flagwrap.io.config import load_config
from flagwrap.params import TubeWall


def case(radius_um=None, spacing=0.2):
    cfg = load_config(case_files()["s_putrefaciens_50hz_held"])
    if radius_um is None:
        return cfg
    um = 1e-6
    return cfg.replace(tubes=(TubeWall(radius=radius_um * um, length=10 * um,
                                       center=(0.0, 0.0, -2.0 * um), axis=(0.0, 0.0, 1.0),
                                       blob_spacing=spacing * radius_um * um),))


def threshold(cfg) -> dict:
    from flagwrap.stability.threshold import critical_from_config, whirl_torque
    from flagwrap.system.parts import tube_blobs

    start = time.perf_counter()
    r = critical_from_config(cfg, "cw")
    fil = cfg.filament
    torque = whirl_torque(r) * fil.bending_modulus / fil.length if r.converged else math.nan
    return {"tube_radius_um": cfg.tubes[0].radius * 1e6 if cfg.tubes else None,
            "tube_blobs": len(tube_blobs(cfg)[0]) if cfg.tubes else 0,
            "converged": r.converged, "crossing": r.crossing, "machin_c": r.machin_c,
            "bracket": list(r.bracket), "frequency_c_hz": r.frequency_c,
            "mode_frequency": r.mode_frequency, "torque_c_pn_nm": torque * 1e21,
            "seconds": time.perf_counter() - start}


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--radii", type=float, nargs="*", default=[3.0, 2.0, 1.5, 1.0])
    p.add_argument("--spacing", type=float, default=0.2)
    p.add_argument("--free", action="store_true")
    a = p.parse_args(argv)
    cases = ([None] if a.free else []) + list(a.radii)
    for R in cases:
        print(json.dumps(threshold(case(R, a.spacing))), flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
