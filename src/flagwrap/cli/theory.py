"""Scaling-theory numbers and the helix force-extension law (main text Eq. 1, SI).

Actions:
  numbers  recompute the main text's bacterial- and model-scale numbers (M, Re, omega_c, N_c)
  stretch  force-extension curve of a helix with moment-free ends as CSV (defaults: the SI's
           stretching-test helix, 2R = 30 mm, P = 34 mm, L = 305 mm, 2a = 3.19 mm, 2b = 2.88 mm,
           E = 1.2 x 1.33 MPa, nu = 0.49)
"""

from __future__ import annotations

#: bound of --points (each point solves the helix's force balance; 1e5 points take ~1 s and
#: ~100 MB; a curve needs a few hundred)
MAX_POINTS = 100_000

import argparse


def add_arguments(parser: argparse.ArgumentParser) -> None:
    sub = parser.add_subparsers(dest="action", metavar="ACTION", required=True)
    sub.add_parser("numbers", help="the paper's order-of-magnitude numbers")
    s = sub.add_parser("stretch", help="force-extension curve (CSV: psi_deg, z_over_L, F_N, F_reduced)")
    s.add_argument("--radius", type=float, default=15e-3, help="helix radius R [m]")
    s.add_argument("--pitch", type=float, default=34e-3, help="pitch P [m]")
    s.add_argument("--length", type=float, default=305e-3, help="arclength L [m]")
    s.add_argument("--youngs-modulus", type=float, default=1.2 * 1.33e6, help="E [Pa]")
    s.add_argument("--poisson", type=float, default=0.49, help="nu")
    s.add_argument("--a", type=float, default=3.19e-3 / 2, help="larger semi-axis a [m]")
    s.add_argument("--b", type=float, default=2.88e-3 / 2, help="smaller semi-axis b [m] (equal to --a for round)")
    s.add_argument("--points", type=int, default=50, help="number of curve points")
    s.add_argument("--no-axial-stretch", action="store_true", help="drop the F/(pi E a b) term of z/L")
    s.add_argument("-o", "--output", default=None, help="output CSV (default: stdout)")


def run(args: argparse.Namespace) -> int:
    import math

    import numpy as np

    from flagwrap.errors import UserInputError

    if args.action == "numbers":
        from flagwrap.theory.scaling import paper_numbers

        p = paper_numbers()
        two_pi = 2 * math.pi
        print(f"M (A = 3 pN um^2, eta = 1 mPa s, f = 150 Hz, L = 7 um)   = {p.machin_bacterium:.4g}   [paper: ~750]")
        print(f"Re bacterium (R = 0.6 um, f = 50 Hz, water)                = {p.reynolds_bacterium:.3g} [paper: ~1e-4]")
        print(f"Re model (R = 15 mm, f = 0.01 Hz, 1250 kg/m^3, 1.1 Pa s)   = {p.reynolds_model:.3g} [paper: ~2e-2]")
        print(f"N_c = 0.5 A/R (A = 3 pN um^2, R = 0.6 um)                  = {p.critical_torque_pn_nm:.4g} pN nm [paper: ~2500]")
        print(f"N_m = 0.9 A/R                                              = {p.peak_torque_pn_nm:.4g} pN nm [paper: ~4500]")
        lo, hi = p.omega_c_bacterium_material
        print(f"omega_c bacteria (E/eta)(a/R)^3(a/L), eta = 1e-2..1e-3     = {lo:.3g}..{hi:.3g} rad/s "
              f"({lo / two_pi:.3g}..{hi / two_pi:.3g} Hz) [paper: '10^2-10^3 Hz']")
        print(f"omega_c model (E/eta)(a/R)^3(a/L)                          = {p.omega_c_model_material:.3g} rad/s "
              f"({p.omega_c_model_material / two_pi:.3g} Hz) [paper: 0.01-0.1 Hz]")
        print(f"omega_c model A/(zeta R^3 L), P = 34 mm                    = {p.omega_c_model_rft:.3g} rad/s "
              f"({p.omega_c_model_rft / two_pi:.3g} Hz)")
        return 0

    from flagwrap.cli.triangulate import write_csv
    from flagwrap.theory.stretching import StretchedHelix

    if not 2 <= args.points <= MAX_POINTS:
        raise UserInputError(f"--points must be in [2, {MAX_POINTS}], got {args.points}")
    # physical ranges (a molecule to a lab tank; a gel to steel), so that no value overflows
    for opt, v, lo, hi in (("--radius", args.radius, 1e-9, 10.0), ("--pitch", args.pitch, 1e-9, 10.0),
                           ("--length", args.length, 1e-9, 100.0), ("--a", args.a, 1e-10, 1.0),
                           ("--b", args.b, 1e-10, 1.0), ("--poisson", args.poisson, -0.999, 0.5),
                           ("--youngs-modulus", args.youngs_modulus, 1.0, 1e13)):
        if not (v is not None and math.isfinite(v) and lo <= v <= hi):
            raise UserInputError(f"{opt} must be in [{lo:g}, {hi:g}] (SI), got {v!r}")
    if args.output is not None:
        from flagwrap.io.outputs import check_output_file

        check_output_file(args.output, "-o", suffixes=(".csv", ".txt"))
    b = None if args.b == args.a else args.b
    h = StretchedHelix(args.radius, args.pitch, args.length, args.youngs_modulus, args.poisson, args.a, b)
    psi = np.linspace(h.psi0, math.radians(5.0), args.points)
    z, F = h.force_extension(psi, axial_stretch=not args.no_axial_stretch)
    cols = {"psi_deg": np.degrees(psi), "z_over_L": z, "F_N": F, "F_reduced": F / h.force_scale}
    if not all(np.all(np.isfinite(c)) for c in cols.values()):
        raise UserInputError("these inputs give a force-extension curve that is not finite "
                             "(--radius, --pitch, --length, --youngs-modulus, --a, --b)")
    write_csv(cols, args.output)
    return 0
