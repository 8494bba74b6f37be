"""Run a simulation from a TOML config (or a built-in paper case) and write a run file.

Examples::

    flagwrap run examples/fig4a.toml -o out/fig4a.nc
    flagwrap run --case fig4a -o out/fig4a.nc --figure out/fig4a.png
"""

from __future__ import annotations

import sys


def add_arguments(p):
    p.add_argument("config", nargs="?", help="TOML config file (see examples/)")
    p.add_argument("--case", help="built-in paper case instead of a file (see `flagwrap cases`)")
    p.add_argument("-o", "--output", help="run file to write (.nc); default out/<name>.nc")
    p.add_argument("--figure", help="also write a summary figure (PNG/PDF) of tip height and torque")
    p.add_argument("--no-hi", action="store_true", help="switch long-range hydrodynamics off")
    p.add_argument("--integrator", choices=["ros34pw2", "ros2", "euler"], help="override numerics.integrator")
    p.add_argument("--quiet", action="store_true", help="no progress bar")


def load(args):
    import dataclasses

    from flagwrap.cases import get_case
    from flagwrap.errors import UserInputError
    from flagwrap.io.config import load_config

    if (args.config is None) == (args.case is None):
        raise UserInputError("give a config file or --case NAME (not both)")
    cfg = load_config(args.config) if args.config else get_case(args.case)
    num = cfg.numerics
    if args.no_hi:
        num = dataclasses.replace(num, hydrodynamics=False)
    if args.integrator:
        num = dataclasses.replace(num, integrator=args.integrator)
    return cfg.replace(numerics=num)


def run(args) -> int:
    from pathlib import Path

    from flagwrap.io.runfile import write_run
    from flagwrap.simulation import simulate

    cfg = load(args)
    out = Path(args.output or f"out/{cfg.name}.nc")
    print(f"flagwrap run {cfg.name}: M = {cfg.machin:.4g}, Re = {cfg.reynolds:.3g}, "
          f"omega/omega_c (scaling) = {cfg.omega_ratio_scaling:.3g}, N = {cfg.filament.n_beads}, "
          f"HI {'on' if cfg.numerics.hydrodynamics else 'off'}", file=sys.stderr)
    traj = simulate(cfg, progress=not args.quiet)
    write_run(traj, out)
    print(f"wrote {out} ({traj.status}, {traj.n_steps} steps, {traj.wall_time:.1f} s)", file=sys.stderr)
    if args.figure:
        from flagwrap.io.runfile import read_run
        from flagwrap.plotting.summary import summary_figure

        summary_figure(read_run(out), args.figure)
        print(f"wrote {args.figure}", file=sys.stderr)
    if not traj.ok:
        print(f"flagwrap run: run stopped: {traj.message} (partial output kept in {out})", file=sys.stderr)
        return 1
    return 0
