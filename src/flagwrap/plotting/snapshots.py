"""Snapshot strips of a run: the two camera views at chosen times (paper Fig. 4(a),(b)).

Rows are the two cameras of the experiment (:data:`flagwrap.plotting.render.CAMERAS`),
columns the chosen times ``t/T``; every panel has the same axes limits and scale, so the
shapes can be compared across time and between views. See :mod:`flagwrap.plotting.render`
for how the tube and the semi-transparent body are drawn.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from flagwrap.errors import UserInputError
from flagwrap.io.atomic import savefig_atomic


def cw_phase(ds):
    """``(t/T)`` range ``(start, end)`` of the first clockwise phase of the motor, or ``None``.

    CW means ``omega < 0`` (CCW seen from the free end is positive). The phase starts at the
    last saved frame before the motor turns CW (the switch itself).
    """
    om = ds["omega"].values
    turns = ds["turns"].values
    cw = np.nonzero(om < 0)[0]
    if not len(cw):
        return None
    i0 = cw[0]
    stop = np.nonzero(om[i0:] >= 0)[0]
    i1 = i0 + stop[0] - 1 if len(stop) else len(om) - 1
    return float(turns[max(i0 - 1, 0)]), float(turns[i1])


def default_times(ds, n: int = 6) -> np.ndarray:
    """``n`` times ``t/T`` evenly spread over the CW phase (over the whole run if none)."""
    if n < 1:
        raise UserInputError(f"need at least one snapshot, got {n}")
    span = cw_phase(ds)
    turns = ds["turns"].values
    lo, hi = span if span else (float(turns[0]), float(turns[-1]))
    return np.linspace(lo, hi, n)


def frame_indices(ds, times) -> np.ndarray:
    """Indices of the saved frames nearest to the requested ``t/T`` values.

    Raises :class:`UserInputError` for a time outside the run (beyond half a save interval).
    """
    turns = ds["turns"].values
    times = np.atleast_1d(np.asarray(times, float))
    tol = 0.5 * float(np.median(np.diff(turns))) if len(turns) > 1 else 0.0
    bad = times[~np.isfinite(times) | (times < turns[0] - tol) | (times > turns[-1] + tol)]
    if len(bad):
        raise UserInputError(
            f"snapshot time(s) (-t) t/T = {', '.join(f'{b:g}' for b in bad)} outside the run "
            f"[{turns[0]:g}, {turns[-1]:g}]"
        )
    return np.abs(turns[None, :] - times[:, None]).argmin(axis=1)


def snapshot_figure(ds, times=None, n: int = 6, panel_width: float = 1.3, title: str | None = None,
                    renderer_kwargs: dict | None = None):
    """Figure of the snapshot strip: 2 rows (cameras) x ``len(times)`` columns.

    Parameters
    ----------
    ds : run dataset (:func:`flagwrap.io.runfile.read_run`)
    times : t/T values; default :func:`default_times` (``n`` over the CW phase)
    panel_width : width of one panel [inch]
    title : figure title; default names the run and its Machin number

    Returns
    -------
    fig : matplotlib Figure (caller saves and closes it)
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from flagwrap.plotting.render import (
        CAMERAS,
        Renderer,
        body_poses,
        nice_scale_bar,
        scene_of,
        style_view,
        view_limits,
    )

    times = default_times(ds, n) if times is None else np.atleast_1d(np.asarray(times, float))
    idx = frame_indices(ds, times)
    X = ds["position"].values
    # a polymorphic filament: coloured by form (render.polymorph_rgb)
    order = ds["polymorph_order"].values if "polymorph_order" in ds.variables else None
    turns = ds["turns"].values
    om = ds["omega"].values
    scene = scene_of(ds)
    poses = body_poses(ds)  # a free swimmer's body, drawn where it is
    ulim, zlim = view_limits(X[idx], scene, poses=None if poses is None else
                             (poses[0][idx], poses[1][idx]))
    aspect = (zlim[1] - zlim[0]) / (ulim[1] - ulim[0])
    ncol = len(idx)
    fig, axes = plt.subplots(2, ncol, figsize=(panel_width * ncol + 0.4, 2 * panel_width * aspect + 0.8),
                             squeeze=False)
    rend = Renderer(scene, **(renderer_kwargs or {}))
    bar = nice_scale_bar(ulim[1] - ulim[0], fraction=0.4)  # a bar one can read at strip size
    from flagwrap.io.runfile import config_of
    from flagwrap.plotting.render import draw_boundary

    cfg = config_of(ds)
    for j, i in enumerate(idx):
        for r, cam in enumerate(CAMERAS):
            ax = axes[r, j]
            draw_boundary(ax, cfg, cam)
            rend.draw(ax, X[i], cam, None if poses is None else (poses[0][i], poses[1][i]),
                      None if order is None else order[i])
            sense = "CW" if om[i] < 0 else ("CCW" if om[i] > 0 else "stop")
            style_view(ax, ulim, zlim,
                       title=f"$t/T$ = {turns[i]:.2f} ({sense})" if r == 0 else None,
                       scale_bar=bar if (j == 0 and r == len(CAMERAS) - 1) else None,
                       length=scene.length)
        axes[0, j].set_title(axes[0, j].get_title(), fontsize=7)
    for r, cam in enumerate(CAMERAS):
        axes[r, 0].set_ylabel(cam.name, fontsize=7)
        axes[r, 0].yaxis.label.set_visible(True)
    if title is None:
        hi = "with HI" if ds.attrs.get("hydrodynamics", 1) else "without HI"
        title = f"{ds.attrs.get('title', 'flagwrap run')}: M = {float(ds.attrs['machin']):.4g}, {hi}"
        if order is not None:
            title += (f"; blue: {ds.attrs.get('polymorph_a', 'polymorph A')}, orange: "
                      f"{ds.attrs.get('polymorph_b', 'polymorph B')}")
    # wrapped to the figure's width (~13 characters per inch at 8 pt): a one-column strip is
    # narrower than its title
    import textwrap

    width_in = fig.get_size_inches()[0]
    lines = textwrap.wrap(title, max(16, int(13 * width_in))) or [""]
    fig.suptitle("\n".join(lines), fontsize=8)
    top = 1 - (0.12 * len(lines) + 0.05) / fig.get_size_inches()[1]
    fig.tight_layout(rect=(0, 0, 1, min(0.96, top)), w_pad=0.2, h_pad=0.3)
    return fig


def write_snapshots(ds, path, formats=("png", "pdf"), dpi: int = 200, **kwargs) -> list[Path]:
    """Render :func:`snapshot_figure` and save it once per format (suffix replaced).

    Returns the written paths.
    """
    import matplotlib.pyplot as plt

    fig = snapshot_figure(ds, **kwargs)
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    out = []
    try:
        for fmt in formats:
            p = path.with_suffix("." + fmt.lstrip("."))
            savefig_atomic(fig, p, dpi=dpi)
            out.append(p)
    finally:
        plt.close(fig)
    return out
