"""Render a snapshot strip of a run: both camera views at chosen t/T (PNG and PDF).

Examples::

    flagwrap snapshots out/fig4a.nc                      # 6 times over the CW phase
    flagwrap snapshots out/fig4a.nc -t 10 11 12.5 14 -o figs/fig4a_strip.png
"""

from __future__ import annotations


def add_arguments(p):
    p.add_argument("run_file", help="run file (.nc) written by `flagwrap run`")
    p.add_argument("-o", "--output", help="output path; one file per format with its suffix "
                   "(default: RUN_snapshots.png/.pdf beside the run file)")
    p.add_argument("-t", "--times", type=float, nargs="+", metavar="T",
                   help="times t/T to show (nearest saved frames); default: evenly over the CW phase")
    p.add_argument("-n", type=int, default=6, help="number of snapshots when --times is not given (6)")
    p.add_argument("--formats", default="png,pdf", help="comma-separated formats (png,pdf)")
    p.add_argument("--dpi", type=int, default=200, help="raster resolution (200)")


def run(args) -> int:
    from pathlib import Path

    from flagwrap.errors import UserInputError
    from flagwrap.io.runfile import read_run
    from flagwrap.plotting.snapshots import write_snapshots

    ds = read_run(args.run_file)
    out = Path(args.output) if args.output else Path(args.run_file).with_name(
        Path(args.run_file).stem + "_snapshots.png")
    formats = [f.strip().lower() for f in args.formats.split(",") if f.strip()]
    if not formats:
        raise UserInputError("--formats is empty")
    from matplotlib.figure import Figure

    known = Figure().canvas.get_supported_filetypes()
    bad = [f for f in formats if f not in known]
    if bad:
        raise UserInputError(f"--formats: {', '.join(bad)} not supported; choose from "
                             f"{', '.join(sorted(known))}")
    if not 1 <= args.dpi <= 1200:
        raise UserInputError(f"--dpi must be in [1, 1200], got {args.dpi}")
    if not 1 <= args.n <= 50:
        raise UserInputError(f"-n must be in [1, 50] snapshots, got {args.n}")
    from flagwrap.io.outputs import check_output_file

    for f in formats:
        check_output_file(out.with_suffix("." + f), "snapshot file (-o)")
    if args.times is not None and len(args.times) > 50:
        raise UserInputError(f"-t/--times: at most 50 times, got {len(args.times)}")
    paths = write_snapshots(ds, out, formats=formats, dpi=args.dpi, times=args.times, n=args.n)
    for p in paths:
        print(p)
    return 0
