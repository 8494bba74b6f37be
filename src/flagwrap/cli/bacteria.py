"""Place flagellar-wrapping bacteria on the stability diagram (M vs (R/L)^3, SI data).

Prints the packaged species (SI, "Parameter values of flagellar-wrapping bacteria") with
M = eta omega L^4 / A, A = n pi E a^4 / 4, and M/M_c for M_c = 0.06 (R/L)^-3. Add your own
species with --file USER.toml (same schema as flagwrap/data/bacteria.toml).
"""

from __future__ import annotations

import argparse


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--file", action="append", default=[], help="extra species TOML (repeatable)")
    parser.add_argument("--only-file", action="store_true", help="omit the packaged species")
    parser.add_argument("--prefactor", type=float, default=0.06, help="c in M_c = c (R/L)^-3 (default 0.06)")
    parser.add_argument("--sources", action="store_true", help="also list every parameter's source and status")
    parser.add_argument("--csv", action="store_true", help="machine-readable CSV instead of the table")


def run(args: argparse.Namespace) -> int:
    from flagwrap.bacteria.species import default_species, format_table, load_species_file
    from flagwrap.errors import UserInputError

    species = [] if args.only_file else default_species()
    for f in args.file:
        species += load_species_file(f)
    if not species:
        raise UserInputError("no species to show (use --file with --only-file)")
    keys = [s.key for s in species]
    if len(set(keys)) != len(keys):
        raise UserInputError("duplicate species keys across files")
    if args.csv:
        print("key,name,form,n_flagella,radius_um,length_um,frequency_hz,viscosity_pa_s,A_pn_um2,M,R_over_L_cubed,M_c,M_over_M_c,side,paper_side")
        for s in species:
            print(",".join(str(v) for v in (
                s.key, s.name, s.form, s.n_flagella, s.radius_um, s.length_um, s.frequency_hz, s.viscosity_pa_s,
                f"{s.bending_stiffness_pn_um2:.6g}", f"{s.machin:.6g}", f"{s.radius_over_length_cubed:.6g}",
                f"{s.critical_machin(args.prefactor):.6g}", f"{s.instability_ratio(args.prefactor):.6g}",
                s.side(args.prefactor), s.paper_side or "")))
        return 0
    print(format_table(species, args.prefactor))
    for s in species:
        if s.paper_side is not None and s.paper_side != s.side(args.prefactor):
            need = s.crossing_inputs(args.prefactor)
            print(f"\n{s.key}: lands {s.side(args.prefactor)} but the paper says {s.paper_side}. "
                  f"Any one of these would put it on the boundary: eta = {need['viscosity_pa_s'] * 1e3:.3g} mPa s, "
                  f"f = {need['frequency_hz']:.3g} Hz, n = {need['n_flagella']:.3g}, L = {need['length_um']:.3g} um, "
                  f"R = {need['radius_um']:.3g} um, prefactor c = {need['prefactor']:.3g}.")
    if args.sources:
        for s in species:
            print(f"\n[{s.key}] {s.name} ({s.form})")
            for fname, p in s.provenance.items():
                val = getattr(s, fname)
                print(f"  {fname:<20} {str(val):<10} {p.status:<10} {p.source}" + (f" -- {p.note}" if p.note else ""))
    return 0
