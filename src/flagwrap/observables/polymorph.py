"""What a polymorphic filament did (docs/polymorph.md, "Analysis"), from a run file's
order parameters ``polymorph_order`` (time, bead): the fraction of the filament in
polymorph B over time, where B first appeared (from the motor or the free end), and the
speed of the front between the two forms.

Only the vertices that transform count (:func:`~flagwrap.system.polymorph.rest_pair`: the
filament's, not the hook's or the motor's). A vertex is in B when ``phi > 0`` (the double
well's barrier top). The front is the B region's edge farthest from where B began: the
contour position where ``phi`` crosses 0 there, linearly interpolated between beads; its
speed is the slope of a least-squares line through it over the frames in which the front
exists and moves (B present and not yet the whole filament).
"""

from __future__ import annotations

import numpy as np


def transforming_vertices(config) -> np.ndarray:
    """(N,) bool over every filament's beads: the vertices whose rest shape follows phi,
    rebuilt from the config (the filaments only: no mobility is built)."""
    from flagwrap.system.parts import build_parts
    from flagwrap.system.polymorph import rest_pair

    return np.concatenate([rest_pair(p, config)[4] for p in build_parts(config)])


def polymorph_summaries(ds) -> list | None:
    """:func:`polymorph_summary` of every flagellum of the run, or ``None`` without the
    polymorph state. What all flagella share (the config, the transforming vertices, the
    two forms' heights) is computed once."""
    if "polymorph_order" not in ds.variables:
        return None
    from flagwrap.io.runfile import config_of, filament_slices
    from flagwrap.system.polymorph import polymorph_geometry

    cfg = config_of(ds)
    mask = transforming_vertices(cfg)
    fil = cfg.filament
    RB, PB, _ = polymorph_geometry(cfg)
    common = {"height_a": -fil.pitch / np.hypot(2 * np.pi * fil.helix_radius, fil.pitch),
              "height_b": -PB / np.hypot(2 * np.pi * RB, PB),
              "polymorph_a": ds.attrs.get("polymorph_a", cfg.polymorph.polymorph_a),
              "polymorph_b": ds.attrs.get("polymorph_b", cfg.polymorph.polymorph_b)}
    order, x0 = ds["polymorph_order"].values, ds["position"].values[0]
    turns, t = ds["turns"].values, ds["time"].values
    return [_summary(order[:, sl], mask[sl], x0[sl], turns, t, common)
            for sl in filament_slices(ds)]


def polymorph_summary(ds, filament: int = 0) -> dict | None:
    """``None`` for a run without the polymorph state; else, for flagellum ``filament``,

    * ``polymorph_a``, ``polymorph_b``: the two forms' library names;
    * ``fraction_b_final``, ``fraction_b_max``: the fraction of transforming vertices in B;
    * ``start_turns``, ``start_time_s``: the first frame with any vertex in B (None: never);
    * ``start_position_m``, ``start_fraction``: that vertex's contour distance from the
      filament's first bead (the motor's end) [m], and its place along the transforming
      vertices as a fraction; ``starts_at``: "motor" (first third), "middle" or "free end"
      (last third), or "present at the start" when the first frame already holds B (the
      configured initial state, not a transformation: no start position then);
    * ``front_speed_m_s``: the front's speed along the contour, positive away from where B
      began (None without a moving front over at least 3 frames);
    * ``height_a``, ``height_b``: ``-P/sqrt((2 pi R)^2 + P^2)``, the free end's height
      ``(z(L) - z(0))/L`` of each form's straight-axis helix hanging from the motor: a change
      of form moves the free end by their difference, which the buckling verdict (a rise of
      the free end) cannot tell from a buckle;
    * ``fraction_series`` (time,).
    """
    summaries = polymorph_summaries(ds)
    return None if summaries is None else summaries[filament]


def _summary(order, mask, x0, turns, t, common) -> dict:
    """One flagellum's :func:`polymorph_summary` from its order (time, N), transforming
    vertices (N,), first-frame beads (N, 3), and what all flagella share."""
    # contour distance from the filament's first bead (the motor's end of its chain)
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(x0, axis=0), axis=1))])
    phi, sm = order[:, mask], s[mask]
    inb = phi > 0.0
    frac = inb.mean(axis=1) if mask.any() else np.zeros(len(order))
    out = {**common,
           "fraction_b_final": float(frac[-1]), "fraction_b_max": float(frac.max()),
           "start_turns": None, "start_time_s": None, "start_position_m": None,
           "start_fraction": None, "starts_at": None, "front_speed_m_s": None,
           "fraction_series": frac}
    hit = np.flatnonzero(inb.any(axis=1))
    if not hit.size:
        return out
    k0 = int(hit[0])
    first = np.flatnonzero(inb[k0])
    # where B began: the B vertex of that frame with the largest phi
    j0 = int(first[np.argmax(phi[k0, first])])
    length = float(sm[-1] - sm[0]) if len(sm) > 1 else 1.0
    where = (sm[j0] - sm[0]) / length
    out.update(start_turns=float(turns[k0]), start_time_s=float(t[k0]))
    if k0 == 0:
        out["starts_at"] = "present at the start"
    else:
        out.update(start_position_m=float(sm[j0]), start_fraction=float(where),
                   starts_at="motor" if where < 1 / 3 else
                   ("free end" if where > 2 / 3 else "middle"))
    fronts, times = [], []
    for k in range(k0, len(order)):
        if not 0.0 < frac[k] < 1.0:
            continue
        p = phi[k]
        # the crossings of phi = 0 between neighbouring transforming vertices
        c = np.flatnonzero(np.sign(p[:-1]) != np.sign(p[1:]))
        if not c.size:
            continue
        pos = sm[c] + p[c] / (p[c] - p[c + 1]) * (sm[c + 1] - sm[c])
        fronts.append(pos[np.argmax(np.abs(pos - sm[j0]))])
        times.append(t[k])
    if len(fronts) >= 3 and np.ptp(times) > 0:
        f = np.asarray(fronts)
        slope = np.polyfit(np.asarray(times), f, 1)[0]
        away = np.sign(f[-1] - sm[j0]) or 1.0
        out["front_speed_m_s"] = float(slope * away)
    return out
