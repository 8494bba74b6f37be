"""The nature of the onset (issue 16, item 4): is this model's Hopf bifurcation sub- or
supercritical, and why does the time-domain M_c (576) lie below the linear one (617)?

    python studies/stability_onset.py basin        # (a) finite perturbations at M = 600
    python studies/stability_onset.py hysteresis   # (b) M stepped up through M_c and back
    python studies/stability_onset.py protocol     # (c) the paper protocol's CW phase seen
                                                   #     against the steady CW state
    python studies/stability_onset.py verdict      # (d) the rise criterion's verdict on long
                                                   #     CW phases between the two thresholds
    python studies/stability_onset.py amplitude    # (e) saturated amplitude just above M_c
    python studies/stability_onset.py cycle        # (f) that oscillation taken below M_c

All runs: the Fig. 4(a) helix (examples/fig4a.toml), HI on, tol 1e-5, stepped in the turning
frame (numerics.frame = "rotating"; tests/unit/test_rotating.py checks it against the lab
frame). The steady states come from flagwrap.stability (Newton). "deviation" is the largest
distance of a bead from the steady shape in the turning frame, in L. "rise" is the free
end's height above that of the steady shape. Prints markdown tables for docs/stability.md.
"""

from __future__ import annotations

import dataclasses
import sys
import time

import numpy as np

from flagwrap.io.config import load_config
from flagwrap.params import Phase
from flagwrap.simulation import Simulation, make_system
from flagwrap.stability.spectrum import mode_vector, spectrum
from flagwrap.stability.steady import branch, retract
from flagwrap.stability.threshold import find_critical
from flagwrap.system.rod_system import RodSystem
from flagwrap.system.rotating import RotatingFrame, rotation

TWO_PI = 2 * np.pi


def config(machin, protocol, tol=1e-5):
    cfg = load_config("examples/fig4a.toml")
    return cfg.replace(
        motor=dataclasses.replace(cfg.motor, machin=machin, protocol=protocol),
        numerics=dataclasses.replace(cfg.numerics, tol=tol, frame="rotating", save_every=0.05))


def steady(frame, machins):
    """The linear threshold and the steady CW states at ``machins``."""
    r = find_critical(frame, m_max=3000.0)
    return r, branch(frame, machins)


def on_whirl(M, protocol):
    """The config at ``M`` with ``protocol``, its turning frame (CW), the linear threshold, the
    steady CW whirl at ``M``, its spectrum, its critical mode (a real vector over the unknowns,
    largest bead displacement 1) and its bead positions."""
    cfg = config(M, protocol)
    base_sys = RodSystem(cfg)
    frame = RotatingFrame(base_sys, -1.0)
    r, st = steady(frame, [M])
    st = st[M]
    sp = spectrum(frame, st, vectors=True)
    mode = mode_vector(frame, sp.vectors[:, 0]).real
    return cfg, frame, r, st, sp, mode, base_sys.unpack(frame.full(st.z))[0]


def deviation(frame, tr, x_star):
    """Largest bead distance from ``x_star`` (turning frame) at each recorded frame, and the
    free end's height minus the steady one's."""
    A = tr.arrays()
    dev, rise = [], []
    for k in range(len(A["t"])):
        R = rotation(frame.axis, -A["phi"][k])
        xr = A["x"][k] @ R.T
        xs = x_star(A["t"][k]) if callable(x_star) else x_star
        dev.append(float(np.max(np.linalg.norm(xr - xs, axis=1))))
        rise.append(float(xr[-1, 2] - xs[-1, 2]))
    return A["t"], np.array(dev), np.array(rise)


def basin():
    M = 600.0
    cfg, frame, r, st, sp, mode, x = on_whirl(M, (Phase("cw", 10.0, 1.0),))
    print(f"M = {M:g}: linear M_c = {r.machin_c:.1f}; leading eigenvalue "
          f"{sp.leading.real:+.4f} +- {abs(sp.leading.imag):.4f}i")
    print("| perturbation along the critical mode [L] | largest deviation in 10 CW turns [L] | "
          "final deviation [L] | largest rise [L] | steps | wall [s] |")
    print("|---:|---:|---:|---:|---:|---:|")
    for amp in (1e-3, 1e-2, 3e-2, 0.05, 0.1, 0.2):
        system = make_system(cfg)
        # along the mode with the bond lengths kept (a linear kick of 0.1 L would strain them)
        y0 = frame.full(retract(frame, st.z, amp * mode))
        t0 = time.perf_counter()
        tr = Simulation(cfg, system=system).run(y0=y0, base=st.base)
        _, dev, rise = deviation(frame, tr, x)
        note = "" if tr.ok else f" ({tr.status}: {tr.message})"
        print(f"| {amp:g} | {dev.max():.3g} | {dev[-1]:.3g} | {rise.max():+.3f} | "
              f"{tr.n_steps}{note} | {time.perf_counter() - t0:.0f} |", flush=True)


