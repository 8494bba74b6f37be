"""Where the filament is against a plane wall (``[[wall]]``; docs/confinement.md), from a run
file's positions: the gap between each bead's surface and the wall (its centre's height above
the plane less the filament's radius ``a``), its smallest value over the run and at the end,
and the free end's height above the wall."""

from __future__ import annotations

import numpy as np


def wall_summary(ds) -> dict | None:
    """``None`` for a run without a wall; else ``gap_min`` [m] (smallest bead gap over the
    run, negative: a bead's surface past the plane, which contact resists), ``gap_min_turns``
    (when), ``gap_final`` [m] (the last frame's), ``tip_height_final`` [m] (the first
    flagellum's free end above the wall), ``gap_series`` (time,) [m]."""
    from flagwrap.io.runfile import config_of

    cfg = config_of(ds)
    if not cfg.walls:
        return None
    w = cfg.walls[0]
    n, p = w.unit_normal, np.asarray(w.point, float)
    x = ds["position"].values  # (time, bead, xyz), lab frame [m]
    gap = (x - p) @ n - cfg.filament.cross_section_radius
    series = gap.min(axis=1)
    k = int(np.argmin(series))
    return {"gap_min": float(series[k]), "gap_min_turns": float(ds["turns"].values[k]),
            "gap_final": float(series[-1]),
            "tip_height_final": float((ds["tip_position"].values[-1] - p) @ n),
            "gap_series": series}
