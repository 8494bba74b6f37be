"""Each species against this model's own threshold, computed for its own geometry.

The paper places bacteria on its scaling line ``M_c = 0.06 (R/L)^-3``, measured on table-top
helices with ``L/a ~ 270``. A bacterial flagellum has ``L/a ~ 700`` and its own pitch. This
module builds the species' filament as a config and computes its linear threshold with
:mod:`flagwrap.stability`:
* SI geometry ``L``, ``R``, ``P`` and ``a`` from the species table;
* a bundle of ``n`` flagella as one filament of bending stiffness ``n A_1`` (the paper's
  ``B_n = n B_1``; Young's modulus ``n E``, same radius);
* its fluid ``eta`` and its motor frequency, HI on, the clamp, the paper's transparent body
  (``R/R_cell = 0.6``).

The bead spacing is the paper's rig's: ``b = a / 0.225`` (1.5 mm beads 6.67 mm apart at
N = 61). That gives N ~ 160 for a 7 um flagellum, where a bacterium with the rig's N = 61
would have a 2.6x sparser, leakier bead chain. A species without a pitch (C. insecticola,
coil form) is refused by name: its steady whirl cannot be built.
"""

from __future__ import annotations

import math

from flagwrap.errors import UserInputError

#: bead radius over bead spacing of the paper's rig (a = 1.5 mm, L = 0.4 m, N = 61)
PAPER_RADIUS_OVER_SPACING = 1.5 / (400.0 / 60.0)
MAX_BEADS = 400


def species_config(sp, n_beads: int | None = None, hydrodynamics: bool = True):
    """The SI config of species ``sp`` (:class:`flagwrap.bacteria.species.Species`)."""
    from flagwrap.io.config import config_from_dict

    if sp.pitch_um is None:
        raise UserInputError(f"species {sp.key!r}: pitch_um is not known, so its helix (and its "
                             f"steady whirl) cannot be built; give pitch_um in a species file")
    L = sp.length_um * 1e-6
    a = sp.filament_radius_nm * 1e-9
    if n_beads is None:
        n_beads = int(round(L * PAPER_RADIUS_OVER_SPACING / a)) + 1
    if not 21 <= n_beads <= MAX_BEADS:
        raise UserInputError(f"species {sp.key!r}: {n_beads} beads for L/a = {L / a:.0f} at the "
                             f"rig's spacing; allowed 21..{MAX_BEADS} (give n_beads)")
    d = {
        "name": sp.key,
        "filament": {"length": L, "helix_radius": sp.radius_um * 1e-6, "pitch": sp.pitch_um * 1e-6,
                     "cross_section_radius": a,
                     "youngs_modulus": sp.n_flagella * sp.youngs_modulus_pa,
                     "poisson_ratio": 0.49, "handedness": "left", "n_beads": n_beads,
                     "stretch_stiffness": 1000.0},
        "fluid": {"viscosity": sp.viscosity_pa_s, "density": 1000.0},
        "body": {"radius_ratio": 0.6, "enabled": True},
        "motor": {"frequency": sp.frequency_hz,
                  "protocol": [{"direction": "ccw", "turns": 1.0}, {"direction": "cw", "turns": 1.0}]},
        "numerics": {"hydrodynamics": bool(hydrodynamics)},
    }
    return config_from_dict(d)


def species_threshold(sp, n_beads: int | None = None, hydrodynamics: bool = True,
                      m_factor: float = 30.0) -> dict:
    """M_c (CW) of the species' own filament by linear stability, with its M and both ratios."""
    from flagwrap.stability.threshold import critical_from_config

    cfg = species_config(sp, n_beads, hydrodynamics)
    m_max = m_factor * max(cfg.machin_critical_scaling, cfg.machin)
    r = critical_from_config(cfg, "cw", m_max=m_max)
    mc = r.machin_c if r.converged else math.nan
    return {"key": sp.key, "name": sp.name, "form": sp.form, "n_beads": cfg.filament.n_beads,
            "machin": cfg.machin, "machin_c_model": mc, "crossing": r.crossing or None,
            "ratio_model": cfg.machin / mc if r.converged else math.nan,
            "ratio_paper_line": sp.instability_ratio(0.06), "converged": r.converged,
            "message": r.message, "wall_time_s": r.wall_time}
