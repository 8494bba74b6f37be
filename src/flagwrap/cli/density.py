"""Density of the iron-oxide-filled elastomer, or the powder mass for a target density (SI).

Either give one batch (--base, --catalyst, --powder masses, any one unit), a CSV of batches
(columns m_base,m_cat,m_feo), or --polymer-mass with --target to get the powder mass.
Densities in kg/m^3 (defaults: HTV-4000 1150, iron oxide 5740, glycerin 1250).
"""

from __future__ import annotations

import argparse

#: physical range of a density here [kg/m^3]: from the lightest liquids to the densest solids
#: (osmium, 22590); a value in g/cm^3 (1.15) falls below it and is named
DENSITY_RANGE = (100.0, 30000.0)
#: bound of a mass (any one unit): a lab batch is grams to kilograms; 1e308 overflowed the sums
MASS_MAX = 1e12
#: the powder's largest volume fraction in the cured mix: the densest packing of spheres
#: (pi / sqrt(18) = 0.7405); beyond it no polymer fills the gaps between the grains
MAX_POWDER_VOLUME_FRACTION = 0.74


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


def _check_options(args) -> None:
    """Every number within its physical range, before anything is computed (1e308 masses gave
    rho_eff = nan, a target next to the powder's density 2e14 g of powder per g, exit 0)."""
    from flagwrap.errors import check_range

    lo, hi = DENSITY_RANGE
    for opt in ("rho_polymer", "rho_powder", "fluid", "target"):
        v = getattr(args, opt)
        if v is not None:
            check_range("--" + opt.replace("_", "-"), v, lo, hi, "kg/m^3")
    for opt in ("base", "catalyst", "powder"):
        v = getattr(args, opt)
        if v is not None:
            check_range("--" + opt, v, 0.0, MASS_MAX, "(mass, any one unit)")
    if args.polymer_mass is not None:
        check_range("--polymer-mass", args.polymer_mass, 1e-12, MASS_MAX, "(mass, any one unit)")
    if args.rho_powder <= args.rho_polymer:
        from flagwrap.errors import UserInputError

        raise UserInputError(f"--rho-powder = {args.rho_powder:g} kg/m^3 must exceed --rho-polymer = "
                             f"{args.rho_polymer:g} kg/m^3 (the filler makes the elastomer heavier)")


def _powder_volume_fraction(mp, mf, rp, rf):
    import numpy as np

    vp, vf = np.asarray(mp, dtype=float) / rp, np.asarray(mf, dtype=float) / rf
    return vf / (vp + vf)


def run(args: argparse.Namespace) -> int:
    import numpy as np

    from flagwrap.cli.triangulate import read_csv_columns, write_csv
    from flagwrap.errors import UserInputError, check_result
    from flagwrap.experiment.density import density_mismatch, effective_density, powder_mass_for_density

    _check_options(args)
    phi_max = MAX_POWDER_VOLUME_FRACTION
    rp, rf = args.rho_polymer, args.rho_powder
    if args.polymer_mass is not None:
        target = args.fluid if args.target is None else args.target
        t_max = rp + phi_max * (rf - rp)  # phi = (rho_t - rho_p) / (rho_f - rho_p)
        if not rp <= target <= t_max:
            raise UserInputError(
                f"--target = {target:g} kg/m^3 must be in [--rho-polymer, --rho-polymer + {phi_max} "
                f"(--rho-powder - --rho-polymer)] = [{rp:g}, {t_max:.6g}] kg/m^3 (above it the powder "
                f"would fill more than {phi_max:.0%} of the volume, past the densest packing)")
        m = float(powder_mass_for_density(args.polymer_mass, target, rp, rf))
        check_result("powder mass", m, 0.0, MASS_MAX * 1e3, "(unit of --polymer-mass)")
        print(f"powder mass = {m:.6g} (same unit as --polymer-mass) for rho_eff = {target:g} kg/m^3")
        return 0
    if args.batches_csv:
        mass = (0.0, MASS_MAX, "(mass, any one unit)")
        c = read_csv_columns(args.batches_csv, ("m_base", "m_cat", "m_feo"),
                             bounds={"m_base": mass, "m_cat": mass, "m_feo": mass})
        mb, mc, mf = c["m_base"], c["m_cat"], c["m_feo"]
        csv = args.batches_csv
        where = lambda k: f"{csv}: data row {k + 1}:"  # noqa: E731
    elif None not in (args.base, args.catalyst, args.powder):
        mb, mc, mf = (np.atleast_1d(float(v)) for v in (args.base, args.catalyst, args.powder))
        where = lambda k: "--base/--catalyst/--powder:"  # noqa: E731
    else:
        raise UserInputError("give a batches CSV, or --base, --catalyst and --powder, or --polymer-mass")
    mp = mb + mc
    if np.any(mp <= 0):
        k = int(np.argmax(mp <= 0))
        raise UserInputError(f"{where(k)} base + catalyst mass must be > 0")
    phi = _powder_volume_fraction(mp, mf, rp, rf)
    if np.any(phi > phi_max):
        k = int(np.argmax(phi > phi_max))
        raise UserInputError(
            f"{where(k)} the powder would fill {phi[k]:.3g} of the "
            f"volume, more than {phi_max} (the densest packing: no polymer left between the grains); "
            f"m_feo / (m_base + m_cat) must be <= {phi_max / (1 - phi_max) * rf / rp:.4g}")
    rho = effective_density(mb, mc, mf, rp, rf)
    mis = density_mismatch(rho, args.fluid)
    for k in range(rho.size):
        check_result("rho_eff", rho[k], rp, rf, "kg/m^3")
        check_result("mismatch", mis[k], 0.0, 1e3)
    write_csv({"m_base": mb, "m_cat": mc, "m_feo": mf, "rho_eff": rho, "mismatch": mis}, None)
    return 0
