"""Paper figures, one function per figure; each writes ``NAME.png`` and ``NAME.pdf`` into ``outdir``.

Functions take an output folder and numerical knobs, compute what they plot, and return the
paths written. Headless (Agg backend).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

__all__ = ["fig3"]

#: SI stretching-test helix (SI "Uniaxial stretching test of a helix"), lengths [m], E [Pa].
FIG3_HELIX = dict(radius=15e-3, pitch=34e-3, length=305e-3, youngs_modulus=1.2 * 1.33e6, poisson_ratio=0.49)


def _save(fig, outdir: Path, name: str) -> list[Path]:
    outdir.mkdir(parents=True, exist_ok=True)
    paths = [outdir / f"{name}.png", outdir / f"{name}.pdf"]
    fig.savefig(paths[0], dpi=150)
    fig.savefig(paths[1])
    return paths


def fig3(outdir: str | Path = "out/figures", *, n_beads: int = 201, n_steps: int = 40,
         long_factor: int = 3, z_over_L_max: float = 0.95) -> list[Path]:
    """Main text Fig. 3(b) / SI Fig. S(HelicalForce): force-extension of the stretched helix.

    Left: pulling force ``F`` [mN] against ``z/L`` for the SI helix (2R = 30 mm, P = 34 mm,
    L = 305 mm, E = 1.2 x 1.33 MPa, nu = 0.49): main text Eq. 1 for the round section
    ``a = 1.5 mm`` with ``z/L = cos psi + F/(pi E a^2)``; the SI's elliptic law
    (``2a = 3.19 mm``, ``2b = 2.88 mm``, derived form, see :mod:`flagwrap.theory.stretching`);
    the quasi-static bead simulation (:func:`flagwrap.quasistatic.stretch_helix`, round
    section, moment-free ends pulled by their end points) for the helix itself and for one
    ``long_factor`` times longer (same ``R``, ``P``, more turns; the law does not depend on
    ``L`` at fixed ``z/L``). Right: relative deviation of the bead force from Eq. 1.

    Parameters
    ----------
    outdir : str or Path
        output folder (created).
    n_beads : int
        beads of the L = 305 mm helix (the long one gets ``long_factor (n_beads-1) + 1``).
    n_steps : int
        extension steps from rest to ``z_over_L_max``.
    long_factor : int
        length multiplier of the second simulated helix (0: omit it).

    Returns
    -------
    list of Path
        the PNG and PDF written.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from flagwrap.quasistatic import law_force_at_extension, stretch_helix
    from flagwrap.theory.stretching import StretchedHelix

    round_h = StretchedHelix(semi_axis_a=1.5e-3, **FIG3_HELIX)
    ellip_h = StretchedHelix(semi_axis_a=3.19e-3 / 2, semi_axis_b=2.88e-3 / 2, **FIG3_HELIX)
    runs = [(round_h, stretch_helix(round_h, n_beads, z_over_L_max, n_steps))]
    if long_factor and long_factor > 1:
        lh = StretchedHelix(semi_axis_a=1.5e-3, **{**FIG3_HELIX, "length": long_factor * FIG3_HELIX["length"]})
        runs.append((lh, stretch_helix(lh, long_factor * (n_beads - 1) + 1, z_over_L_max, n_steps)))

    psi = np.linspace(np.deg2rad(14.0), round_h.psi0, 400)
    fig, (ax, axd) = plt.subplots(1, 2, figsize=(10, 4.2), constrained_layout=True)
    zr, Fr = round_h.force_extension(psi)
    ax.plot(zr, 1e3 * Fr, "C0-", lw=2, label=f"Eq. 1, round a = 1.5 mm ($A\\kappa_0^2$ = {1e3 * round_h.force_scale:.1f} mN)")
    ze, Fe = ellip_h.force_extension(psi)
    ax.plot(ze, 1e3 * Fe, "C2--", lw=1.5,
            label=f"SI law, elliptic 2a = 3.19, 2b = 2.88 mm ($A_2\\kappa_0^2$ = {1e3 * ellip_h.force_scale:.1f} mN)")
    styles = [("C3o", "full"), ("C1s", "none")]
    for (h, r), (st, fill) in zip(runs, styles):
        lab = f"bead model, L = {1e3 * h.length:.0f} mm ({h.turns:.1f} turns, N = {r.n_beads})"
        ax.plot(r.z_over_L, 1e3 * r.force, st, ms=4, fillstyle=fill, label=lab)
        sel = r.z_over_L > r.z_over_L[0] + 0.02
        dev = (r.force[sel] - law_force_at_extension(h, r.z_over_L[sel])) / law_force_at_extension(h, r.z_over_L[sel])
        axd.plot(r.z_over_L[sel], 100 * dev, st + "-", ms=4, fillstyle=fill, label=lab)
    ax.set_xlabel("extension z/L")
    ax.set_ylabel("pulling force F [mN]")
    ax.set_xlim(0.3, 1.0)
    ax.set_ylim(bottom=-1.0)
    ax.legend(fontsize=7, loc="upper left")
    ax.set_title("Fig. 3(b): stretching with moment-free ends", fontsize=10)
    for y in (-3, 3):
        axd.axhline(y, color="0.6", lw=0.8, ls=":")
    axd.axhline(0, color="C0", lw=1)
    axd.axvline(0.9, color="0.6", lw=0.8, ls=":")
    axd.set_xlabel("extension z/L")
    axd.set_ylabel("(F$_{bead}$ - F$_{Eq. 1}$) / F$_{Eq. 1}$ [%]")
    axd.set_xlim(0.3, 1.0)
    axd.legend(fontsize=7, loc="lower right")
    axd.set_title("deviation from Eq. 1 (finite length: ends on the force line)", fontsize=10)
    paths = _save(fig, Path(outdir), "fig3")
    plt.close(fig)
    return paths
