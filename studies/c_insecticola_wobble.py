"""The free end's swing of C. insecticola runs below their threshold, against the decay the
linear spectrum predicts (docs/bacterium.md, "C. insecticola").

    python studies/c_insecticola_wobble.py STABILITY.json RUN.nc [RUN.nc ...] -o FIG.png

STABILITY.json: ``flagwrap stability examples/c_insecticola.toml --json`` (its continuation
branch: the leading eigenvalue against M); RUN.nc: ``flagwrap run`` files of the example at
speeds below f_c, after ``flagwrap analyze`` (which stores the free end's height). For each run
the height after the CW switch is drawn with the envelope ``exp(Re(lambda) omega t)`` of the
leading pair at the run's M (interpolated along the branch), started at the first 3-turn
window's half swing, and the swing per 3-turn window is printed beside the linear ratio.
"""

from __future__ import annotations

import argparse
import json
import math

import numpy as np


def leading_pair(branch, machin):
    """``(Re, |Im|)`` of the leading eigenvalue at ``machin`` (units of omega), interpolated."""
    m = np.array([p["machin"] for p in branch])
    order = np.argsort(m)
    m = m[order]
    re = np.array([branch[i]["leading_re"] for i in order])
    im = np.array([branch[i]["leading_im"] for i in order])
    return float(np.interp(machin, m, re)), float(np.interp(machin, m, im))


def main(argv=None):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import xarray as xr

    p = argparse.ArgumentParser()
    p.add_argument("stability")
    p.add_argument("runs", nargs="+")
    p.add_argument("-o", "--output", required=True)
    args = p.parse_args(argv)
    branch = json.load(open(args.stability))["branch"]
    fig, ax = plt.subplots(figsize=(7, 3.6))
    for path in args.runs:
        ds = xr.open_dataset(path, engine="h5netcdf")
        t, h = ds.turns.values, ds.free_end_height.values
        machin = float(ds.attrs["machin"])
        i = int(np.flatnonzero(ds.omega.values < 0)[0])  # first CW frame; the switch is the frame before
        t_s = t[i - 1] if i > 0 else t[0]
        re, im = leading_pair(branch, machin)
        m = t >= t_s
        label = f"M = {machin:.0f}: leading pair {re:.4f} +- {im:.3f}i"
        line, = ax.plot(t[m] - t_s, h[m], lw=1.2, label=label)
        windows = np.arange(t_s, t[-1] - 2.95, 3.0)
        swings = [np.ptp(h[(t >= a) & (t < a + 3)]) for a in windows]
        ratio = math.exp(re * 2 * math.pi * 3)
        mid = h[m].mean()
        tt = np.linspace(0, t[-1] - t_s, 200)
        env = 0.5 * swings[0] * np.exp(re * 2 * math.pi * (tt - 1.5))
        ax.plot(tt, mid + env, "--", color=line.get_color(), lw=0.8)
        ax.plot(tt, mid - env, "--", color=line.get_color(), lw=0.8)
        print(f"{path}: M = {machin:.1f}, swings {np.round(swings, 3)}, ratios "
              f"{np.round(np.array(swings[1:]) / np.array(swings[:-1]), 2)}, linear {ratio:.2f}, "
              f"period {1 / im:.2f} turns")
    ax.set_xlabel("motor turns after the CW switch")
    ax.set_ylabel("free-end height / L")
    ax.set_title("C. insecticola below threshold: free end (solid), linear decay (dashed)", fontsize=10)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(args.output, dpi=120)


if __name__ == "__main__":
    main()
