"""Buoyancy studies quoted in docs/gravity.md (issue 18).

    python studies/gravity.py greenhill          # straight rod: G_c at N = 31, 61, 121 vs 7.837
    python studies/gravity.py static             # Fig. 4(a) helix, motor at rest: rise vs G
    python studies/gravity.py static --check     # ... and the time loop's end state at two G
    python studies/gravity.py waiting --mismatch -0.02 --machin-c 383 [--eps 0.1 0.25 0.5 1]
    python studies/gravity.py movies [--mismatch 0 -0.01 -0.02 -0.03] [--only movie6 movie7]

``greenhill`` and ``static`` take seconds (static equilibria by Newton,
flagwrap.analysis.static_buckling). ``waiting`` runs the Fig. 4(a) helix at the given density
mismatch at M = (1 + eps) M_c (the test-run protocol of ``flagwrap critical``: 5 CCW turns,
then CW) into out/gravity-waiting/ (cached: re-running reuses the runs) and prints t_c/T
against the paper's 0.5/eps. ``movies`` runs the SI movie configs (examples/movie*.toml, their
own frequencies and 10 CCW + 10 CW protocol, in full) at each density mismatch into
out/gravity-movies/ (cached) and prints this model's class beside the paper's.
"""

from __future__ import annotations

import argparse
import numpy as np


def _fig4a(n_beads=None, protocol=None, machin=None, hi=True):
    from flagwrap.cases import get_case
    from flagwrap.io.config import config_from_dict

    d = get_case("fig4a").to_dict()
    if n_beads is not None:
        d["filament"]["n_beads"] = n_beads
    if protocol is not None:
        d["motor"] = {"machin": machin or d["motor"]["machin"], "protocol": protocol}
    d["numerics"]["hydrodynamics"] = hi
    return config_from_dict(d)


def greenhill():
    from flagwrap.analysis.static_buckling import GREENHILL_CLAMPED_FREE, critical_gravity

    print("straight rod clamped at the top, buoyant, motor at rest (Greenhill: G_c = 7.837)")
    print(f"{'N':>4} {'G_c':>9} {'G_c/7.837-1':>12} {'G_c (1-b/2L)^3/7.837-1':>24}")
    res = {}
    for N in (31, 61, 121):
        g = critical_gravity(_fig4a(N), 5.0, 12.0, rtol=1e-6)[0]
        res[N] = g
        b = 1.0 / (N - 1)
        print(f"{N:>4} {g:>9.5f} {g / GREENHILL_CLAMPED_FREE - 1:>+12.2%} "
              f"{g * (1 - b / 2) ** 3 / GREENHILL_CLAMPED_FREE - 1:>+24.3%}")
    rich = 2 * res[121] - res[61]
    print(f"Richardson (61, 121): {rich:.5f} ({rich / GREENHILL_CLAMPED_FREE - 1:+.3%})")


def static(check=False):
    from flagwrap.analysis.static_buckling import static_branch, with_gravity_number
    from flagwrap import units
    from flagwrap.simulation import Simulation

    cfg = _fig4a()
    G = np.arange(0.0, 30.01, 1.0)
    br = static_branch(cfg, G)
    print("Fig. 4(a) helix (N = 61, kink lead), motor at rest: static equilibrium vs G")
    print(f"{'G':>5} {'mismatch':>9} {'rise [L]':>9} {'tip from axis [L]':>18} {'lowest eig':>11}")
    fil = cfg.filament  # G = -per x mismatch
    per = units.gravity_number(cfg.fluid.density, fil.cross_section_radius, fil.length, fil.bending_modulus)
    for g, h, o, lam in zip(br.G, br.tip_height, br.tip_offset, br.lowest_eigenvalue):
        print(f"{g:>5.1f} {-g / per:>+9.2%} {h:>9.4f} {o:>18.4f} {lam:>11.4f}")
    print(f"static rise reaches 0.15 L at G = {br.crossing(0.15):.2f} "
          f"(mismatch {-br.crossing(0.15) / per:+.2%}); {br.message or 'no static instability in the range'}")
    if check:
        # the time loop with the motor at rest must end in the same equilibrium (HI off: faster)
        for g in (8.0, 16.0):
            c = with_gravity_number(_fig4a(protocol=[{"direction": "stop", "turns": 20.0}],
                                           machin=1.0, hi=False), g)
            traj = Simulation(c).run()
            z = traj.arrays()["x"][-1, -1, 2]
            i = int(np.argmin(np.abs(br.G - g)))
            print(f"time loop, G = {g}: tip z = {z:.5f} L after 20 turns at M = 1 (static: "
                  f"{br.tip_z[i]:.5f}); {traj.status}")


