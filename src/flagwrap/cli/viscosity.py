"""Glycerin viscosity: falling sphere, slender-rod drag fit, Andrade fit and eta(T) (SI).

Actions (SI units: m, m/s, kg/m^3, N, Pa s; temperatures in K unless --celsius):
  sphere   eta from a terminal velocity (--velocity) or a CSV track with columns t,z
  rod      fit eta to a CSV of immersed length L and force F (SI sign convention, F < 0)
  andrade  fit eta_inf and U to a CSV with columns T,eta[,eta_err]
  at       eta at --temperature from the SI's Andrade constants (or --eta-inf/--energy)
"""

from __future__ import annotations

import argparse

# physical ranges (SI) of what goes in and what comes out, so that no value overflows and no
# absurd number is printed as a measurement (1e308 inputs printed eta = inf, exit 0)
#: a viscosity [Pa s]: from gases (1.8e-5) to pitch (2e8) and beyond, below glasses
ETA_RANGE = (1e-6, 1e12)
#: a terminal velocity or insertion speed [m/s]
SPEED_RANGE = (1e-9, 10.0)
#: a sphere's or rod's radius [m]
RADIUS_RANGE = (1e-6, 1.0)
#: an absolute temperature [K] (below 200 K: a forgotten --celsius)
TEMPERATURE_RANGE = (200.0, 2000.0)


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


def _check_options(args) -> None:
    """Every number within its physical range, before anything is read or fitted."""
    from flagwrap.cli.density import DENSITY_RANGE
    from flagwrap.errors import check_range

    checks = {
        "sphere": (("--velocity", "velocity", *SPEED_RANGE, "m/s"),
                   ("--velocity-error", "velocity_error", 0.0, SPEED_RANGE[1], "m/s"),
                   ("--t-min", "t_min", -1e9, 1e9, "s"),
                   ("--radius", "radius", *RADIUS_RANGE, "m"),
                   ("--density", "density", *DENSITY_RANGE, "kg/m^3"),
                   ("--fluid-density", "fluid_density", *DENSITY_RANGE, "kg/m^3")),
        "rod": (("--speed", "speed", *SPEED_RANGE, "m/s"),
                ("--radius", "radius", *RADIUS_RANGE, "m"),
                ("--fluid-density", "fluid_density", *DENSITY_RANGE, "kg/m^3")),
        "andrade": (),
        "at": (("--eta-inf", "eta_inf", 1e-30, 1e6, "Pa s"),
               ("--energy", "energy", 1e-25, 1e-17, "J"),
               ("--machin", "machin", 1e-12, 1e12, "")),
    }[args.action]
    for opt, attr, lo, hi, unit in checks:
        v = getattr(args, attr)
        if v is not None:
            check_range(opt, v, lo, hi, unit)


