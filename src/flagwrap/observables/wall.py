"""Where the filament and the cell are against a boundary (``[[wall]]`` or ``[[tube]]``;
docs/confinement.md, "Observables"), from a run file's positions.

* Every run: the gap between each bead's surface and the boundary (its centre's distance
  to it less the filament's radius ``a``; for a tube :meth:`flagwrap.confinement.tube.Tube.gap`),
  its smallest value over the run and at the end, and the free end's distance from the
  boundary: its height above a wall, its distance from a tube's axis.
* A free cell beside a wall: its body centre's height above the wall over the run, the angle
  of its axis to the wall's plane at the end, and over the last turns its speed parallel
  to the wall and towards it (the body centre's displacement over the window, as
  :func:`flagwrap.observables.swimming.phase_summary` measures the swimming speed).
* A free cell in a tube: its body centre's distance from the tube's axis over the run, the
  angle of its axis to the tube's at the end, and over the last turns its speed along the
  tube and away from its axis.
"""

from __future__ import annotations

import math

import numpy as np


def wall_summary(ds, final_turns: float = 1.0) -> dict | None:
    """``None`` for a run without a wall or tube; else ``boundary`` ("wall" or "tube"),
    ``gap_min`` [m] (smallest bead gap over the run, negative: a bead's surface past the
    boundary, which contact resists), ``gap_min_turns`` (when), ``gap_final`` [m] (the last
    frame's), ``gap_series`` (time,) [m], and ``tip_height_final`` [m] (wall: the first
    flagellum's free end above it) or ``tip_axis_distance_final`` [m] (tube: from its axis).
    A free cell beside a wall adds ``body_height`` (time,) [m] (its centre above the wall),
    ``body_height_final``, ``body_height_min`` [m], ``body_tilt_final_deg`` (its axis to the
    wall's plane, + pointing away from the wall), and over the last ``final_turns`` reference
    turns ``speed_parallel`` and ``speed_normal`` [m/s] (+ away from the wall). A free cell in
    a tube adds ``body_axis_distance`` (time,) [m], ``body_axis_distance_final``,
    ``body_axis_distance_max`` [m], ``body_tilt_final_deg`` (its axis to the tube's), and
    ``speed_along`` (+ along ``tube.axis``) and ``speed_radial`` (+ away from the axis)
    [m/s] over the last turns."""
    from flagwrap.io.runfile import config_of

    cfg = config_of(ds)
    if not (cfg.walls or cfg.tubes):
        return None
    a = cfg.filament.cross_section_radius
    x = ds["position"].values  # (time, bead, xyz), lab frame [m]
    tip = ds["tip_position"].values
    if cfg.walls:
        w = cfg.walls[0]
        n, p = w.unit_normal, np.asarray(w.point, float)
        gap = (x - p) @ n - a
        out = {"boundary": "wall", "tip_height_final": float((tip[-1] - p) @ n)}
    else:
        tube = cfg.tubes[0].geometry(1.0)  # in metres
        gap = tube.gap(x.reshape(-1, 3)).reshape(x.shape[:2]) - a
        out = {"boundary": "tube",
               "tip_axis_distance_final": float(tube.cylindrical(tip[-1:])[1][0])}
    series = gap.min(axis=1)
    k = int(np.argmin(series))
    out.update(gap_min=float(series[k]), gap_min_turns=float(ds["turns"].values[k]),
               gap_final=float(series[-1]), gap_series=series)
    if "body_position" in ds.variables:
        out.update(_free_body_beside_wall(ds, cfg, n, p, final_turns) if cfg.walls
                   else _free_body_in_tube(ds, cfg, tube, final_turns))
    return out


def body_centre(config) -> np.ndarray:
    """The cell body's centre in its own frame [m]: the mean of its blob shell (the shell
    is symmetric about the centre for every shape)."""
    from flagwrap.body.multiblob import cell_body_blobs

    return cell_body_blobs(config)[0].mean(axis=0) * config.filament.length


def body_centres(ds, cfg) -> tuple[np.ndarray, np.ndarray]:
    """``(R, c)``: a free body's rotations (time, 3, 3) and lab centres (time, 3) [m] from
    its run file."""
    from flagwrap.observables.swimming import quaternion_matrices

    R = quaternion_matrices(ds["body_orientation"].values)
    return R, ds["body_position"].values + R @ body_centre(cfg)


def _centres_and_window(ds, cfg, final_turns: float):
    """``(R, c, d, dt)``: body rotations and lab centres (time, 3) [m], and the centre's
    displacement over the last ``final_turns`` reference turns and its duration [s]."""
    R, c = body_centres(ds, cfg)
    t = ds["time"].values
    T = 1.0 / cfg.scales.omega
    t1 = float(t[-1])
    k = np.flatnonzero(t >= max(float(t[0]), t1 - 2 * math.pi * final_turns * T) - 1e-12 * t1)
    i, j = k[0], k[-1]
    return R, c, c[j] - c[i], t[j] - t[i]


def _free_body_in_tube(ds, cfg, tube, final_turns: float) -> dict:
    """A free cell in a tube: its body centre's distance from the axis (time,) [m], at the
    end and its largest, its axis' angle to the tube's at the end, and over the last turns
    its speed along the tube (+ along ``tube.axis``) and away from the axis [m/s]."""
    R, c, d, dt = _centres_and_window(ds, cfg, final_turns)
    _, r = tube.cylindrical(c)
    _, r0 = tube.cylindrical(c[-1] - d)  # the window's first centre
    a = np.asarray(tube.axis)
    cos = min(1.0, abs(float(R[-1][:, 2] @ a)))
    return {"body_axis_distance": r, "body_axis_distance_final": float(r[-1]),
            "body_axis_distance_max": float(r.max()),
            "body_tilt_final_deg": math.degrees(math.acos(cos)),
            "speed_along": float(d @ a) / dt if dt > 0 else math.nan,
            "speed_radial": float(r[-1] - r0) / dt if dt > 0 else math.nan}


def _free_body_beside_wall(ds, cfg, n, p, final_turns: float) -> dict:
    R, c, d, dt = _centres_and_window(ds, cfg, final_turns)
    h = (c - p) @ n
    normal = float(d @ n)
    axis = R[-1][:, 2]
    return {"body_height": h, "body_height_final": float(h[-1]),
            "body_height_min": float(h.min()),
            "body_tilt_final_deg": math.degrees(math.asin(max(-1.0, min(1.0, float(axis @ n))))),
            "speed_parallel": float(np.linalg.norm(d - normal * n) / dt) if dt > 0 else math.nan,
            "speed_normal": normal / dt if dt > 0 else math.nan}
