"""Density of the iron-oxide-filled elastomer, or the powder mass for a target density (SI).

Either give one batch (--base, --catalyst, --powder masses, any one unit), a CSV of batches
(columns m_base,m_cat,m_feo), or --polymer-mass with --target to get the powder mass.
Densities in kg/m^3 (defaults: HTV-4000 1150, iron oxide 5740, glycerin 1250).
"""

from __future__ import annotations

import argparse


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("batches_csv", nargs="?", default=None, help="CSV with columns m_base,m_cat,m_feo")
    parser.add_argument("--base", type=float, help="base mass")
    parser.add_argument("--catalyst", type=float, help="catalyst mass")
    parser.add_argument("--powder", type=float, help="iron oxide mass")
    parser.add_argument("--polymer-mass", type=float, help="base + catalyst mass, to compute the powder mass")
    parser.add_argument("--target", type=float, default=None, help="target density [kg/m^3] (default: --fluid)")
    parser.add_argument("--rho-polymer", type=float, default=1150.0, help="[kg/m^3]")
    parser.add_argument("--rho-powder", type=float, default=5740.0, help="[kg/m^3]")
    parser.add_argument("--fluid", type=float, default=1250.0, help="liquid density for the mismatch [kg/m^3]")


def run(args: argparse.Namespace) -> int:
    import numpy as np

    from flagwrap.cli.triangulate import read_csv_columns, write_csv
    from flagwrap.errors import UserInputError
    from flagwrap.experiment.density import density_mismatch, effective_density, powder_mass_for_density

    if args.polymer_mass is not None:
        target = args.fluid if args.target is None else args.target
        m = float(powder_mass_for_density(args.polymer_mass, target, args.rho_polymer, args.rho_powder))
        print(f"powder mass = {m:.6g} (same unit as --polymer-mass) for rho_eff = {target:g} kg/m^3")
        return 0
    if args.batches_csv:
        c = read_csv_columns(args.batches_csv, ("m_base", "m_cat", "m_feo"))
        mb, mc, mf = c["m_base"], c["m_cat"], c["m_feo"]
    elif None not in (args.base, args.catalyst, args.powder):
        mb, mc, mf = (np.atleast_1d(float(v)) for v in (args.base, args.catalyst, args.powder))
    else:
        raise UserInputError("give a batches CSV, or --base, --catalyst and --powder, or --polymer-mass")
    rho = effective_density(mb, mc, mf, args.rho_polymer, args.rho_powder)
    write_csv({"m_base": mb, "m_cat": mc, "m_feo": mf, "rho_eff": rho,
               "mismatch": density_mismatch(rho, args.fluid)}, None)
    return 0
