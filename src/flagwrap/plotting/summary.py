"""Summary figure of one run: free-end height and motor torque against t/T."""

from __future__ import annotations

from pathlib import Path

from flagwrap.io.atomic import savefig_atomic


def figure_suffixes() -> set:
    """File suffixes matplotlib can save (``.png``, ``.pdf``, ``.svg``, ...)."""
    from matplotlib.backend_bases import FigureCanvasBase

    return {f".{k}" for k in FigureCanvasBase.get_supported_filetypes()}


def summary_figure(ds, path):
    """Two panels: ``(z(L) - z(0))/L`` and ``N_m R / A`` against ``t/T`` (paper Fig. 4(c),(d))."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    turns = ds["turns"].values
    L = ds.attrs["length"]
    from flagwrap.io.runfile import filament_slices
    from flagwrap.observables.tip import free_end_heights

    many = len(filament_slices(ds)) > 1
    z = free_end_heights(ds["position"].values, L, filament_slices(ds))
    tq = ds["motor_torque_reduced"].values
    fig, (a1, a2) = plt.subplots(2, 1, figsize=(6, 5), sharex=True)
    for k in range(z.shape[1]):  # one line per flagellum
        a1.plot(turns, z[:, k], color=f"C{k}" if many else "C0",
                label=f"flagellum {k}" if many else None)
    a1.axhline(0, color="0.6", lw=0.8, ls="--", label="free end level with the clamp")
    verdict = _verdict(ds)
    if verdict is not None:  # the paper's rise criterion, where the run's analysis applies
        state, level = verdict
        a1.axhline(level, color="C1", lw=0.8, ls="-.",
                   label="rise criterion (0.15 L over the CCW baseline)")
    a1.legend(fontsize=7, loc="best")
    a1.set_ylabel(r"$[z(L)-z(0)]/L$")
    a2.plot(turns, tq, color="C3")
    a2.axhline(0, color="0.6", lw=0.8, ls="--")
    a2.set_ylabel(r"$N_m R/A$ (CCW > 0)" + (", all motors" if many else ""))
    a2.set_xlabel(r"$t/T$ (motor turns)")
    edges = [float(turns[0])] + _switch_turns(ds) + [float(turns[-1])]
    om = ds["omega"].values
    for t_sw in edges[1:-1]:
        for ax in (a1, a2):
            ax.axvline(t_sw, color="0.5", lw=0.8, ls=":")
    for t0, t1 in zip(edges[:-1], edges[1:]):  # name each phase by its motor's sense
        k = min(range(len(turns)), key=lambda i: abs(turns[i] - 0.5 * (t0 + t1)))
        sense = "CCW" if om[k] > 0 else ("CW" if om[k] < 0 else "stop")
        a1.text(0.5 * (t0 + t1), 1.0, sense, transform=a1.get_xaxis_transform(), ha="center",
                va="bottom", fontsize=8, color="0.3")
    hi = "with HI" if ds.attrs.get("hydrodynamics", 1) else "without HI"
    title = f"{ds.attrs.get('title', '')}: M = {ds.attrs['machin']:.4g}, {hi}"
    if verdict is not None:
        title += f"; final state: {verdict[0]}"
    a1.set_title(title, pad=14)
    fig.tight_layout()
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    savefig_atomic(fig, path, dpi=150)
    plt.close(fig)
    return path


def _verdict(ds):
    """``(final state, rise level)`` of the run by ``flagwrap analyze``'s default criteria, or
    None where they do not apply (no cell body, no CW phase, a partial run)."""
    from flagwrap.errors import UserInputError

    try:
        from flagwrap.analysis.runfile_attrs import analyze_dataset

        a = analyze_dataset(ds)
        sm = a.summary()
        return str(sm["state"]), float(sm["baseline_height"]) + float(a.params()["threshold"])
    except (UserInputError, KeyError, ValueError):
        return None


def _switch_turns(ds):
    import numpy as np

    om = np.sign(ds["omega"].values)
    idx = np.nonzero(np.diff(om) != 0)[0]
    # the frame at a switch is recorded with the old phase's speed: its time is the switch
    return [float(ds["turns"].values[i]) for i in idx]
