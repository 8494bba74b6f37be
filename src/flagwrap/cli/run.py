"""Run a simulation from a TOML config or a built-in case (by name) and write a run file.

Examples::

    flagwrap run examples/fig4a.toml -o out/fig4a.nc
    flagwrap run fig4a -o out/fig4a.nc --figure out/fig4a.png     # a built-in case, from any folder
    flagwrap run --list-cases                                     # the built-in cases (examples/*.toml)
    flagwrap run examples/fig4a.toml -o out/fig4a.nc --resume     # after a crash or kill

Built-in cases: every example config ships with the package; its name (``fig4a``, ``hook``,
``s_putrefaciens``, ...) works wherever a config path does (run, critical, stability, the API).

Checkpoints: the complete loop state goes to ``--checkpoint`` (default ``<output>.ckpt.h5``)
every ``--checkpoint-seconds`` (default 60) of wall time and/or every ``--checkpoint-every``
accepted steps, written atomically (temporary file, fsync, rename). ``--resume`` continues from
it and gives the same run file as an uninterrupted run (bit for bit, same version and threads);
it refuses a checkpoint of another config or version. The checkpoint is deleted once the run
completes. A run stopped by a guard (non-finite force, bead in the body, bond strain, step size
below ``numerics.dt_min``) still writes its run file: every frame up to the last good one, with
``status = "failed"`` and the message, and exits 1. Input errors exit 2 before any work starts
(including a run whose output would not fit in memory or on disk).
"""

from __future__ import annotations

import sys


#: ``--precise``: the tolerance at which a swimmer's mean rates are within 0.5 % of converged
#: (docs/bacterium.md: 0.44 % for issue 35's stiff swimmer, 0.1-0.7 % from tol 1e-5 on
#: S. putrefaciens)
PRECISE_TOL = 1e-6

def add_arguments(p):
    p.add_argument("config", nargs="?",
                   help="TOML config file or the name of a built-in case (--list-cases)")
    from flagwrap.cases import CASES

    p.add_argument("--case", choices=sorted(CASES), metavar="NAME",
                   help="a built-in case instead of a file (same as giving its name as CONFIG)")
    p.add_argument("--list-cases", action="store_true",
                   help="list the built-in cases (the example configs shipped with the package) "
                        "and where their files are, and run nothing")
    p.add_argument("-o", "--output", help="run file to write (.nc); default out/<name>.nc")
    p.add_argument("--figure", help="also write a summary figure (PNG/PDF) of tip height and torque")
    p.add_argument("--no-hi", action="store_true", help="switch long-range hydrodynamics off")
    p.add_argument("--integrator", choices=["ros34pw2", "ros2", "euler"], help="override numerics.integrator")
    p.add_argument("--frame", choices=["lab", "rotating"], default=None,
                   help="step in the lab frame or the frame turning with the motor (numerics.frame; "
                        "docs/stability.md; on a free cell the motor's frame relative to the body, "
                        "docs/bacterium.md); the run file is in the lab frame either way")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.add_argument("--perturb", type=float, default=None, metavar="METRES",
                   help="start from the rest shape displaced by at most this much (overrides "
                        "initial.perturbation; 0 = at rest)")
    p.add_argument("--seed", type=int, default=None, help="seed of the random perturbation (initial.seed)")
    p.add_argument("--perturb-mode", choices=["random", "lateral"], default=None,
                   help="shape of the perturbation (initial.mode)")
    p.add_argument("--shape", choices=["helix", "straight"], default=None,
                   help="stress-free shape of the filament (overrides filament.shape)")
    p.add_argument("--self-contact", action="store_true",
                   help="filament self-contact on (contact.self_contact = true)")
    p.add_argument("--checkpoint", metavar="PATH", help="checkpoint file (default <output>.ckpt.h5)")
    p.add_argument("--checkpoint-every", type=int, default=0, metavar="N",
                   help="also checkpoint every N accepted steps (default: off)")
    p.add_argument("--checkpoint-seconds", type=float, default=60.0, metavar="S",
                   help="checkpoint every S seconds of wall time (default 60; 0 = off)")
    p.add_argument("--no-checkpoint", action="store_true", help="write no checkpoints")
    p.add_argument("--resume", action="store_true",
                   help="continue from the checkpoint (same config and options as the first run)")
    p.add_argument("--turns", type=float, nargs=2, metavar=("CCW", "CW"), default=None,
                   help="a shorter (or longer) protocol for a first try: CCW motor turns, then "
                        "CW (0: none), instead of motor.protocol")
    p.add_argument("--precise", action="store_true",
                   help=f"numerics.tol = {PRECISE_TOL:g} (if looser): the preset for quoting mean "
                        "rates (swimming speed, rotation, motor rate) within 0.5 %% "
                        "(docs/bacterium.md, 'Tolerance for swimmers'); about 2x the steps")
    p.add_argument("--dry-run", action="store_true",
                   help="say what the run would cost (unknowns, memory, disk, a measured time "
                        "per step and per turn) and run nothing")


