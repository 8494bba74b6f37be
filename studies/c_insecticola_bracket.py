"""How C. insecticola's linear buckling threshold moves with the two numbers of its example
that have no source (docs/bacterium.md, "C. insecticola"): the coil's pitch and the cell's
radius, each varied alone about examples/c_insecticola.toml.

    python studies/c_insecticola_bracket.py [CONFIG] [--pitch P ...] [--cell-radius R ...]
                                            [--n-flagella N ...] [--motion free|fixed]

Defaults: the config itself, then the pitch at 1.2 and 2.8 um (1.79 and 1.51 helical turns
at R = 0.6 um, L = 7.1 um: the seed's "1.5-2 turn" coil allows any P below 2.86 um, and the
coil forms with a source have P/R = 3.0-3.5, P = 1.8-2.1 um here) and the cell radius at
0.25 and 0.45 um (0.5-0.9 um wide: below the ~1 um channels the cell passes wrapped, Yoshioka
et al. 2026), the cell's length held at R + H.
``--n-flagella``: the bundle's filament count, its bending stiffness n B_1 (seed SI), the
config's being 2 (none by default: f_c and T_c scale with n where the hook is soft).
Each case prints one JSON line: M_c, the critical motor rate f_c [Hz] (relative to the body),
the crossing, the steady whirl's motor torque at f_c [pN nm] and seconds; the seed's 40 Hz
is above f_c where the filament buckles.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import time


def _filament(base, **changes):
    """``base`` with its filament changed (the pitch given as the one helix parameter)."""
    fil = base.filament
    fil = dataclasses.replace(fil, **{"pitch": fil.pitch, **changes, "pitch_angle_deg": None,
                                      "turns": None})
    return base.replace(filament=fil)


def cases(base, pitches, radii, counts=(), n_config=2):
    yield "config", base
    for p in pitches:
        yield f"pitch {p:g} um", _filament(base, pitch=p * 1e-6)
    total = base.body.radius + base.body.cylinder_length
    for r in radii:
        body = dataclasses.replace(base.body, radius=r * 1e-6, cylinder_length=total - r * 1e-6)
        yield f"cell radius {r:g} um", base.replace(body=body)
    for n in counts:
        E = base.filament.youngs_modulus * n / n_config
        yield f"{n} flagella", _filament(base, youngs_modulus=E)


def main(argv=None):
    from flagwrap.io.config import load_config
    from flagwrap.stability.threshold import critical_from_config, whirl_torque

    p = argparse.ArgumentParser()
    p.add_argument("config", nargs="?", default="examples/c_insecticola.toml")
    p.add_argument("--pitch", type=float, nargs="*", default=[1.2, 2.8], help="[um]")
    p.add_argument("--cell-radius", type=float, nargs="*", default=[0.25, 0.45], help="[um]")
    p.add_argument("--n-flagella", type=int, nargs="*", default=[], help="bundle size")
    p.add_argument("--motion", choices=("free", "fixed"), default=None)
    p.add_argument("--m-start", type=float, default=100.0)
    p.add_argument("--skip-config", action="store_true", help="only the varied cases")
    args = p.parse_args(argv)
    base = load_config(args.config)
    if args.motion:
        base = base.replace(body=dataclasses.replace(base.body, motion=args.motion))
    for name, cfg in cases(base, args.pitch, args.cell_radius, args.n_flagella):
        if args.skip_config and name == "config":
            continue
        t0 = time.perf_counter()
        res = critical_from_config(cfg, "cw", m_start=args.m_start)
        A_L = cfg.filament.bending_modulus / cfg.filament.length  # the torque unit [N m]
        print(json.dumps(dict(case=name, motion=cfg.body.motion, pitch_um=cfg.filament.pitch * 1e6,
                              cell_radius_um=cfg.body.radius * 1e6, machin_c=res.machin_c,
                              frequency_c=res.frequency_c,
                              torque_c_pn_nm=whirl_torque(res) * A_L * 1e21,
                              crossing=res.crossing, converged=res.converged,
                              seconds=round(time.perf_counter() - t0, 1))), flush=True)


if __name__ == "__main__":
    main()