def hysteresis():
    M0 = 600.0
    speeds = [0.9, 0.95, 1.0, 1.05, 1.1, 1.2, 1.1, 1.05, 1.0, 0.95, 0.9, 0.8]
    turns = 10.0
    proto = tuple(Phase("cw", turns, s) for s in speeds)
    cfg = config(M0, proto)
    base_sys = RodSystem(cfg)
    frame = RotatingFrame(base_sys, -1.0)
    machins = sorted({round(M0 * s, 6) for s in speeds})
    r, states = steady(frame, machins)
    first = states[round(M0 * speeds[0], 6)]
    x0, th0, _ = base_sys.unpack(frame.full(first.z))
    system = make_system(cfg)
    y0 = system.pack(x0, th0, 0.0)
    t0 = time.perf_counter()
    tr = Simulation(cfg, system=system).run(y0=y0, base=first.base)
    sched = system.schedule
    shapes = {m: base_sys.unpack(frame.full(s.z))[0] for m, s in states.items()}

    def x_star(t):
        k = sched.segment_index(t)
        return shapes[round(M0 * speeds[k], 6)]

    t, dev, rise = deviation(frame, tr, x_star)
    print(f"linear M_c = {r.machin_c:.1f}; the run: {tr.status} {tr.message} "
          f"{tr.n_steps} steps, {time.perf_counter() - t0:.0f} s")
    print("| phase | M | steady state | mean deviation, last turn [L] | largest deviation [L] | "
          "mean rise, last turn [L] |")
    print("|---:|---:|---|---:|---:|---:|")
    for k, seg in enumerate(sched.segments):
        m = M0 * speeds[k]
        sel = (t > seg.t0) & (t <= seg.t1)
        last = sel & (t > seg.t1 - TWO_PI / abs(seg.omega))
        if not last.any():
            break
        stable = "stable" if m < r.machin_c else "unstable"
        print(f"| {k + 1} | {m:.0f} | {stable} | {dev[last].mean():.3g} | {dev[sel].max():.3g} | "
              f"{rise[last].mean():+.3f} |", flush=True)


def protocol():
    """The paper protocol (5 CCW + 10 CW) at M around the two thresholds: how far the CW
    phase's transient carries the helix from the steady CW state."""
    print("| M | linear | largest deviation from the steady CW state [L] | final deviation [L] | "
          "largest rise above it [L] | final rise [L] |")
    print("|---:|---|---:|---:|---:|---:|")
    for M in (546.2, 572.5, 579.2, 600.0, 630.0):
        cfg, frame, r, _, _, _, x = on_whirl(M, (Phase("ccw", 5.0, 1.0), Phase("cw", 10.0, 1.0)))
        tr = Simulation(cfg).run()
        t, dev, rise = deviation(frame, tr, x)
        cw = t > 5 * TWO_PI
        print(f"| {M:g} | {'stable' if M < r.machin_c else 'unstable'} | {dev[cw].max():.3g} | "
              f"{dev[-1]:.3g} | {rise[cw].max():+.3f} | {rise[-1]:+.3f} |", flush=True)


def verdict():
    """The paper protocol with a long CW phase (5 CCW + 30 CW) at M between the time-domain
    threshold (576) and the linear one (617): the rise criterion's verdict
    (``flagwrap analyze``) beside the distance from the steady CW state as the run goes on."""
    import json
    import subprocess

    from flagwrap.io.runfile import write_run

    print("| M | linear | rise-criterion verdict (flagwrap analyze) | t_c/T | final class | "
          "deviation from the steady CW state [L] at CW turn 5 / 10 / 20 / 30 |")
    print("|---:|---|---|---:|---|---|")
    for M in (579.2, 600.0):
        cfg, frame, r, _, _, _, x = on_whirl(M, (Phase("ccw", 5.0, 1.0), Phase("cw", 30.0, 1.0)))
        tr = Simulation(cfg).run()
        path = f"out/stability/verdict_M{M:g}.nc"
        write_run(tr, path)
        out = subprocess.run(["flagwrap", "analyze", path, "--json", "--no-write"],
                             capture_output=True, text=True, check=True).stdout
        a = json.loads(out.splitlines()[0])
        t, dev, _ = deviation(frame, tr, x)
        at = [dev[np.argmin(np.abs(t - (5 + k) * TWO_PI))] for k in (5, 10, 20, 30)]
        print(f"| {M:g} | {'stable' if M < r.machin_c else 'unstable'} | "
              f"{'buckled' if a.get('buckled') else 'stable'} | {a.get('waiting_time_turns')} | "
              f"{a.get('state')} | {' / '.join(f'{v:.3g}' for v in at)} |", flush=True)


