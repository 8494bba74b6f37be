"""Triangulate 3D points from two-camera image coordinates (CSV in, CSV out).

Reads a CSV with a header containing x1,y1,x2,y2 (pixels from each image centre; camera 1 on
+x looking along -x, camera 2 on +y looking along -y, see docs/experiment.md) and writes
X,Y,Z (same length unit as --d1/--d2) and the ray gap. With --wall1/--wall2 the rays are
refracted at the tank wall (Snell, --n, default 1.47 glycerin). With --calibrate KNOWN.csv
(columns X,Y,Z,x1,y1,x2,y2) the distances and focal length are first fitted to known points.
"""

from __future__ import annotations

import argparse
import csv
import sys
from pathlib import Path


def read_csv_columns(path: str, required: tuple[str, ...], optional: tuple[str, ...] = ()) -> dict:
    """Read numeric columns by header name; raise UserInputError on any problem."""
    import numpy as np

    from flagwrap.errors import UserInputError

    p = Path(path)
    if not p.is_file():
        raise UserInputError(f"CSV file not found: {p}")
    with p.open(newline="", encoding="utf-8") as fh:
        rows = [r for r in csv.reader(fh) if r and not r[0].lstrip().startswith("#")]
    if not rows:
        raise UserInputError(f"{p}: empty CSV")
    header = [h.strip() for h in rows[0]]
    missing = [c for c in required if c not in header]
    if missing:
        raise UserInputError(f"{p}: missing column(s) {missing}; header is {header}")
    out = {}
    for col in required + tuple(c for c in optional if c in header):
        j = header.index(col)
        try:
            out[col] = np.array([float(r[j]) for r in rows[1:]], dtype=float)
        except (ValueError, IndexError):
            raise UserInputError(f"{p}: column {col!r} has a non-numeric or missing entry") from None
    if any(v.size == 0 for v in out.values()):
        raise UserInputError(f"{p}: no data rows")
    return out


def write_csv(columns: dict, out: str | None) -> None:
    """Write equal-length columns as CSV to ``out`` or stdout."""
    names = list(columns)
    fh = open(out, "w", newline="", encoding="utf-8") if out else sys.stdout
    try:
        w = csv.writer(fh)
        w.writerow(names)
        for row in zip(*(columns[n] for n in names)):
            w.writerow([f"{float(v):.12g}" for v in row])
    finally:
        if out:
            fh.close()


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("image_csv", help="CSV with columns x1,y1,x2,y2 [pixels]")
    parser.add_argument("--d1", type=float, required=True, help="distance of camera 1 from the origin [length]")
    parser.add_argument("--d2", type=float, required=True, help="distance of camera 2 from the origin [length]")
    parser.add_argument("--focal-px", type=float, default=1680.0, help="apparent focal length [pixels] (SI: 1680)")
    parser.add_argument("--wall1", type=float, default=None, help="camera 1 to tank wall [length] (enables refraction)")
    parser.add_argument("--wall2", type=float, default=None, help="camera 2 to tank wall [length]")
    parser.add_argument("--n", type=float, default=1.47, help="refractive index of the liquid (default 1.47)")
    parser.add_argument("--calibrate", metavar="KNOWN_CSV", default=None,
                        help="fit d1, d2, focal length to points with columns X,Y,Z,x1,y1,x2,y2")
    parser.add_argument("-o", "--output", default=None, help="output CSV (default: stdout)")


def run(args: argparse.Namespace) -> int:
    import numpy as np

    from flagwrap.experiment.triangulation import StereoRig, calibrate, triangulate

    rig = StereoRig(args.d1, args.d2, args.focal_px, wall_1=args.wall1, wall_2=args.wall2, n_medium=args.n)
    if args.calibrate:
        k = read_csv_columns(args.calibrate, ("X", "Y", "Z", "x1", "y1", "x2", "y2"))
        cal = calibrate(rig, np.column_stack([k["X"], k["Y"], k["Z"]]),
                        np.column_stack([k["x1"], k["y1"], k["x2"], k["y2"]]))
        rig = cal.rig
        for name, v, e in zip(cal.names, cal.values, cal.errors):
            print(f"# calibrated {name} = {v:.8g} +- {e:.2g}", file=sys.stderr)
        print(f"# reprojection rms = {cal.rms_px:.3g} px", file=sys.stderr)
    c = read_csv_columns(args.image_csv, ("x1", "y1", "x2", "y2"))
    pts, gap = triangulate(rig, np.column_stack([c["x1"], c["y1"], c["x2"], c["y2"]]), return_gap=True)
    write_csv({"X": pts[:, 0], "Y": pts[:, 1], "Z": pts[:, 2], "gap": gap}, args.output)
    return 0
