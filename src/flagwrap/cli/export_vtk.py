"""Export a run for ParaView: one .vtp polyline per saved frame, a .pvd time series, the body.

Open DIR/run.pvd in ParaView. Point data per bead: arclength, curvature, twist_rate,
excess_twist_rate, handedness (sign of discrete torsion), elastic_force.

Examples::

    flagwrap export-vtk out/fig4a.nc out/fig4a_vtk
"""

from __future__ import annotations


def add_arguments(p):
    p.add_argument("run_file", help="run file (.nc) written by `flagwrap run`")
    p.add_argument("directory", help="output folder (created)")
    p.add_argument("--time", choices=["turns", "seconds"], default="turns",
                   help="time values of the .pvd: t/T (default) or seconds")
    p.add_argument("--stride", type=int, default=1, help="write every n-th saved frame (1)")
    p.add_argument("--no-forces", action="store_true", help="skip the elastic force per bead")


def run(args) -> int:
    from flagwrap.io.runfile import read_run
    from flagwrap.io.vtk import export_vtk

    from flagwrap.errors import UserInputError
    from flagwrap.io.outputs import check_output_dir

    check_output_dir(args.directory, "export folder")
    if args.stride < 1:
        raise UserInputError(f"--stride must be >= 1, got {args.stride}")
    ds = read_run(args.run_file)
    pvd = export_vtk(ds, args.directory, time_unit=args.time, stride=args.stride,
                     with_forces=not args.no_forces)
    print(pvd)
    return 0
