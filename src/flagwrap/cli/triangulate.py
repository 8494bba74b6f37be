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


def read_csv_columns(path: str, required: tuple[str, ...], optional: tuple[str, ...] = (),
                     bounds: dict | None = None) -> dict:
    """Read numeric columns by header name; raise UserInputError on any problem: a missing
    column, a non-numeric or non-finite entry, or one outside ``bounds[column] = (lo, hi,
    unit)`` (the column's physical range; the message names file, column, row and range)."""
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
    for col, v in out.items():
        lo, hi, unit = (bounds or {}).get(col, (-np.inf, np.inf, ""))
        bad = ~(np.isfinite(v) & (v >= lo) & (v <= hi))
        if np.any(bad):
            k = int(np.argmax(bad))
            rng = f" must be in [{lo:g}, {hi:g}]{(' ' + unit) if unit else ''}" if np.isfinite(lo) or np.isfinite(hi) \
                else " must be finite"
            raise UserInputError(f"{p}: column {col!r}{rng}, got {float(v[k])!r} in data row {k + 1}")
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


#: physical ranges: camera distances and known points in the length unit of --d1/--d2 (m or
#: mm), the focal length and image coordinates in pixels, the refractive index (glycerin 1.47)
LENGTH_MAX = 1e6
FOCAL_PX_RANGE = (1.0, 1e6)
PIXEL_MAX = 1e6
N_RANGE = (1.0, 5.0)


def _check_options(args) -> None:
    """Every number within its physical range, before any file is read (1e308 distances gave
    inf gaps, a focal length of 1e308 px points at the origin, exit 0)."""
    from flagwrap.errors import UserInputError, check_range

    for opt, v in (("--d1", args.d1), ("--d2", args.d2)):
        check_range(opt, v, 1e-6, LENGTH_MAX, "(length unit)")
    check_range("--focal-px", args.focal_px, *FOCAL_PX_RANGE, "px")
    check_range("--n", args.n, *N_RANGE)
    if (args.wall1 is None) != (args.wall2 is None):
        raise UserInputError("--wall1 and --wall2 must be given together (refraction at the tank wall)")
    for opt, w, d in (("--wall1", args.wall1, args.d1), ("--wall2", args.wall2, args.d2)):
        if w is not None and not (check_range(opt, w, 0.0, LENGTH_MAX, "(length unit)") < d):
            raise UserInputError(f"{opt} must be in [0, {'--d1' if opt == '--wall1' else '--d2'} = {d:g}), got {w!r}")


def run(args: argparse.Namespace) -> int:
    import numpy as np

    from flagwrap.errors import ResultError, check_result
    from flagwrap.experiment.triangulation import StereoRig, calibrate, triangulate

    _check_options(args)
    if args.output is not None:
        from flagwrap.io.outputs import check_output_file

        check_output_file(args.output, "-o", suffixes=(".csv", ".txt"))
    px = (-PIXEL_MAX, PIXEL_MAX, "px")
    image_bounds = {c: px for c in ("x1", "y1", "x2", "y2")}
    rig = StereoRig(args.d1, args.d2, args.focal_px, wall_1=args.wall1, wall_2=args.wall2, n_medium=args.n)
    if args.calibrate:
        length = (-LENGTH_MAX, LENGTH_MAX, "(length unit)")
        k = read_csv_columns(args.calibrate, ("X", "Y", "Z", "x1", "y1", "x2", "y2"),
                             bounds={**image_bounds, "X": length, "Y": length, "Z": length})
        try:
            cal = calibrate(rig, np.column_stack([k["X"], k["Y"], k["Z"]]),
                            np.column_stack([k["x1"], k["y1"], k["x2"], k["y2"]]))
        except ResultError:
            raise
        except Exception as exc:  # UserInputError included: name the file it came from
            from flagwrap.errors import UserInputError

            raise UserInputError(f"--calibrate {args.calibrate}: {exc}") from None
        hint = f"the known points in {args.calibrate} do not fit a two-camera rig (check their units)"
        for name, v, e in zip(cal.names, cal.values, cal.errors):
            lo, hi = FOCAL_PX_RANGE if name == "focal_px" else (1e-6, LENGTH_MAX)
            check_result(f"calibrated {name}", v, lo, hi, "", hint)
            check_result(f"calibrated {name}'s error", e, 0.0, hi, "", hint)
        check_result("reprojection rms", cal.rms_px, 0.0, PIXEL_MAX, "px", hint)
        rig = cal.rig
        for name, v, e in zip(cal.names, cal.values, cal.errors):
            print(f"# calibrated {name} = {v:.8g} +- {e:.2g}", file=sys.stderr)
        print(f"# reprojection rms = {cal.rms_px:.3g} px", file=sys.stderr)
    c = read_csv_columns(args.image_csv, ("x1", "y1", "x2", "y2"), bounds=image_bounds)
    pts, gap = triangulate(rig, np.column_stack([c["x1"], c["y1"], c["x2"], c["y2"]]), return_gap=True)
    # each point must be finite and in front of both cameras (beyond the walls): the midpoint of
    # two rays that meet behind a camera is a mismatched pair of image points, not a position
    bad = ~(np.all(np.isfinite(pts), axis=1) & np.isfinite(gap))
    for i in range(2):
        centre, axis, _, _, wall = rig.camera(i)
        with np.errstate(invalid="ignore"):
            bad |= ~((pts - centre) @ axis > wall)
    if np.any(bad):
        j = int(np.argmax(bad))
        raise ResultError(f"{args.image_csv}: {int(bad.sum())} of {bad.size} rows give no point in front of both "
                          f"cameras (first: data row {j + 1}, X,Y,Z = {', '.join(f'{v:.4g}' for v in pts[j])}): "
                          "the image points of a row do not see the same point (check the matching and the "
                          "camera distances)")
    write_csv({"X": pts[:, 0], "Y": pts[:, 1], "Z": pts[:, 2], "gap": gap}, args.output)
    return 0