def waiting(mismatch, machin_c, eps_values):
    from flagwrap.analysis.critical import RunCache
    from flagwrap.analysis.waiting_time import waiting_time_sweep
    from flagwrap.io.config import config_from_dict

    d = _fig4a().to_dict()
    d["filament"].pop("density", None)
    d["filament"]["density_mismatch"] = mismatch
    cfg = config_from_dict(d)
    print(f"Fig. 4(a) helix at density mismatch {mismatch:+.3g} (G = {cfg.gravity_number:.4g}), "
          f"M_c = {machin_c:g}")
    rows = waiting_time_sweep(cfg, machin_c, eps_values, cache=RunCache("out/gravity-waiting"),
                              on_run=lambda e, r: print(f"  eps = {e:<5g} M = {r.machin:8.2f} "
                                                        f"buckled {r.buckled} t_c/T = {r.waiting_time} "
                                                        f"class {r.state}", flush=True))
    print(f"{'eps':>6} {'M':>8} {'t_c/T':>7} {'0.5/eps':>8} {'class':>9}")
    for r in rows:
        t = r.get("waiting_time")
        print(f"{r['eps']:>6g} {r['machin']:>8.2f} {t if t is None else round(t, 2)!s:>7} "
              f"{0.5 / r['eps']:>8.2f} {r.get('state')!s:>9}")


#: SI movie configs and the paper's outcome at the movie's frequency (SI "Supplemental Movies")
MOVIES = (("movie2", "stable", "twirling, 0.86 omega_c"), ("movie3", "wrapping", "1.97 omega_c"),
          ("movie5", "folding", "1.72 omega_c"), ("movie6", "folding", "normal form, 1.29 omega_c"),
          ("movie7", "buckled", "critical, 1.04 omega_c"))


def movies(mismatches, only=None):
    import functools
    from pathlib import Path

    from flagwrap.analysis.critical import RunCache, simulate_and_analyse
    from flagwrap.io.config import config_from_dict, load_config

    root = Path(__file__).resolve().parents[1]
    cache = RunCache("out/gravity-movies", runner=functools.partial(simulate_and_analyse, stop_after=None),
                     key_extra="full protocol")
    print(f"{'movie':<7} {'paper':<9} {'mismatch':>8} {'G':>7} {'M':>7} {'model class':<11} "
          f"{'buckled':<7} {'t_c/T':>6}  paper's note")
    for name, paper, note in MOVIES:
        if only and name not in only:
            continue
        base = load_config(root / "examples" / f"{name}.toml")
        for dm in mismatches:
            d = base.to_dict()
            d["filament"].pop("density", None)
            if dm != 0:
                d["filament"]["density_mismatch"] = dm
            cfg = config_from_dict(d)
            r = cache.run(cfg)
            t = r.waiting_time
            print(f"{name:<7} {paper:<9} {dm:>+8.3g} {cfg.gravity_number:>7.3g} {cfg.machin:>7.4g} "
                  f"{r.state:<11} {str(r.buckled):<7} {'-' if t is None else f'{t:.2f}':>6}  {note}",
                  flush=True)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = p.add_subparsers(dest="what", required=True)
    sub.add_parser("greenhill")
    s = sub.add_parser("static")
    s.add_argument("--check", action="store_true")
    w = sub.add_parser("waiting")
    w.add_argument("--mismatch", type=float, required=True)
    w.add_argument("--machin-c", type=float, required=True)
    w.add_argument("--eps", type=float, nargs="+", default=[0.1, 0.25, 0.5, 1.0])
    m = sub.add_parser("movies")
    m.add_argument("--mismatch", type=float, nargs="+", default=[0.0, -0.01, -0.02, -0.03])
    m.add_argument("--only", nargs="+", help="movie names (default: all)")
    a = p.parse_args(argv)
    if a.what == "greenhill":
        greenhill()
    elif a.what == "static":
        static(a.check)
    elif a.what == "movies":
        movies(a.mismatch, a.only)
    else:
        waiting(a.mismatch, a.machin_c, a.eps)


if __name__ == "__main__":
    main()
