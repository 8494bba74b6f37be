"""Run a parameter sweep (grid or M_c boundary search) on Dask into out/sweeps/NAME.

Every case (geometry psi, n, R/L, R/R_cell; M or omega/omega_c of the scaling line; HI) is a
test run of CCW then K CW turns, stopped 2 turns after buckling. Each finished case is written
atomically as it finishes (runs/KEY.nc + rows/KEY.json, KEY = hash of the case's config and
the flagwrap version); re-running the same sweep skips finished cases; a case that fails is
recorded with its error and the sweep goes on. At the end the table of the spec's rows is
written to table.parquet (pyarrow installed) or table.nc (netCDF4) and table.csv. Exit code 1
if any case of the spec is failed. See docs/sweeps.md.

Examples::

    flagwrap sweep examples/sweeps/fig5-quick.toml
    flagwrap sweep examples/sweeps/fig5.toml --scheduler tcp://10.0.0.5:8786
    flagwrap sweep examples/sweeps/fig5-quick.toml --scheduler synchronous --dry-run
"""

from __future__ import annotations


def add_arguments(p):
    p.add_argument("spec", metavar="SWEEP.toml", help="sweep file (examples/sweeps/)")
    p.add_argument("--scheduler", default="local", metavar="ADDRESS",
                   help="'local' (default: LocalCluster, one worker per core), 'synchronous' "
                        "(in this process), or a Dask scheduler address tcp://HOST:PORT")
    p.add_argument("--workers", type=int, default=None, help="LocalCluster workers (all cores)")
    p.add_argument("--out", default="out/sweeps", metavar="DIR",
                   help="parent folder; results go to DIR/NAME (out/sweeps)")
    p.add_argument("--retry-failed", action="store_true", help="re-run cases recorded as failed")
    p.add_argument("--dry-run", action="store_true", help="list the cases and whether they are done")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")


def run(args) -> int:
    import re
    from pathlib import Path

    from flagwrap.errors import UserInputError
    from flagwrap.sweep.runner import fmt_float, run_sweep
    from flagwrap.sweep.spec import load_spec
    from flagwrap.sweep.store import SweepStore

    sched = args.scheduler
    if sched not in ("local", "synchronous") and not re.fullmatch(
            r"(tcp|tls|ws|wss|ucx)://[^\s:/]+:\d{1,5}|[^\s:/]+:\d{1,5}", sched):
        raise UserInputError(f"--scheduler must be 'local', 'synchronous' or a Dask scheduler "
                             f"address like tcp://HOST:PORT, got {sched!r}")
    spec = load_spec(args.spec)
    if args.workers is not None and args.workers < 1:
        raise UserInputError(f"--workers must be >= 1, got {args.workers}")
    from flagwrap.io.outputs import check_output_dir

    root = Path(args.out) / spec.name
    check_output_dir(root, "sweep folder (--out)")
    store = SweepStore(root)
    if args.dry_run and spec.mode == "boundary":
        from flagwrap.sweep.boundary import geometry_key

        geos = spec.geometries()
        print(f"{spec.name}: {len(geos)} geometries, mode boundary, -> {root}")
        for c in geos:
            gk = geometry_key(c, spec.boundary)
            done = store.read_boundary(gk) is not None
            print(f"  {gk}  psi={c.psi_deg:5.1f} n={c.turns:4.2f} R/L={c.r_over_l:.4f} "
                  f"first M={spec.boundary['guess_ratio'] * c.machin_scaling:9.2f}{_gravity(c)} hi={c.hi}  "
                  f"{'done' if done else 'todo'}")
        return 0
    if args.dry_run:
        print(f"{spec.name}: {len(spec.cases)} cases, mode {spec.mode}, -> {root}")
        for c in spec.cases:
            row = store.read_row(c.key)
            print(f"  {c.key}  psi={c.psi_deg:5.1f} n={c.turns:4.2f} R/L={c.r_over_l:.4f} "
                  f"M={c.machin:9.2f} (x{c.omega_ratio_scaling:.3g} scaling){_gravity(c)} hi={c.hi}  "
                  f"{row['status'] + ' ' + str(row.get('state')) if row else 'todo'}")
        return 0
    rep = run_sweep(spec, root, scheduler=args.scheduler, n_workers=args.workers,
                    retry_failed=args.retry_failed, progress=not args.no_progress)
    print(f"{spec.name}: {rep.total} {'cases' if spec.mode == 'grid' else 'geometries'}, "
          f"{rep.skipped} already done, {rep.finished} finished, {rep.failed} failed, "
          f"wall time {rep.wall_time_s:.1f} s")
    for key, err in rep.errors:
        print(f"  FAILED {key}: {err}")
    if rep.failed_before:
        print(f"  {len(rep.failed_before)} failed in an earlier run, kept (--retry-failed reruns them):")
        for key, err in rep.failed_before:
            print(f"  FAILED {key}: {err}")
    if spec.mode == "boundary":
        for b in store.boundaries():
            grav = (f" density_mismatch={b['density_mismatch']:+.4g} G={b.get('gravity_number', 0.0):.4g}"
                    if b.get("density_mismatch") is not None else "")
            print(f"  psi={b['psi_deg']:5.1f} n={b['turns']:4.2f} R/L={b['r_over_l']:.4f}{grav} "
                  f"M_c={fmt_float(b.get('machin_c'), '.1f')} bracket={b.get('bracket')} "
                  f"converged={b.get('converged')} status={b['status']}")
    print(f"table: {rep.table_path}")
    return 0 if rep.failed == 0 and not rep.failed_before else 1


def _gravity(case) -> str:
    """`` mismatch=... G=...`` for a case with a density mismatch (gravity number beside M)."""
    if case.density_mismatch is None:
        return ""
    return f" mismatch={case.density_mismatch:+.4g} G={case.gravity_number:.4g}"
