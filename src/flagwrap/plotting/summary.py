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
    if many:
        a1.legend(fontsize=7)
    a1.axhline(0, color="0.6", lw=0.8, ls="--")
    a1.set_ylabel(r"$[z(L)-z(0)]/L$")
    a2.plot(turns, tq, color="C3")
    a2.set_ylabel(r"$N_m R/A$ (CCW > 0)" + (", all motors" if many else ""))
    a2.set_xlabel(r"$t/T$")
    for t_sw in _switch_turns(ds):
        for ax in (a1, a2):
            ax.axvline(t_sw, color="0.5", lw=0.8, ls=":")
    hi = "with HI" if ds.attrs.get("hydrodynamics", 1) else "without HI"
    a1.set_title(f"{ds.attrs.get('title', '')}: M = {ds.attrs['machin']:.4g}, {hi}")
    fig.tight_layout()
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    savefig_atomic(fig, path, dpi=150)
    plt.close(fig)
    return path


def _switch_turns(ds):
    import numpy as np

    om = np.sign(ds["omega"].values)
    idx = np.nonzero(np.diff(om) != 0)[0]
    # the frame at a switch is recorded with the old phase's speed: its time is the switch
    return [float(ds["turns"].values[i]) for i in idx]
