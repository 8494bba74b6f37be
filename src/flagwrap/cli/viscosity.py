"""Glycerin viscosity: falling sphere, slender-rod drag fit, Andrade fit and eta(T) (SI).

Actions (SI units: m, m/s, kg/m^3, N, Pa s; temperatures in K unless --celsius):
  sphere   eta from a terminal velocity (--velocity) or a CSV track with columns t,z
  rod      fit eta to a CSV of immersed length L and force F (SI sign convention, F < 0)
  andrade  fit eta_inf and U to a CSV with columns T,eta[,eta_err]
  at       eta at --temperature from the SI's Andrade constants (or --eta-inf/--energy)
"""

from __future__ import annotations

import argparse


def add_arguments(parser: argparse.ArgumentParser) -> None:
    sub = parser.add_subparsers(dest="action", metavar="ACTION", required=True)
    s = sub.add_parser("sphere", help="Stokes falling-sphere viscosity")
    g = s.add_mutually_exclusive_group(required=True)
    g.add_argument("--velocity", type=float, help="terminal velocity U [m/s]")
    g.add_argument("--track", help="CSV with columns t [s], z [m]; U is the fitted slope")
    s.add_argument("--velocity-error", type=float, default=0.0, help="one-sigma error of U [m/s]")
    s.add_argument("--t-min", type=float, default=None, help="fit the track only from this time [s]")
    s.add_argument("--radius", type=float, default=2.5e-3, help="sphere radius [m] (SI: 2.5e-3)")
    s.add_argument("--density", type=float, default=7420.0, help="sphere density [kg/m^3] (SI: 7420)")
    s.add_argument("--fluid-density", type=float, default=1250.0, help="liquid density [kg/m^3] (SI: 1250)")

    r = sub.add_parser("rod", help="fit eta to slender-rod force vs immersed length")
    r.add_argument("csv", help="CSV with columns L [m], F [N][, F_err [N]]")
    r.add_argument("--speed", type=float, default=5e-3, help="insertion speed U [m/s] (SI: 5e-3)")
    r.add_argument("--radius", type=float, default=2e-3, help="rod radius [m] (SI: 2e-3)")
    r.add_argument("--fluid-density", type=float, default=1250.0, help="liquid density [kg/m^3]")
    r.add_argument("--fit-density", action="store_true", help="also fit the buoyancy density")

    a = sub.add_parser("andrade", help="fit Andrade's law eta = eta_inf exp(U/k_B T)")
    a.add_argument("csv", help="CSV with columns T, eta [Pa s][, eta_err [Pa s]]")
    a.add_argument("--celsius", action="store_true", help="T column is in degrees Celsius")

    t = sub.add_parser("at", help="eta(T) from Andrade's law")
    t.add_argument("--temperature", type=float, required=True, help="temperature [K] (or C with --celsius)")
    t.add_argument("--celsius", action="store_true")
    t.add_argument("--eta-inf", type=float, default=None, help="Pa s (default: SI 6.92687e-10)")
    t.add_argument("--energy", type=float, default=None, help="J (default: SI 8.559e-20)")
    t.add_argument("--machin", type=float, default=None,
                   help="also rescale this M (computed at 20 C) to the given temperature")


def run(args: argparse.Namespace) -> int:
    from flagwrap.cli.triangulate import read_csv_columns
    from flagwrap.experiment import viscosity as vis

    if args.action == "sphere":
        if args.track:
            c = read_csv_columns(args.track, ("t", "z"))
            fit = vis.terminal_velocity_fit(c["t"], c["z"], t_min=args.t_min)
            U, dU = abs(fit.slope), fit.slope_error
            print(f"terminal velocity U = {U:.6g} +- {dU:.2g} m/s")
        else:
            U, dU = args.velocity, args.velocity_error
        res = vis.sphere_viscosity(U, args.radius, args.density, args.fluid_density, velocity_error=dU)
        print(f"eta = {res.viscosity:.6g} +- {res.viscosity_error:.2g} Pa s")
        print(f"Re (liquid density) = {res.reynolds_fluid:.3g}; Re (sphere density) = {res.reynolds_sphere:.3g}")
    elif args.action == "rod":
        c = read_csv_columns(args.csv, ("L", "F"), ("F_err",))
        res = vis.fit_rod_viscosity(c["L"], c["F"], args.speed, args.radius, args.fluid_density,
                                    fit_density=args.fit_density, force_error=c.get("F_err"))
        print(f"eta = {res.viscosity:.6g} +- {res.viscosity_error:.2g} Pa s")
        if args.fit_density:
            print(f"rho_gly = {res.fluid_density:.6g} +- {res.fluid_density_error:.2g} kg/m^3")
    elif args.action == "andrade":
        c = read_csv_columns(args.csv, ("T", "eta"), ("eta_err",))
        T = _kelvin(c["T"], args.celsius)
        res = vis.fit_andrade(T, c["eta"], c.get("eta_err"))
        print(f"eta_inf = {res.eta_inf:.6g} Pa s (ln: {res.log_eta_inf:.6g} +- {res.log_eta_inf_error:.2g})")
        print(f"U = {res.energy:.6g} +- {res.energy_error:.2g} J")
        print(f"corr(ln eta_inf, U) = {res.correlation:.4f}; reduced chi2 = {res.chi2_reduced:.3g}")
    else:
        T = float(_kelvin(args.temperature, args.celsius))
        kw = {}
        if args.eta_inf is not None:
            kw["eta_inf"] = args.eta_inf
        if args.energy is not None:
            kw["energy"] = args.energy
        print(f"eta({T:.2f} K) = {float(vis.andrade_viscosity(T, **kw)):.6g} Pa s")
        if args.machin is not None:
            print(f"M({T:.2f} K) = {vis.machin_at_temperature(args.machin, T, **kw):.6g} (from M(293.15 K) = {args.machin:g})")
    return 0


def _kelvin(T, celsius: bool):
    """Temperatures in K; values below 200 K are refused as a forgotten ``--celsius`` (the
    Andrade law of the paper's glycerol holds in its liquid range, above ~290 K)."""
    import numpy as np

    from flagwrap.errors import UserInputError

    T = np.asarray(T, dtype=float) + (273.15 if celsius else 0.0)
    if np.any(T < 200.0):
        raise UserInputError(f"temperature {float(np.min(T)):g} K is below 200 K: give Kelvin, "
                             "or degrees Celsius with --celsius")
    return T