def amplitude(turns=100.0):
    """Just above the linear threshold: how the oscillation that grows from the steady state
    (1e-3 L kick along the critical mode) saturates. A supercritical Hopf saturates at an
    amplitude ~ sqrt(M - M_c); a subcritical one leaves for a far state. Prints the mean
    deviation over each 10-turn window."""
    windows = np.arange(0.0, turns + 1e-9, 10.0)
    print("| M | eps = M/M_c - 1 | Re lambda | " + " | ".join(
        f"turns {a:g}-{b:g}" for a, b in zip(windows[:-1], windows[1:])) + " |")
    print("|---:|---:|---:|" + "---:|" * (len(windows) - 1))
    for M in (625.0, 635.0, 650.0):
        cfg, frame, r, st, sp, mode, x = on_whirl(M, (Phase("cw", turns, 1.0),))
        y0 = frame.full(retract(frame, st.z, 1e-3 * mode))
        tr = Simulation(cfg, system=make_system(cfg)).run(y0=y0, base=st.base)
        t, dev, _ = deviation(frame, tr, x)
        cols = [dev[(t > a * TWO_PI) & (t <= b * TWO_PI)].mean()
                for a, b in zip(windows[:-1], windows[1:])]
        print(f"| {M:g} | {M / r.machin_c - 1:.4f} | {sp.leading.real:+.4f} | "
              + " | ".join(f"{c:.3g}" for c in cols) + " |", flush=True)


def cycle():
    """Sub- or supercritical: saturate the oscillation at M = 635 (eps = 0.03, 100 turns from a
    1e-3 L kick), then lower M below M_c (610, then 590) for 50 turns each. A supercritical
    Hopf has no cycle below M_c: the oscillation decays back to the whirl. A subcritical one
    keeps a finite-amplitude cycle there, beside the stable whirl."""
    M0 = 635.0
    plan = [(1.0, 100.0), (610.0 / M0, 50.0), (590.0 / M0, 50.0)]
    cfg = config(M0, tuple(Phase("cw", n, s) for s, n in plan))
    base_sys = RodSystem(cfg)
    frame = RotatingFrame(base_sys, -1.0)
    machins = [round(M0 * s, 6) for s, _ in plan]
    r, states = steady(frame, machins)
    st = states[machins[0]]
    sp = spectrum(frame, st, vectors=True)
    mode = mode_vector(frame, sp.vectors[:, 0]).real
    y0 = frame.full(retract(frame, st.z, 1e-3 * mode))
    system = make_system(cfg)
    tr = Simulation(cfg, system=system).run(y0=y0, base=st.base)
    sched = system.schedule
    shapes = {m: base_sys.unpack(frame.full(s.z))[0] for m, s in states.items()}
    t, dev, _ = deviation(frame, tr, lambda tt: shapes[machins[sched.segment_index(tt)]])
    print(f"linear M_c = {r.machin_c:.1f}; {tr.status} {tr.message} {tr.n_steps} steps")
    print("| phase | M | linear | mean distance from the whirl per 10 turns [L] |")
    print("|---:|---:|---|---|")
    for k, seg in enumerate(sched.segments):
        m = machins[k]
        n = int(round(plan[k][1] / 10))
        T = TWO_PI / abs(seg.omega)
        cols = [dev[(t > seg.t0 + 10 * j * T) & (t <= seg.t0 + 10 * (j + 1) * T)].mean()
                for j in range(n)]
        print(f"| {k + 1} | {m:g} | {'stable' if m < r.machin_c else 'unstable'} | "
              + ", ".join(f"{c:.3g}" for c in cols) + " |", flush=True)


if __name__ == "__main__":
    what = sys.argv[1] if len(sys.argv) > 1 else "basin"
    {"basin": basin, "hysteresis": hysteresis, "protocol": protocol, "verdict": verdict,
     "amplitude": amplitude, "cycle": cycle}[what]()