def load(args):
    import dataclasses
    import math

    from flagwrap.cases import get_case
    from flagwrap.errors import UserInputError
    from flagwrap.io.config import load_config_or_case

    if (args.config is None) == (args.case is None):
        raise UserInputError("give a config file or --case NAME (not both)")
    cfg = load_config_or_case(args.config) if args.config else get_case(args.case)
    num = cfg.numerics
    if args.no_hi:
        num = dataclasses.replace(num, hydrodynamics=False)
    if args.integrator:
        num = dataclasses.replace(num, integrator=args.integrator)
    if getattr(args, "frame", None):
        num = dataclasses.replace(num, frame=args.frame)
    if getattr(args, "precise", False) and num.tol > PRECISE_TOL:
        num = dataclasses.replace(num, tol=PRECISE_TOL)
    ini = cfg.initial
    changes = {k: v for k, v in (("perturbation", getattr(args, "perturb", None)),
                                 ("seed", getattr(args, "seed", None)),
                                 ("mode", getattr(args, "perturb_mode", None))) if v is not None}
    if changes:
        try:
            ini = dataclasses.replace(ini, **changes)
        except UserInputError as exc:  # name the option, not the config key
            raise UserInputError(str(exc).replace("initial.perturbation", "--perturb")
                                 .replace("initial.seed", "--seed")) from None
    turns = getattr(args, "turns", None)
    if turns is not None:
        from flagwrap.params import Phase

        ccw, cw = turns
        if not (math.isfinite(ccw) and math.isfinite(cw) and ccw >= 0 and cw >= 0 and ccw + cw > 0):
            raise UserInputError(f"--turns must be two numbers >= 0 (CCW CW), not both 0, got "
                                 f"{ccw:g} {cw:g}")
        phases = tuple(Phase(d, t) for d, t in (("ccw", ccw), ("cw", cw)) if t > 0)
        if cfg.flagella and any(f.protocol for f in cfg.flagella):
            raise UserInputError("--turns replaces motor.protocol, but [[flagellum]] tables have "
                                 "their own protocols: edit them in the config instead")
        cfg = cfg.replace(motor=dataclasses.replace(cfg.motor, protocol=phases))
    fil, con = cfg.filament, cfg.contact
    if getattr(args, "shape", None):
        fil = dataclasses.replace(fil, shape=args.shape, pitch_angle_deg=None, turns=None)
    if getattr(args, "self_contact", False):
        con = dataclasses.replace(con, self_contact=True)
    return cfg.replace(numerics=num, initial=ini, filament=fil, contact=con)


