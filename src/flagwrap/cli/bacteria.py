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
    parser.add_argument("--stability", action="store_true",
                        help="also compute THIS model's linear threshold for each species' own "
                             "geometry (flagwrap stability on its filament: ~20-30 s per species; "
                             "docs/stability.md)")
    parser.add_argument("--model-boundary", metavar="JSON", default=None,
                        help="also place each species against THIS model's density-matched (G = 0) "
                             "boundary, read from `flagwrap figure gravity`'s gravity.json (its 0 %% "
                             "mismatch fit) or `flagwrap figure fig5`'s fig5.json (docs/gravity.md)")


def run(args: argparse.Namespace) -> int:
    from flagwrap.bacteria.species import default_species, format_table, load_species_file
    from flagwrap.errors import UserInputError

    from flagwrap.errors import check_range

    # c of M_c = c (R/L)^-3: the paper's 0.06; 1e308 divided by zero inside the table
    check_range("--prefactor", args.prefactor, 1e-6, 1e3)
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
    if args.model_boundary is not None:
        print()
        print(format_model_boundary(species, load_model_boundary(args.model_boundary), args.model_boundary))
    if args.stability:
        print()
        print(format_stability(species))
    if args.sources:
        for s in species:
            print(f"\n[{s.key}] {s.name} ({s.form})")
            for fname, p in s.provenance.items():
                val = getattr(s, fname)
                print(f"  {fname:<20} {str(val):<10} {p.status:<10} {p.source}" + (f" -- {p.note}" if p.note else ""))
    return 0


def load_model_boundary(path) -> dict:
    """The density-matched fit ``{prefactor, exponent, prefactor_beta3, ...}`` from a
    gravity.json (entry with ``density_mismatch == 0``) or a fig5.json (``fit``)."""
    import json
    import math
    from pathlib import Path

    from flagwrap.errors import UserInputError

    p = Path(path)
    try:
        doc = json.loads(p.read_text())
    except FileNotFoundError:
        raise UserInputError(f"--model-boundary: file not found: {p}") from None
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise UserInputError(f"--model-boundary: {p} is not a JSON file: {exc}") from None
    fit = None
    if isinstance(doc, dict) and isinstance(doc.get("fig5"), list):
        fit = next((f.get("fit") for f in doc["fig5"] if f.get("density_mismatch") == 0), None)
    elif isinstance(doc, dict) and isinstance(doc.get("fit"), dict):
        fit = doc["fit"]
    ok = isinstance(fit, dict) and isinstance(fit.get("prefactor_beta3"), (int, float)) \
        and math.isfinite(fit["prefactor_beta3"]) and fit["prefactor_beta3"] > 0
    if not ok:
        raise UserInputError(f"--model-boundary: {p} has no density-matched boundary fit (expected "
                             "gravity.json with a 0 % mismatch diagram, or fig5.json)")
    return fit


def format_model_boundary(species, fit: dict, source) -> str:
    """Each species' M against this model's fitted boundary (beta = 3 fixed, and free beta)."""
    import math

    c3 = fit["prefactor_beta3"]
    c, beta = fit.get("prefactor"), fit.get("exponent")
    free = isinstance(c, (int, float)) and isinstance(beta, (int, float)) and math.isfinite(c) and math.isfinite(beta)
    head = f"{'species':<39} {'M':>8} {'M/M_c paper':>11} {'M/M_c model':>11}" + (f" {'(free beta)':>11}" if free else "") + "  side (model)"
    lines = [f"This model's density-matched boundary ({source}): M_c = {c3:.3g} (R/L)^-3"
             + (f"; free fit M_c = {c:.3g} (R/L)^-{beta:.2f}" if free else "")
             + ". Measured at a/L = 1/267 (the paper's helices), extrapolated to the bacteria's own "
               "R/L: an inference, not a simulation of each species.", head, "-" * len(head)]
    for s in species:
        rl = s.radius_um / s.length_um
        r3 = s.machin / (c3 * rl ** -3)
        label = f"{s.name[:30]} ({s.form})"
        row = f"{label:<39} {s.machin:>8.4g} {s.instability_ratio(0.06):>11.3g} {r3:>11.3g}"
        if free:
            row += f" {s.machin / (c * rl ** -beta):>11.3g}"
        lines.append(row + f"  {'unstable' if r3 > 1 else 'stable'}")
    return "\n".join(lines)


def format_stability(species) -> str:
    """Each species' M against this model's linear M_c for its own filament."""
    from flagwrap.bacteria.stability import species_threshold
    from flagwrap.errors import UserInputError

    head = (f"{'species':<39} {'N':>4} {'M':>8} {'M_c model':>10} {'crossing':>8} "
            f"{'M/M_c model':>11} {'M/M_c paper':>11}  side (model)")
    lines = ["This model's linear threshold (flagwrap stability, CW, HI on, clamp) for each "
             "species' own R, P, L, a and bundle stiffness, beads at the rig's spacing "
             "(docs/stability.md, docs/bacteria.md):", head, "-" * len(head)]
    for s in species:
        label = f"{s.name[:30]} ({s.form})"
        try:
            r = species_threshold(s)
        except UserInputError as exc:
            lines.append(f"{label:<39} not computed: {exc}")
            continue
        if not r["converged"]:
            lines.append(f"{label:<39} {r['n_beads']:>4} {r['machin']:>8.4g} not found: {r['message']}")
            continue
        side = "unstable" if r["ratio_model"] > 1 else "stable"
        lines.append(f"{label:<39} {r['n_beads']:>4} {r['machin']:>8.4g} {r['machin_c_model']:>10.4g} "
                     f"{r['crossing']:>8} {r['ratio_model']:>11.3g} {r['ratio_paper_line']:>11.3g}  {side}")
    return "\n".join(lines)