def run(args: argparse.Namespace) -> int:
    from flagwrap.cli.density import DENSITY_RANGE
    from flagwrap.cli.triangulate import read_csv_columns
    from flagwrap.errors import UserInputError, check_result
    from flagwrap.experiment import viscosity as vis

    _check_options(args)
    eta_lo, eta_hi = ETA_RANGE

    def check_eta(value, error, hint):
        check_result("eta", value, eta_lo, eta_hi, "Pa s", hint)
        check_result("eta's error", error, 0.0, eta_hi, "Pa s", hint)

    if args.action == "sphere":
        if args.track:
            c = read_csv_columns(args.track, ("t", "z"), bounds={"t": (-1e9, 1e9, "s"), "z": (-1e3, 1e3, "m")})
            t = c["t"] if args.t_min is None else c["t"][c["t"] >= args.t_min]
            if len(set(t.tolist())) < 2:
                raise UserInputError(f"{args.track}: the track (from --t-min on) needs at least 2 different "
                                     f"times t to fit a velocity, got {len(set(t.tolist()))}")
            fit = vis.terminal_velocity_fit(c["t"], c["z"], t_min=args.t_min)
            U, dU = abs(fit.slope), fit.slope_error
            hint = f"the track {args.track} is not a sphere falling at a steady speed (check its units: t in s, z in m)"
            check_result("terminal velocity U", U, *SPEED_RANGE, "m/s", hint)
            check_result("U's error", dU, 0.0, SPEED_RANGE[1], "m/s", hint)
            print(f"terminal velocity U = {U:.6g} +- {dU:.2g} m/s")
        else:
            U, dU = args.velocity, args.velocity_error
        res = vis.sphere_viscosity(U, args.radius, args.density, args.fluid_density, velocity_error=dU)
        check_eta(res.viscosity, res.viscosity_error, "check --velocity, --radius and the densities (SI units)")
        print(f"eta = {res.viscosity:.6g} +- {res.viscosity_error:.2g} Pa s")
        print(f"Re (liquid density) = {res.reynolds_fluid:.3g}; Re (sphere density) = {res.reynolds_sphere:.3g}")
    elif args.action == "rod":
        c = read_csv_columns(args.csv, ("L", "F"), ("F_err",),
                             bounds={"L": (1e-6, 100.0, "m"), "F": (-1e6, 1e6, "N"), "F_err": (1e-15, 1e6, "N")})
        n_lengths = len(set(c["L"].tolist()))
        need = 2 if args.fit_density else 1
        if n_lengths < need or c["L"].size <= need:
            raise UserInputError(f"{args.csv}: fitting eta{' and the density' if args.fit_density else ''} needs "
                                 f"more than {need} rows and at least {need} different immersed lengths L, got "
                                 f"{c['L'].size} rows, {n_lengths} different")
        res = vis.fit_rod_viscosity(c["L"], c["F"], args.speed, args.radius, args.fluid_density,
                                    fit_density=args.fit_density, force_error=c.get("F_err"))
        hint = f"the forces in {args.csv} do not follow a rod's drag (check the units: L in m, F in N)"
        check_eta(res.viscosity, res.viscosity_error, hint)
        if args.fit_density:
            check_result("rho_gly", res.fluid_density, *DENSITY_RANGE, "kg/m^3", hint)
            check_result("rho_gly's error", res.fluid_density_error, 0.0, DENSITY_RANGE[1], "kg/m^3", hint)
        print(f"eta = {res.viscosity:.6g} +- {res.viscosity_error:.2g} Pa s")
        if args.fit_density:
            print(f"rho_gly = {res.fluid_density:.6g} +- {res.fluid_density_error:.2g} kg/m^3")
    elif args.action == "andrade":
        c = read_csv_columns(args.csv, ("T", "eta"), ("eta_err",),
                             bounds={"T": (-1e4, 1e4, "K or C"), "eta": (*ETA_RANGE, "Pa s"),
                                     "eta_err": (1e-300, ETA_RANGE[1], "Pa s")})
        T = _kelvin(c["T"], args.celsius)
        if len(set(T.tolist())) < 2:
            raise UserInputError(f"{args.csv}: fitting Andrade's law needs at least 2 different temperatures, got 1")
        res = vis.fit_andrade(T, c["eta"], c.get("eta_err"))
        hint = f"the viscosities in {args.csv} do not fall with temperature as a liquid's do"
        check_result("U", res.energy, 0.0, 1e-17, "J", hint)
        check_result("U's error", res.energy_error, 0.0, 1e-17, "J", hint)
        check_result("eta_inf", res.eta_inf, 1e-300, eta_hi, "Pa s", hint)
        check_result("ln eta_inf's error", res.log_eta_inf_error, 0.0, 700.0, "", hint)
        print(f"eta_inf = {res.eta_inf:.6g} Pa s (ln: {res.log_eta_inf:.6g} +- {res.log_eta_inf_error:.2g})")
        print(f"U = {res.energy:.6g} +- {res.energy_error:.2g} J")
        print(f"corr(ln eta_inf, U) = {res.correlation:.4f}; reduced chi2 = {res.chi2_reduced:.3g}")
    else:
        T = float(_kelvin(args.temperature, args.celsius, "--temperature"))
        kw = {}
        if args.eta_inf is not None:
            kw["eta_inf"] = args.eta_inf
        if args.energy is not None:
            kw["energy"] = args.energy
        import numpy as np

        with np.errstate(over="ignore"):
            eta = float(vis.andrade_viscosity(T, **kw))
        check_eta(eta, 0.0, "check --eta-inf and --energy")
        if args.machin is not None:
            with np.errstate(over="ignore"):
                m = vis.machin_at_temperature(args.machin, T, **kw)
            check_result("M", m, 1e-12, 1e12, "", "check --machin, --eta-inf and --energy")
        print(f"eta({T:.2f} K) = {eta:.6g} Pa s")
        if args.machin is not None:
            print(f"M({T:.2f} K) = {m:.6g} (from M(293.15 K) = {args.machin:g})")
    return 0


def _kelvin(T, celsius: bool, what: str = "temperature"):
    """Temperatures in K within :data:`TEMPERATURE_RANGE`; values below 200 K are refused as a
    forgotten ``--celsius`` (the Andrade law of the paper's glycerol holds in its liquid range,
    above ~290 K)."""
    import numpy as np

    from flagwrap.errors import UserInputError

    T = np.asarray(T, dtype=float) + (273.15 if celsius else 0.0)
    lo, hi = TEMPERATURE_RANGE
    if not np.all(np.isfinite(T)):
        raise UserInputError(f"{what} must be finite, got {float(T[~np.isfinite(T)].flat[0])!r}")
    if np.any(T < lo):
        raise UserInputError(f"{what} {float(np.min(T)):g} K is below {lo:g} K: give Kelvin, "
                             "or degrees Celsius with --celsius")
    if np.any(T > hi):
        raise UserInputError(f"{what} must be in [{lo:g}, {hi:g}] K, got {float(np.max(T)):g} K")
    return T
