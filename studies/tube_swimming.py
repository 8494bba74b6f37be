"""The extended and the wrapped S. putrefaciens cell swimming along straight tubes of
decreasing radius, against free space (docs/confinement.md, "A free cell in a tube").

Run: ``python studies/tube_swimming.py [--radii 3 2 1.5] [--turns 3] [--settle 0]
[--spacing 0.4] [--out out/tube_swimming]``

1. The two swimming states, from ``examples/s_putrefaciens_wrap.toml`` (speed motor, 50 Hz)
   in the motor's frame: **extended**, the end of its 4 CCW turns (the coil pushes from
   behind); **wrapped**, the end of its whole protocol (4 CCW + 12 CW: wrapped round the body).
2. With ``--settle N``, N more turns in free space first, and their end is the state (the
   extended cell needs ~8 to swim periodically; the wrapped one is periodic at once).
3. Each state with its body put back at the origin, unturned (free space is invariant under
   a rigid motion; the tube is placed about the body's axis), then ``--turns`` more reference
   turns in its direction: in free space, and inside an open straight tube about the body's
   axis (its middle ``--centre`` um below the motor, ``--length`` um long: the coil reaches
   2.9 um below the motor, the body 2.5 um above it) of each radius in
   ``--radii`` um, blobs ``--spacing`` um apart (each run's own ``flagwrap analyze``
   numbers over the last turn: the progress along the path's screw axis, ``screw_speed``,
   and Lighthill's efficiency with it; and the screw speed of every turn, to show that the
   run is periodic).

Prints one table row per (state, radius): steps, seconds, the body's distance from the axis,
the swimming speed along the tube, the motor's torque and power, and the efficiency, each
also against free space. Each run file is kept in ``--out``.
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import time
from pathlib import Path

import one_thread  # noqa: F401  (one thread per process, before numpy loads)

import numpy as np

from flagwrap.cases import case_files
from flagwrap.io.config import load_config
from flagwrap.params import Phase
from flagwrap.simulation import Simulation


def base_config(turns, direction, frame="rotating"):
    cfg = load_config(case_files()["s_putrefaciens_wrap"])
    return cfg.replace(
        motor=dataclasses.replace(cfg.motor, protocol=turns if isinstance(turns, tuple)
                                  else (Phase(direction, turns),)),
        numerics=dataclasses.replace(cfg.numerics, frame=frame))


def with_tube(cfg, radius_um, length_um, centre_um, spacing_um):
    from flagwrap.params import TubeWall

    um = 1e-6  # the config is in SI once loaded
    tube = TubeWall(radius=radius_um * um, length=length_um * um,
                      center=(0.0, 0.0, -centre_um * um), axis=(0.0, 0.0, 1.0),
                      blob_spacing=spacing_um * um)
    return cfg.replace(tubes=(tube,))


def states(out: Path, make_config=None, protocols=None):
    """``{"extended": (y, frames), "wrapped": (y, frames)}`` in the motor's frame (kept in
    ``out/states.npz`` and read back from it when there): the ends of ``protocols``
    (``{name: (Phase, ...)}``, default S. putrefaciens' 4 CCW, and 4 CCW + 12 CW turns) run
    from ``make_config(protocol)`` (default this study's case)."""
    from flagwrap.elasticity.rod import Frames

    make_config = make_config or (lambda protocol: base_config(protocol, None))
    protocols = protocols or {"extended": (Phase("ccw", 4.0),),
                              "wrapped": (Phase("ccw", 4.0), Phase("cw", 12.0))}
    cache = out / "states.npz"
    if cache.exists():
        z = np.load(cache)
        return {n: (z[f"{n}_y"], Frames(z[f"{n}_t"], z[f"{n}_d1"], z[f"{n}_rt"]))
                for n in protocols}
    found, keep = {}, {}
    for name, protocol in protocols.items():
        start = time.perf_counter()
        tr = Simulation(make_config(protocol)).run()
        print(f"{name} state: {tr.status}, {tr.n_steps} steps, "
              f"{time.perf_counter() - start:.0f} s", flush=True)
        fr = tr.final_frames
        found[name] = (tr.final_y, fr)
        keep.update({f"{name}_y": tr.final_y, f"{name}_t": fr.t, f"{name}_d1": fr.d1,
                     f"{name}_rt": fr.rt})
    np.savez(cache, **keep)
    return found


def at_origin(system, y, flip=False):
    """The state with its pole at the origin, its body along +z (``flip``: along -z, turned
    by pi about x)."""
    y = np.array(y, float)
    y[system.sl_X] = 0.0
    y[system.sl_q] = (0.0, 1.0, 0.0, 0.0) if flip else (1.0, 0.0, 0.0, 0.0)
    return y


def run_one(cfg, y0, base, path):
    from flagwrap.io.runfile import write_run

    sim = Simulation(cfg)
    y = at_origin(sim.system, y0)
    start = time.perf_counter()
    t_end = 2 * math.pi * sum(p.turns for p in cfg.motor.protocol)
    tr = sim.run(t_end=t_end, y0=y, base=base, t0=0.0)
    wall = time.perf_counter() - start
    write_run(tr, path)
    return tr, wall


def measure(path, final_turns: float = 2.0):
    """The last ``final_turns`` reference turns of a run file: the swimming summary (screw
    speed, motor power, Lighthill's efficiency) and the tube's (None in free space), and the
    progress ``U`` [m/s] with its efficiency ``eta``: along the tube in a tube, along the
    path's screw axis in free space. Two turns, because in a tube the cell, slightly off the
    axis and tilted, precesses about it at the body's rate (~171 degrees a motor turn): the
    single turns alternate by ~15 %, pairs agree to 0.2 %."""
    from flagwrap.io.runfile import config_of, read_run
    from flagwrap.observables.swimming import body_drag, swimming_summary
    from flagwrap.observables.wall import wall_summary

    ds = read_run(path)
    final = swimming_summary(ds, final_turns)[-1]
    w = wall_summary(ds, final_turns)
    U = final["screw_speed"] if w is None else w["speed_along"]  # the tube's axis: the body's
    final.update(U=U, eta=body_drag(config_of(ds)) * U * U / final["motor_power"],
                 per_turn=per_turn(ds))
    return final, w


def per_turn(ds) -> list[float]:
    """The screw speed [m/s] over each whole reference turn of a run file's dataset (its
    convergence: a periodic swimmer gives the same number every turn)."""
    from flagwrap.io.runfile import config_of
    from flagwrap.observables.swimming import phase_summary

    t = ds["time"].values
    T = 2 * math.pi / config_of(ds).scales.omega
    args = (ds["motor_angle"].values, ds["body_position"].values, ds["body_orientation"].values)
    return [phase_summary(t, *args, k * T, (k + 1) * T)["screw_speed"]
            for k in range(round(t[-1] / T))]


def main(argv=None):
    p = argparse.ArgumentParser()
    p.add_argument("--radii", type=float, nargs="+", default=[3.0, 2.0, 1.5])
    p.add_argument("--turns", type=float, default=3.0)
    p.add_argument("--spacing", type=float, default=0.4,
                   help="blob spacing [um], at most --max-ratio times the radius")
    p.add_argument("--max-ratio", type=float, default=0.25)
    p.add_argument("--length", type=float, default=10.0)
    p.add_argument("--centre", type=float, default=0.2)
    p.add_argument("--modes", nargs="+", default=["extended", "wrapped"])
    p.add_argument("--settle", type=float, default=0.0,
                   help="turns in free space first; every run then starts from their end")
    p.add_argument("--out", default="out/tube_swimming")
    args = p.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    found = states(out)
    rows = []
    for mode in args.modes:
        y0, base = found[mode]
        direction = "ccw" if mode == "extended" else "cw"
        if args.settle > 0:
            tr, wall = run_one(base_config(args.settle, direction), y0, base,
                               out / f"{mode}_settle{args.settle:g}.nc")
            y0, base = tr.final_y, tr.final_frames
            print(f"{mode}: {args.settle:g} turns in free space first, {wall:.0f} s", flush=True)
        for radius in [None, *args.radii]:
            cfg = base_config(args.turns, direction)
            h = args.spacing if radius is None else min(args.spacing, args.max_ratio * radius)
            if radius is not None:
                cfg = with_tube(cfg, radius, args.length, args.centre, h)
            tag = "free" if radius is None else f"R{radius:g}"
            path = out / f"{mode}_{tag}_h{h:g}.nc"
            tr, wall = run_one(cfg, y0, base, path)
            final, w = measure(path)
            rows.append((mode, radius, tr, wall, final, w, h))
            print(f"{mode} {tag}: {tr.status} {tr.n_steps} steps ({tr.n_rejected} rejected) "
                  f"{wall:.0f} s; speed {final['U'] * 1e6:.3f} um/s, "
                  f"efficiency {final['eta'] * 100:.3g} %"
                  + ("" if w is None else f", along the tube {w['speed_along'] * 1e6:+.3f} um/s,"
                     f" body {w['body_axis_distance_final'] * 1e6:.3f} um from the axis, "
                     f"closest bead {w['gap_min'] * 1e9:.0f} nm")
                  + "; screw speed per turn " + " ".join(f"{u * 1e6:+.3f}" for u in final["per_turn"]),
                  flush=True)
    print("\n| state | tube radius [um] | steps | s | speed [um/s] | vs free | motor power "
          "[fW] | efficiency [%] | vs free | body off axis [um] | closest bead [nm] |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    free = {}
    for mode, radius, tr, wall, final, w, h in rows:
        if radius is None:
            free[mode] = final
        f0 = free[mode]
        off = "-" if w is None else f"{w['body_axis_distance_final'] * 1e6:.3f}"
        gap = "-" if w is None else f"{w['gap_min'] * 1e9:.0f}"
        where = "free" if radius is None else f"{radius:g} (blobs {h:g} apart)"
        print(f"| {mode} | {where} | {tr.n_steps} | {wall:.0f} | {final['U'] * 1e6:.3f} | "
              f"{final['U'] / f0['U']:.3f} | {final['motor_power'] * 1e15:.3g} | "
              f"{final['eta'] * 100:.3g} | {final['eta'] / f0['eta']:.3f} "
              f"| {off} | {gap} |")

if __name__ == "__main__":
    main()