def run(args) -> int:
    import math
    from pathlib import Path

    from flagwrap.errors import UserInputError
    from flagwrap.resources import check_disk, check_memory

    if getattr(args, "list_cases", False):
        return _list_cases(args)
    cfg = load(args)
    out = Path(args.output or f"out/{cfg.name}.nc")
    if args.checkpoint_every < 0:
        raise UserInputError(f"--checkpoint-every must be >= 0, got {args.checkpoint_every}")
    if not (math.isfinite(args.checkpoint_seconds) and args.checkpoint_seconds >= 0):
        raise UserInputError(f"--checkpoint-seconds must be >= 0, got {args.checkpoint_seconds}")
    ckpt = None if args.no_checkpoint else Path(args.checkpoint or f"{out}.ckpt.h5")
    if args.resume and ckpt is None:
        raise UserInputError("--resume needs a checkpoint (drop --no-checkpoint)")
    resume = None
    if args.resume:
        from flagwrap.io.checkpoint import check_compatible, read_checkpoint

        resume = read_checkpoint(ckpt)
        check_compatible(resume, cfg, ckpt)
    est = check_memory(cfg)
    check_disk(cfg, out, checkpoint=ckpt is not None)
    if getattr(args, "dry_run", False):
        return _dry_run(cfg, est, out)
    from flagwrap.io.outputs import check_output_file, output_lock

    check_output_file(out, "output (-o)")
    if ckpt is not None:
        check_output_file(ckpt, "checkpoint")
        if ckpt.resolve() == out.resolve():
            raise UserInputError(f"--checkpoint {ckpt} is the output file itself; give another path")
    if args.figure:
        from flagwrap.plotting.summary import figure_suffixes

        check_output_file(args.figure, "--figure", suffixes=figure_suffixes())
    with output_lock(out, ckpt):
        return _simulate(args, cfg, out, ckpt, resume)


def _list_cases(args) -> int:
    """Print each built-in case: name, what it is (its file's first comment line), and the
    folder of the files (to copy one and edit it)."""
    from flagwrap.cases import CASES_DIR, case_files, describe
    from flagwrap.errors import UserInputError

    if args.config is not None or args.case is not None:
        raise UserInputError("--list-cases takes no config or --case")
    names = case_files()
    width = max(map(len, names))
    for name in names:
        print(f"{name:<{width}}  {describe(name)}")
    print(f"({len(names)} cases; files in {CASES_DIR}; run one by name: flagwrap run NAME)")
    return 0


def _dry_run(cfg, est, out) -> int:
    """Print what the run would cost and run nothing but a 20-step probe (its time per
    step); the turns' step counts are a range measured on the paper's and the bacterial
    examples (benchmarks/integrators.py, benchmarks/swimmer.py)."""
    import dataclasses

    from flagwrap.simulation import Simulation, make_system

    n_f = max(1, len(cfg.flagella))
    print(f"flagwrap run {cfg.name} (dry run): {n_f} flagell{'um' if n_f == 1 else 'a'} of "
          f"{cfg.filament.n_beads} beads, {est.unknowns} unknowns, M = {cfg.machin:.4g}, "
          f"{est.total_turns:g} motor turns, {est.n_saves:.0f} frames saved")
    print(f"  memory ~{est.memory / 2**20:.0f} MiB (output {est.output_memory / 2**20:.0f}, "
          f"linear algebra {est.linalg_memory / 2**20:.0f}); run file ~"
          f"{est.file_bytes / 2**20:.1f} MiB at {out}")
    probe = cfg.replace(numerics=dataclasses.replace(cfg.numerics, max_steps=20))
    system = make_system(probe)
    Simulation(probe, system=system).run()  # compiles and warms the kernels
    tr = Simulation(probe, system=system).run()
    per = tr.wall_time / max(tr.n_steps, 1)
    # steps per motor turn at tol 1e-5: ~1100-1250 (Fig. 4(a) rig and free cells, CCW); two
    # to three times that while flagella bundle, fold or wrap (docs/bundle.md)
    lo, hi = 1000 * est.total_turns * per, 3000 * est.total_turns * per
    tol = cfg.numerics.tol
    print(f"  measured {per * 1e3:.1f} ms per step (20 steps); a motor turn takes ~1000-3000 "
          f"steps at tol 1e-5 (this config: tol {tol:g}{', fewer' if tol > 1e-5 else ''}"
          f"{', more' if tol < 1e-5 else ''}), so the run ~{_duration(lo)} to {_duration(hi)} "
          "on this machine")
    print("  nothing was run (drop --dry-run to run it)")
    return 0


