"""Find the critical speed omega_c (Machin number M_c) of a geometry by bracketing and bisection.

Each test run is the config at one M with CCW_TURNS CCW turns then K = CW_TURNS CW turns;
"buckled" = the free end comes up within the K CW turns (docs/analysis.md criteria). Finished
runs are cached in DIR (<hash of config TOML + version>.nc/.json) and reused. Every run is
printed as it is known; the result is M_c = sqrt(M_lo M_hi) with M_hi/M_lo - 1 <= RTOL.
The finite K biases M_c upward by ~c/K (docs/critical.md).

Which question this answers: the lowest M at which the paper's rise criterion fires within K
CW turns of the reversal. That is neither the whirl's loss of stability (`flagwrap
stability`, the Hopf) nor the far state's existence (`flagwrap stability --far`, its fold
M_f): near the threshold the rise can be the reversal's overshoot of a whirl it returns to.
Whether a run *ends* buckled needs it run on (docs/stability.md, "Two thresholds").

Examples::

    flagwrap critical examples/fig4a.toml --rtol 0.1
    flagwrap critical examples/movie7.toml --guess 480 --json
"""

from __future__ import annotations


def add_arguments(p):
    p.add_argument("config", metavar="CONFIG.toml", help="geometry/fluid/numerics; its motor is replaced")
    p.add_argument("--rtol", type=float, default=0.05, help="relative bracket width to stop at (0.05)")
    p.add_argument("--cw-turns", type=float, default=10.0, help="K: CW turns of a test run (10)")
    p.add_argument("--ccw-turns", type=float, default=5.0, help="CCW turns before the switch (5)")
    p.add_argument("--cache", default="out/critical", metavar="DIR", help="run cache (out/critical)")
    p.add_argument("--guess", type=float, default=None, help="first M to try (the config's M)")
    p.add_argument("--bracket", type=float, nargs=2, default=None, metavar=("M_LO", "M_HI"),
                   help="believed stable / buckled M (both are run or read from the cache)")
    p.add_argument("--factor", type=float, default=2.0, help="bracketing step factor (2)")
    p.add_argument("--max-runs", type=int, default=16, help="give up after this many runs (16)")
    p.add_argument("--no-hi", action="store_true", help="switch hydrodynamic interactions off")
    p.add_argument("--json", action="store_true", help="print the result as one JSON object")


def _check_options(args) -> None:
    """Every option's range, before anything runs (one-line errors naming the option)."""
    from flagwrap.analysis.critical import check_search_options
    from flagwrap.io.outputs import check_output_dir

    check_search_options(args.rtol, args.cw_turns, args.ccw_turns, args.factor, args.max_runs,
                         args.guess, args.bracket, option=_flag)
    check_output_dir(args.cache, "--cache")


def _flag(name: str) -> str:
    return "--" + name.replace("_", "-")


def _fmt(v, f):
    return "-" if v is None or v != v else format(v, f)


def run(args) -> int:
    import json
    import sys

    from flagwrap.analysis.critical import CriticalSearch, RunCache
    from flagwrap.io.config import load_config_or_case

    _check_options(args)
    cfg = load_config_or_case(args.config)
    if args.no_hi:
        import dataclasses

        cfg = cfg.replace(numerics=dataclasses.replace(cfg.numerics, hydrodynamics=False))

    def show(r):
        if not args.json:
            print(f"  M = {r.machin:9.3f}  {'BUCKLED' if r.buckled else 'stable ':7s}  "
                  f"t_c/T = {_fmt(r.waiting_time, '6.2f')}  class = {r.state:<8s}  "
                  f"peak N_m R/A = {_fmt(r.torque_peak, '+.2f')}  {r.status:<9s}  "
                  f"{'reused' if r.reused else 'new   '}  {args.cache}/{r.key}.nc", flush=True)

    search = CriticalSearch(rtol=args.rtol, cw_turns=args.cw_turns, ccw_turns=args.ccw_turns,
                            factor=args.factor, max_runs=args.max_runs,
                            cache=RunCache(args.cache), on_run=show)
    if not args.json:
        print(f"{args.config}: critical search (rtol {args.rtol:g}, {args.ccw_turns:g} CCW + "
              f"{args.cw_turns:g} CW turns, HI {'on' if cfg.numerics.hydrodynamics else 'off'}); "
              f"scaling-line M_c = {cfg.machin_critical_scaling:.1f}; gravity number G = "
              f"{cfg.gravity_number:.4g}", flush=True)
    from flagwrap.simulation import RunInterrupted

    try:
        search.compute(cfg, guess=args.guess, bracket=args.bracket)
    except RunInterrupted as stop:  # Ctrl-C or SIGTERM (a scheduler's limit): no traceback
        print(f"flagwrap critical: interrupted ({stop.signame or 'SIGINT'}) during a run at "
              f"{stop.trajectory.message.split(':')[0]}; the runs finished before it are cached "
              f"in {args.cache}: the same command resumes from them", file=sys.stderr)
        return 143 if stop.signame == "SIGTERM" else 130
    s = search.summary()
    if args.json:
        from flagwrap.sweep.store import jsonable  # NaN -> null at every depth (runs too)

        print(json.dumps(jsonable(s), sort_keys=True, allow_nan=False))
        return 0 if s["converged"] else 1
    lo, hi = s["bracket"]
    print(f"runs: {len(s['runs'])} ({search.cache.n_simulated} simulated, "
          f"{len(s['runs']) - search.cache.n_simulated} reused)")
    if not s["converged"]:
        print(f"NOT CONVERGED: bracket ({_fmt(lo, '.3f')}, {_fmt(hi, '.3f')})")
        return 1
    print(f"M_c     = {s['machin_c']:.2f}  (bracket {lo:.2f} .. {hi:.2f}, +-{100 * s['relative_uncertainty']:.1f} %)")
    print(f"omega_c = {s['omega_c']:.5g} rad/s  (f_c = {s['frequency_c']:.5g} Hz)")
    print(f"M_c / scaling line 0.06 (R/L)^-3 = {s['machin_c'] / s['machin_critical_scaling']:.2f}")
    if not s["monotone"]:
        print("WARNING: non-monotone record (a stable run above a buckled one)")
    return 0
