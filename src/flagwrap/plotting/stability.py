"""Figures of the stability tool (``flagwrap stability --mode``): the steady shape at M_c,
the critical mode on it, and the leading eigenvalues along the branch."""

from __future__ import annotations

import numpy as np

from flagwrap.io.atomic import savefig_atomic


def plot_mode(x, mode, result, config, path, amplitude: float = 0.05):
    """Three panels. (a) The steady shape at the top of the M_c bracket (side view x-z,
    lengths in L), with the shape plus the critical mode at 4 phases ``Re(mode e^{i k pi/2})``
    scaled to ``amplitude`` L of largest displacement. (b) The mode's amplitude along the
    filament. (c) The two leading eigenvalues' real parts against M along the branch, with
    M_c marked."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(1, 3, figsize=(12, 4))
    a = ax[0]
    for k in range(4):
        d = (mode * np.exp(0.5j * np.pi * k)).real * amplitude
        a.plot(x[:, 0] + d[:, 0], x[:, 2] + d[:, 2], lw=0.8, alpha=0.6, label=f"phase {k * 90} deg")
    a.plot(x[:, 0], x[:, 2], "k", lw=2, label="steady shape")
    a.set_aspect("equal")
    a.set_xlabel("x / L")
    a.set_ylabel("z / L")
    a.set_title(f"(a) steady {result.direction.upper()} whirl at M = {result.bracket[1]:.1f}, "
                f"critical mode", fontsize=9)
    a.legend(fontsize=7)
    s = np.arange(len(x)) / (len(x) - 1)
    ax[1].plot(s, np.linalg.norm(mode, axis=1), "C3")
    ax[1].set_xlabel("s / L (clamp at 0)")
    ax[1].set_ylabel("|mode| (largest = 1)")
    kind = {"hopf": "Hopf", "fold": "fold"}.get(result.crossing, "steady")
    ax[1].set_title(f"(b) mode amplitude ({kind}, Omega = {result.mode_frequency:.3f} omega)",
                    fontsize=9)
    pts = sorted(result.branch, key=lambda p: p.machin)
    m = np.array([p.machin for p in pts])
    ax[2].semilogx(m, [p.leading.real for p in pts], "o-", ms=3, label="leading")
    ax[2].semilogx(m, [p.second.real for p in pts], "s-", ms=3, alpha=0.6, label="next")
    lead = np.array([p.leading.real for p in pts])
    ax[2].set_ylim(max(-1.0, 1.1 * lead.min()), max(0.05, 1.2 * lead.max()))
    ax[2].axhline(0.0, color="k", lw=0.7)
    ax[2].axvline(result.machin_c, color="C3", ls="--", label=f"M_c = {result.machin_c:.1f}")
    ax[2].set_xlabel("M")
    ax[2].set_ylabel("Re lambda / omega")
    ax[2].set_title("(c) leading eigenvalues along the branch", fontsize=9)
    ax[2].legend(fontsize=7)
    fig.suptitle(f"{config.name}: linear stability (HI "
                 f"{'on' if config.numerics.hydrodynamics else 'off'})", fontsize=10)
    fig.tight_layout()
    savefig_atomic(fig, path, dpi=120)
    plt.close(fig)
    return path


def plot_bifurcation(diagram, config, path, protocol_threshold=None):
    """The bifurcation diagram (:class:`flagwrap.stability.bifurcation.Diagram`): the free
    end's axial position from rest [L] against M, stable states solid, unstable dashed
    (stable: every eigenvalue with a negative real part). The whirl (blue) with its Hopf or
    fold, the far branch (red) found by relaxation with its fold M_f and the saddle branch
    beyond it, the Hopf cycle's range from the time domain (green bars), and the paper's
    scaling line 0.06 (R/L)^-3 (grey). ``protocol_threshold``: an (lo, hi) bracket of the
    protocol's outcome threshold, shaded."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    z0 = diagram.tip_z0
    fig, ax = plt.subplots(figsize=(7, 4.5))

    labelled = set()

    def draw(points, color, label):
        pts = sorted(points, key=lambda p: p.machin)
        if not pts:
            return
        m = np.array([p.machin for p in pts])
        h = np.array([p.tip_z - z0 for p in pts])
        st = np.array([p.leading.real < 0 for p in pts])
        # a line per run of equal stability, joined to the next point so the curve is whole
        start = 0
        for k in range(1, len(pts) + 1):
            if k == len(pts) or st[k] != st[start]:
                sl = slice(start, min(k + 1, len(pts)))
                name = f"{label}, {'stable' if st[start] else 'unstable'}"
                ax.plot(m[sl], h[sl], color=color, ls="-" if st[start] else "--", lw=1.6,
                        label=None if name in labelled else name)
                labelled.add(name)
                start = k
        ax.plot(m, h, ".", color=color, ms=3)

    draw(diagram.whirl, "C0", "whirl")
    draw(diagram.far + diagram.saddle, "C3", "far state")
    if diagram.cycles:
        for k, c in enumerate(diagram.cycles):
            ax.plot([c.machin, c.machin], [c.tip_min - z0, c.tip_max - z0], "C2-", lw=3,
                    alpha=0.8, label="Hopf cycle (time domain)" if k == 0 else None)
    mh = diagram.machin_hopf
    if np.isfinite(mh):
        kind = {"hopf": "Hopf", "fold": "fold"}.get(diagram.hopf.crossing, "crossing")
        ax.axvline(mh, color="C0", ls=":", lw=1, label=f"whirl's {kind} M = {mh:.1f}")
    if diagram.fold_found:
        ax.axvline(diagram.machin_fold, color="C3", ls=":", lw=1,
                   label=f"far state's fold M_f = {diagram.machin_fold:.1f}")
    if protocol_threshold is not None:
        lo, hi = protocol_threshold
        ax.axvspan(lo, hi, color="C1", alpha=0.25, label=f"protocol threshold {lo:g}-{hi:g}")
    line = config.machin_critical_scaling
    ax.axvline(line, color="0.5", lw=1, label=f"paper's line 0.06 (R/L)^-3 = {line:.0f}")
    # from below the paper's line and the far branch's end to the top of the diagram
    far_m = [p.machin for p in diagram.far + diagram.saddle]
    lo = 0.85 * min([line, mh if np.isfinite(mh) else line] + far_m)
    hi = max([p.machin for p in diagram.whirl + diagram.far] + [lo * 1.5])
    ax.set_xlim(lo, 1.02 * hi)
    inside = [p.tip_z - z0 for p in diagram.whirl + diagram.far + diagram.saddle
              if lo <= p.machin <= hi]
    inside += [v - z0 for c in diagram.cycles for v in (c.tip_min, c.tip_max)]
    if inside:
        pad = 0.05 * (max(inside) - min(inside) + 0.05)
        ax.set_ylim(min(inside) - pad, max(inside) + pad)
    ax.set_xlabel("M")
    ax.set_ylabel("free end above its rest position [L]")
    ax.set_title(f"{config.name}: steady states in the turning frame "
                 f"({diagram.direction.upper()}, HI {'on' if config.numerics.hydrodynamics else 'off'})",
                 fontsize=9)
    ax.legend(fontsize=7, loc="best")
    fig.tight_layout()
    savefig_atomic(fig, path, dpi=120)
    plt.close(fig)
    return path