def _duration(sec: float) -> str:
    if sec < 120:
        return f"{sec:.0f} s"
    if sec < 7200:
        return f"{sec / 60:.0f} min"
    return f"{sec / 3600:.1f} h"


def _completed_run_at(path) -> bool:
    """Whether ``path`` holds a readable run file with ``status = "completed"``."""
    import h5py

    try:
        with h5py.File(path, "r") as f:
            return str(f.attrs.get("status", "")) == "completed"
    except Exception:
        return False


def _simulate(args, cfg, out, ckpt, resume) -> int:
    import math

    from flagwrap.io.outputs import write_or_rescue
    from flagwrap.io.runfile import write_run
    from flagwrap.simulation import simulate

    keep = out.exists() and _completed_run_at(out)

    def write_or_name_checkpoint(traj, target, what):
        # under a file-size limit or a full disk the rescue in the temporary folder fails too;
        # the last checkpoint that was written is then where the work is kept: say so
        from flagwrap.errors import OutputWriteError

        try:
            write_or_rescue(lambda p: write_run(traj, p), target, what)
        except OutputWriteError as exc:
            if ckpt is None or not ckpt.exists():
                raise
            msg = str(exc)
            try:
                from flagwrap.io.checkpoint import read_checkpoint

                c = read_checkpoint(ckpt)
                upto = f"the run up to t/T = {c.t / (2 * math.pi):.4g} ({c.n_steps} steps)"
            except Exception:  # noqa: BLE001 - an unreadable checkpoint keeps nothing
                raise exc from None
            if msg.endswith("; it is lost"):
                msg = msg[: -len("; it is lost")]
            raise OutputWriteError(f"{msg}; {upto} is kept in the checkpoint {ckpt} "
                                   "(--resume continues from it once there is room)") from None

    def write_partial(traj):
        # a failed or interrupted run never replaces a completed run file: it goes beside it
        target = out.with_name(f"{out.stem}.partial{out.suffix}") if keep else out
        write_or_name_checkpoint(traj, target, "partial run")
        return target

    if resume is not None:
        print(f"flagwrap run: resuming from {ckpt} at t/T = {resume.t / (2 * math.pi):.4g} "
              f"({resume.n_steps} steps done)", file=sys.stderr)
    elif ckpt is not None and ckpt.exists():
        print(f"flagwrap run: note: {ckpt} holds an earlier run's checkpoint; starting over "
              "(--resume continues from it instead)", file=sys.stderr)
    print(f"flagwrap run {cfg.name}: M = {cfg.machin:.4g}, Re = {cfg.reynolds:.3g}, "
          f"G = {cfg.gravity_number:.4g}{_mismatch(cfg)}, "
          f"omega/omega_c (scaling) = {cfg.omega_ratio_scaling:.3g}, N = {cfg.filament.n_beads}, "
          f"HI {'on' if cfg.numerics.hydrodynamics else 'off'}{_bead_model(cfg)}", file=sys.stderr)
    _weak_chain_note(cfg)
    if cfg.filament.shape == "helix" and cfg.omega_ratio_scaling > 1.0:
        # the paper's scaling line is not this model's threshold (docs/stability.md): a
        # header that reads "above threshold" must not promise a buckling run
        print(f"flagwrap run: note: omega/omega_c (scaling) = {cfg.omega_ratio_scaling:.3g} "
              "is against the paper's scaling line; this model's threshold for a helix lies "
              "~4x higher in M (the Fig. 4(a) helix: M_c = 617 against the line's 142), so "
              "the run may stay stable: `flagwrap stability` gives this helix's M_c in "
              "seconds (docs/stability.md)", file=sys.stderr)
    if cfg.reynolds > 0.1:
        # the model is Stokes flow by construction; the dimensionless result holds for any fluid
        # at this M, but not for this SI fluid at this speed
        print(f"flagwrap run: note: Re = {cfg.reynolds:.3g} > 0.1: Stokes flow (the model) does not "
              "describe this fluid at this speed; the result holds for the same M in a more viscous "
              "fluid or at a smaller scale", file=sys.stderr)
    from flagwrap.simulation import RunInterrupted

    try:
        traj = simulate(cfg, progress=not args.quiet, resume=resume, checkpoint_path=ckpt,
                        checkpoint_every_steps=args.checkpoint_every,
                        checkpoint_every_seconds=args.checkpoint_seconds)
    except RunInterrupted as stop:
        target = write_partial(stop.trajectory)
        print(f"flagwrap run: run stopped: {stop.trajectory.message} (partial output kept in "
              f"{target}{'; --resume continues from the last checkpoint' if ckpt is not None else ''}"
              f"{f'; the completed {out} is unchanged' if target != out else ''})", file=sys.stderr)
        return 143 if stop.signame == "SIGTERM" else 130  # 128 + the signal's number
    if traj.ok:
        write_or_name_checkpoint(traj, out, "run file")
    else:
        out_written = write_partial(traj)
    if traj.ok and ckpt is not None and ckpt.exists():
        ckpt.unlink()  # the run file now holds everything
    written = out if traj.ok else out_written
    print(f"wrote {written} ({traj.status}, {traj.n_steps} steps, {traj.wall_time:.1f} s)", file=sys.stderr)
    if args.figure:
        from flagwrap.io.runfile import read_run
        from flagwrap.plotting.summary import summary_figure

        summary_figure(read_run(written), args.figure)
        print(f"wrote {args.figure}", file=sys.stderr)
    if not traj.ok:
        print(f"flagwrap run: run stopped: {traj.message} (partial output kept in {out_written}"
              f"{f'; the completed {out} is unchanged' if out_written != out else ''})", file=sys.stderr)
        return 1
    return 0


