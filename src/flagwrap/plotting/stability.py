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
