"""C. insecticola swimming into a constricted tube: does it pass, and in which mode
(docs/confinement.md, "C. insecticola into a constriction").

Run: ``python studies/constriction.py [--modes wrapped extended] [--tube-radius 1.25]
[--neck 0.5] [--neck-length 2] [--spacing 0.2] [--max-turns 40] [--out out/constriction]``
(the docs' runs: ``--modes wrapped --spacing 0.25 [--neck 0.4]``)

1. The two swimming states of ``examples/c_insecticola_torque_speed.toml`` (E. coli's
   torque-speed line, 4500 pN nm stall: the motor that makes this cell wrap,
   docs/bacterium.md), in the motor's frame: **extended**, the end of its 3 CCW reference
   periods; **wrapped**, the end of 3 CCW + 12 CW (the filament round the body). Kept in
   ``out/states.npz``.
2. Each state put back at the origin unturned (the pole at 0, the body along +z) and run
   ``--free`` reference periods in free space: its speed along the body axis, its direction
   (which end leads), and the radius of the cylinder that holds it (``envelope_radius``).
3. The same state inside an open tube of radius ``--tube-radius`` about the body's axis with a
   cosine constriction to ``--neck`` (radius, um) over ``--neck-length`` um, placed ahead of
   the cell in its swimming direction (the cell turned to swim towards +z), its start
   ``--lead`` um beyond the cell's leading point; the tube reaches ``--behind`` um behind
   the cell and ``--beyond`` um past the neck. Blobs ``--spacing`` um apart. The run goes on until the body's centre has passed the
   neck's middle (**passes**), or has moved less than ``--stuck`` um along the axis over the
   last ``--window`` reference periods (**stuck**), or ``--max-turns`` periods.

Prints, per reference period, the body centre's position along the axis measured from the
neck's middle, the motor's rate and torque, the closest bead surface to the wall and the
body's distance from the axis; then one row per mode. Each run file is kept in ``--out``.
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import sys
import time
from pathlib import Path

import one_thread  # noqa: F401  (one thread per process, before numpy loads)

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))

from tube_swimming import at_origin

from flagwrap.cases import case_files
from flagwrap.geometry.frames import quaternion_matrix
from flagwrap.io.config import load_config
from flagwrap.params import Phase
from flagwrap.simulation import TWO_PI, RunInterrupted, Simulation

UM = 1e-6
CASE = "c_insecticola_torque_speed"


def base_config(protocol):
    cfg = load_config(case_files()[CASE])
    return cfg.replace(motor=dataclasses.replace(cfg.motor, protocol=protocol),
                       numerics=dataclasses.replace(cfg.numerics, frame="rotating"))


def states(out: Path):
    """``{"extended": (y, frames), "wrapped": (y, frames)}`` in the motor's frame (kept in
    ``out/states.npz``)."""
    from tube_swimming import states as swimming_states

    return swimming_states(out, base_config,
                           {"extended": (Phase("ccw", 3.0),),
                            "wrapped": (Phase("ccw", 3.0), Phase("cw", 12.0))})


class Passage:
    """Terminating event: every reference period, the body centre's coordinate along the
    tube's axis (+z, the way the cell swims) relative to the neck's middle; "passes" once it
    is beyond the middle, "stuck" once it moved less than ``stuck`` over the last ``window``
    periods. Lengths in core units (L); ``centre_offset`` the body centre from the pole."""

    def __init__(self, z_neck, centre_offset, stuck, window):
        self.z_neck, self.c = z_neck, centre_offset
        self.stuck, self.window = stuck, int(window)
        self.track: list[float] = []
        self.next = 1.0

    def __call__(self, traj) -> str:
        if traj.t[-1] / TWO_PI < self.next - 1e-9:
            return ""
        self.next += 1.0
        b = np.asarray(traj.body[-1], float)
        zc = b[2] + self.c * quaternion_matrix(b[3:7])[2, 2]
        self.track.append(zc)
        print(f"  period {self.next - 1:.0f}: body centre {zc - self.z_neck:+.4f} L from the "
              f"neck's middle, {len(traj.t)} frames", flush=True)
        if zc > self.z_neck:
            return f"passes: the body centre is past the neck's middle after {self.next - 1:.0f} periods"
        if len(self.track) > self.window and \
                abs(self.track[-1] - self.track[-1 - self.window]) < self.stuck:
            return (f"stuck: the body centre moved {abs(self.track[-1] - self.track[-1 - self.window]):.2e} L "
                    f"in {self.window} periods")
        return ""


def run(cfg, y0, base, turns, path, stop=None, flip=False):
    """Run ``turns`` reference periods from the state and write the run file ``path``; with a
    ``stop`` event, checkpointed every 2 min beside it (``.ckpt.h5``) and resumed from there
    when that file exists (the event then counts periods from the checkpoint's time)."""
    from flagwrap.io.checkpoint import read_checkpoint
    from flagwrap.io.runfile import write_run

    ck = path.with_name(path.stem + ".ckpt.h5")
    sim = Simulation(cfg, **({} if stop is None else
                             {"checkpoint_path": ck, "checkpoint_every_seconds": 120.0}))
    y = at_origin(sim.system, y0, flip)
    start = time.perf_counter()
    try:
        if stop is not None and ck.exists():
            c = read_checkpoint(ck)
            stop.next = math.floor(c.t / TWO_PI + 1e-9) + 1.0
            print(f"  resumed from {ck} at t/T = {c.t / TWO_PI:.3f}", flush=True)
            tr = sim.run(resume=c, stop=stop)
        else:
            tr = sim.run(t_end=TWO_PI * turns, y0=y, base=base, t0=0.0, stop=stop)
    except RunInterrupted as exc:  # Ctrl-C or SIGTERM: keep what was computed, then stop
        write_run(exc.trajectory, path)
        raise
    wall = time.perf_counter() - start
    write_run(tr, path)
    return tr, wall


def per_period(path, z_neck_m=0.0):
    """Per reference period of a run file: (end time [s], body centre along z from the neck's
    middle [um], motor rate [Hz], motor torque [pN nm], closest bead surface to the wall
    [nm] (nan without a tube), body centre's distance from the axis [um])."""
    from flagwrap.io.runfile import config_of, read_run

    ds = read_run(path)
    cfg = config_of(ds)
    t = ds["time"].values
    T = TWO_PI / cfg.scales.omega
    X = ds["body_position"].values
    q = ds["body_orientation"].values
    half = (cfg.body.radius + cfg.body.cylinder_length) / 2
    centre = X + half * quaternion_matrix(q)[:, :, 2]
    x = ds["position"].values
    a = cfg.filament.cross_section_radius  # the gap of the filament's surface, as wall_summary's
    tube = cfg.tubes[0].geometry(1.0) if cfg.tubes else None
    rows = []
    for k in range(round(t[-1] / T)):
        m = (t > k * T + 1e-12) & (t <= (k + 1) * T + 1e-12)
        if not m.any():
            continue
        j = np.flatnonzero(m)[-1]
        gap = (float(tube.gap(x[m].reshape(-1, 3)).min()) - a) * 1e9 if tube else math.nan
        rows.append((t[j], (centre[j, 2] - z_neck_m) / UM,
                     float(np.mean(ds["omega"].values[m])) / TWO_PI,
                     float(np.mean(ds["motor_torque"].values[m])) * 1e21,
                     gap, float(np.hypot(*centre[j, :2])) / UM))
    return rows


def main(argv=None):
    from wall_swimming import envelope_radius

    from flagwrap.params import TubeWall

    p = argparse.ArgumentParser()
    p.add_argument("--modes", nargs="+", default=["wrapped", "extended"])
    p.add_argument("--tube-radius", type=float, default=1.25, help="R_t [um]")
    p.add_argument("--neck", type=float, default=0.5, help="R_c [um]")
    p.add_argument("--neck-length", type=float, default=2.0, help="l_c [um]")
    p.add_argument("--lead", type=float, default=0.3, help="[um] from the cell's lead to the neck")
    p.add_argument("--behind", type=float, default=0.5, help="[um] of tube behind the cell")
    p.add_argument("--beyond", type=float, default=2.5, help="[um] of tube past the neck")
    p.add_argument("--spacing", type=float, default=0.2, help="blob spacing [um]")
    p.add_argument("--free", type=float, default=3.0, help="reference periods in free space")
    p.add_argument("--max-turns", type=float, default=40.0)
    p.add_argument("--stuck", type=float, default=0.02, help="[um] of progress that is not stuck")
    p.add_argument("--window", type=int, default=5, help="reference periods")
    p.add_argument("--out", default="out/constriction")
    args = p.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    found = states(out)
    for mode in args.modes:
        y0, base = found[mode]
        cfg = base_config((Phase("cw" if mode == "wrapped" else "ccw", args.max_turns),))
        L = cfg.filament.length
        free_path = out / f"{mode}_free.nc"
        if not free_path.exists():
            tr, wall = run(cfg, y0, base, args.free, free_path)
            print(f"{mode} free: {tr.status} {tr.n_steps} steps {wall:.0f} s", flush=True)
        free = per_period(free_path)
        u_free = (free[-1][1] - free[0][1]) / (free[-1][0] - free[0][0])  # um/s over the last periods
        # The tube run is turned so that the cell swims towards +z: the config's own check
        # of a tube places it against the config's rest helix (hanging along -z from the
        # pole), which a neck below the pole would cross; the state the run starts from is
        # checked against the tube by Simulation.run itself.
        flip = u_free < 0
        env = envelope_radius(free_path) / UM
        sim = Simulation(cfg)
        zs = np.asarray(at_origin(sim.system, y0)[sim.system.sl_x]).reshape(-1, 3)[:, 2] * L / UM
        lo = min(zs.min(), 0.0)
        hi = max(zs.max(), (cfg.body.radius + cfg.body.cylinder_length) / UM)
        if flip:
            lo, hi = -hi, -lo
        z_neck = hi + args.lead + args.neck_length / 2
        back = lo - args.behind
        front = z_neck + args.neck_length / 2 + args.beyond
        tube = TubeWall(radius=args.tube_radius * UM, length=float(front - back) * UM,
                        center=(0.0, 0.0, float(front + back) / 2 * UM), axis=(0.0, 0.0, 1.0),
                        constriction_radius=args.neck * UM,
                        constriction_length=args.neck_length * UM,
                        constriction_center=float(z_neck - (front + back) / 2) * UM,
                        blob_spacing=args.spacing * UM)
        print(f"{mode}: free speed {u_free:+.2f} um/s along the body axis, envelope radius "
              f"{env:.2f} um, cell z {lo:.2f} to {hi:.2f} um; neck's middle at {z_neck:+.2f} um, "
              f"tube {back:+.2f} to {front:+.2f} um", flush=True)
        half = (cfg.body.radius + cfg.body.cylinder_length) / 2 / L
        stop = Passage(z_neck * UM / L, half, args.stuck * UM / L, args.window)
        tag = f"Rt{args.tube_radius:g}_Rc{args.neck:g}_lc{args.neck_length:g}_h{args.spacing:g}"
        path = out / f"{mode}_{tag}.nc"
        tr, wall = run(cfg.replace(tubes=(tube,)), y0, base, args.max_turns, path, stop=stop,
                       flip=flip)
        print(f"{mode} {tag}: {tr.status} ({tr.message}); {tr.n_steps} steps "
              f"({tr.n_rejected} rejected), {wall:.0f} s", flush=True)
        print("| period end [ms] | body centre from the neck's middle [um] | motor [Hz] | "
              "torque [pN nm] | closest bead to the wall [nm] | body off axis [um] |")
        print("|---:|---:|---:|---:|---:|---:|")
        for t, zc, f, m, gap, off in per_period(path, z_neck * UM):
            print(f"| {t * 1e3:.1f} | {zc:+.3f} | {f:+.1f} | {m:.0f} | {gap:.0f} | {off:.3f} |")
        for t, zc, f, m, gap, off in free[-1:]:
            print(f"free space, last period: motor {f:+.1f} Hz, torque {m:.0f} pN nm")


if __name__ == "__main__":
    try:
        main()
    except RunInterrupted as exc:  # the run file holds what was computed; the checkpoint resumes
        sys.exit(f"stopped: {exc}")