def _bead_model(cfg) -> str:
    """The header's word on the beads: the tube model's matched radius (issue 35)."""
    fil = cfg.filament
    if fil.hydrodynamic_model == "tube":
        return (f" (beads matched to a tube of radius a: a_h = "
                f"{fil.bead_radius / fil.cross_section_radius:.3g} a, kappa = {fil.tube_kappa:.3g})")
    return ""


def _weak_chain_note(cfg) -> None:
    """A free swimmer on sphere beads much thinner, hydrodynamically, than the filament: its
    speeds and torques are low by tens of per cent (docs/bacterium.md)."""
    from flagwrap.theory.slender_body import chain_effective_radii

    fil = cfg.filament
    if not (cfg.body.free and cfg.numerics.hydrodynamics and fil.hydrodynamic_model == "spheres"):
        return
    if fil.bond_length < 2 * fil.bead_radius:
        return  # overlapping beads: outside the formula, and not a thin chain
    r_par, r_perp = chain_effective_radii(fil.bead_radius, fil.bond_length)
    if r_perp < 0.5 * fil.cross_section_radius:
        print(f"flagwrap run: note: the sphere beads at b = {fil.bond_length / fil.cross_section_radius:.3g} a "
              f"drag like a tube of radius {r_par / fil.cross_section_radius:.2f} a along and "
              f"{r_perp / fil.cross_section_radius:.2f} a across, so this swimmer's speed and "
              "torques come out low by tens of per cent; filament.hydrodynamic_model = 'tube' "
              "matches the filament (docs/bacterium.md)", file=sys.stderr)


def _mismatch(cfg) -> str:
    """`` (density mismatch -2 %)`` where the filament is not density-matched."""
    if cfg.filament.density is None:
        return ""
    return f" (density mismatch {100 * cfg.density_mismatch:+.3g} %)"
