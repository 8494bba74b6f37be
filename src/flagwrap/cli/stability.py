"""Critical Machin number M_c from linear stability: steady whirl, eigenvalues, crossing type.

The steady state of the config's helix turning at constant speed (a fixed point in the frame
that turns with the motor) is followed in M by Newton continuation from M_START. The
eigenvalues of its Jacobian are computed along the way, and M_c is where the leading one
first crosses zero. Prints M_c, omega_c (SI), the crossing type (Hopf: a complex pair, with
its frequency in the turning frame; steady: a real eigenvalue) and the steady shape at M_c.
The config's motor protocol and M are not used; its geometry, fluid, body, joint and
numerics.hydrodynamics are. A torque or torque-speed motor ([motor] kind) is also judged: the
torque the whirl needs at f_c against the motor's there, whether it buckles the filament, and
the stall torque it would take. Method and validation: docs/stability.md.

Exit status: 0 found, 1 no crossing in the range or the branch lost (what was found is
printed), 2 bad input.

Examples::

    flagwrap stability examples/fig4a.toml
    flagwrap stability examples/fig4a.toml --direction ccw --m-max 3000 --json
    flagwrap stability examples/movie7.toml --mode out/movie7_mode.png --vtk out/movie7_mode.vtp
    flagwrap stability examples/sweeps/fig5.toml --sweep     # every helix of Fig. 5 -> JSON
"""

from __future__ import annotations

import math


def add_arguments(p):
    p.add_argument("config", metavar="CONFIG.toml",
                   help="geometry/fluid/numerics (its M and protocol are not used)")
    p.add_argument("--direction", choices=["cw", "ccw"], default="cw",
                   help="motor direction of the steady state (cw: the buckling one; default)")
    p.add_argument("--m-start", type=float, default=10.0, help="first M of the continuation (10)")
    p.add_argument("--m-max", type=float, default=None,
                   help="last M (default: 20x the scaling line 0.06 (R/L)^-3)")
    p.add_argument("--rtol", type=float, default=1e-3, help="relative width of the final M bracket (1e-3)")
    p.add_argument("--factor", type=float, default=1.25, help="largest continuation step in M (x1.25)")
    p.add_argument("--no-hi", action="store_true", help="switch hydrodynamic interactions off")
    p.add_argument("--mode", default=None, metavar="FILE.png",
                   help="plot the steady shape and the critical mode")
    p.add_argument("--vtk", default=None, metavar="FILE.vtp",
                   help="write the steady shape at M_c with the critical mode as point data (ParaView)")
    p.add_argument("--json", action="store_true", help="print the result as one JSON object")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    g = p.add_argument_group("a whole diagram")
    g.add_argument("--sweep", action="store_true",
                   help="CONFIG is a sweep file (e.g. examples/sweeps/fig5.toml): M_c (CW) of each "
                        "of its geometries, up to 30x the scaling line, written to --out")
    g.add_argument("--out", default=None, metavar="FILE.json",
                   help="result file of --sweep (out/stability/<sweep name>.json)")
    g.add_argument("--workers", type=int, default=None, help="processes for --sweep (the cores)")
    f = p.add_argument_group("two thresholds: the far (wrapped/folded) branch and its fold")
    f.add_argument("--far", action="store_true",
                   help="the bifurcation diagram: the whirl's Hopf, the far state's branch and its "
                        "fold M_f, the Hopf cycle from the time domain (docs/stability.md)")
    f.add_argument("--diagram", default=None, metavar="FILE.png",
                   help="plot the bifurcation diagram (implies --far)")
    f.add_argument("--far-from", default=None, metavar="RUN.nc",
                   help="start the far branch from a run file's last frame (same helix; implies --far)")
    f.add_argument("--m-far", type=float, default=None,
                   help="M of the reversal that finds a far state (1.07, then 1.25, 1.5 M_Hopf)")
    f.add_argument("--m-lo", type=float, default=None, help="lowest M of the far branch (0.3 M_Hopf)")
    f.add_argument("--m-hi", type=float, default=None, help="highest M of the diagram (1.5 M_Hopf)")
    f.add_argument("--settle", type=float, default=20.0,
                   help="motor turns of each relaxation run on the far branch (20)")
    f.add_argument("--cycles", default="1.02,1.05", metavar="R1,R2",
                   help="M/M_Hopf of the time-domain Hopf cycles ('none': no cycle; 1.02,1.05)")


def check_options(args) -> None:
    """Every option's range before any work (one-line errors naming the option)."""
    from flagwrap.errors import UserInputError
    from flagwrap.io.outputs import check_output_file
    from flagwrap.stability.threshold import check_continuation_options

    check_continuation_options(args.m_start, args.m_max, args.rtol, args.factor,
                               option=lambda name: "--" + name.replace("_", "-"))
    if args.mode is not None:
        check_output_file(args.mode, "--mode", {".png", ".pdf", ".svg"})
    if args.vtk is not None:
        check_output_file(args.vtk, "--vtk", {".vtp"})
    if getattr(args, "workers", None) is not None and not 1 <= args.workers <= 256:
        raise UserInputError(f"--workers must be in [1, 256], got {args.workers}")
    if getattr(args, "out", None) is not None:
        if not getattr(args, "sweep", False):
            raise UserInputError("--out is the result file of --sweep; without --sweep use --json")
        check_output_file(args.out, "--out", {".json"})
    from flagwrap.stability.bifurcation import check_diagram_options

    check_diagram_options(getattr(args, "m_far", None), getattr(args, "m_lo", None),
                          getattr(args, "m_hi", None), getattr(args, "settle", 20.0), 1.06,
                          _cycles(getattr(args, "cycles", None)),
                          option=lambda name: "--" + name.replace("_", "-"))
    far = _wants_far(args)
    if not far:
        given = [o for o, v in (("--m-far", getattr(args, "m_far", None)),
                                ("--m-lo", getattr(args, "m_lo", None)),
                                ("--m-hi", getattr(args, "m_hi", None)))
                 if v is not None]
        if getattr(args, "settle", 20.0) != 20.0:
            given.append("--settle")
        if given:
            raise UserInputError(f"{', '.join(given)}: options of the far branch; add --far")
    if far:
        if getattr(args, "sweep", False) and (args.diagram or args.far_from or args.m_far
                                              or args.m_lo or args.m_hi):
            raise UserInputError("--sweep --far adds each helix's fold M_f to the sweep's "
                                 "rows: --diagram, --far-from, --m-far, --m-lo and --m-hi "
                                 "apply to one helix")
        if args.mode or args.vtk:
            raise UserInputError("--far (--diagram, --far-from) draws the diagram: --mode and "
                                 "--vtk do not apply")
        if args.diagram is not None:
            check_output_file(args.diagram, "--diagram", {".png", ".pdf", ".svg"})
        if args.far_from is not None:
            from pathlib import Path

            if not Path(args.far_from).is_file():
                raise UserInputError(f"--far-from: run file not found: {args.far_from}")
    if getattr(args, "sweep", False) and (args.mode or args.vtk or args.direction != "cw"
                                          or args.m_max is not None):
        raise UserInputError("--sweep computes the CW threshold of every geometry up to 30x its "
                             "scaling line: --mode, --vtk, --direction and --m-max do not apply")


def _wants_far(args) -> bool:
    return bool(getattr(args, "far", False) or getattr(args, "diagram", None)
                or getattr(args, "far_from", None))


def _cycles(text) -> tuple:
    """``--cycles``: comma-separated M/M_Hopf ratios, or 'none'."""
    from flagwrap.errors import UserInputError

    if text is None or str(text).strip().lower() in ("none", ""):
        return ()
    try:
        return tuple(float(v) for v in str(text).split(","))
    except ValueError:
        raise UserInputError(f"--cycles must be comma-separated numbers in (1, 2] or 'none', "
                             f"got {text!r}") from None


def _bar(enabled, m_start, m_max):
    if not enabled:
        return None
    from tqdm.auto import tqdm

    return tqdm(total=round(math.log(m_max / m_start), 3), unit="ln M", desc="stability",
                bar_format="{l_bar}{bar}| M = {postfix[0]:.4g} [{elapsed}]", postfix=[m_start])


def run(args) -> int:
    import dataclasses
    import json
    import sys

    from flagwrap.io.config import load_config_or_case
    from flagwrap.stability.threshold import (critical_from_config, refuse_polymorph, refuse_tube,
                                              resolve_m_max)

    check_options(args)
    if getattr(args, "sweep", False):
        return _run_sweep(args)
    cfg = load_config_or_case(args.config)
    refuse_polymorph(cfg)
    refuse_tube(cfg)
    if args.no_hi:
        cfg = cfg.replace(numerics=dataclasses.replace(cfg.numerics, hydrodynamics=False))
    if _wants_far(args):
        return _run_far(args, cfg)
    m_max = resolve_m_max(cfg, args.m_start, args.m_max)
    progress = not (args.json or args.no_progress)
    bar = _bar(progress and sys.stderr.isatty(), args.m_start, m_max)
    import time

    t0 = time.perf_counter()

    def start(m_hi):  # what it is doing, once the system is accepted (a line per state off a TTY)
        if progress:
            fil = cfg.filament
            body = (f", a {cfg.body.motion} no-slip body" if cfg.body.no_slip else "")
            print(f"flagwrap stability {cfg.name}: {fil.n_beads} beads{body}; following the "
                  f"steady {args.direction.upper()} whirl from M = {args.m_start:g} up to "
                  f"{m_hi:.4g} (each state: Newton, then the leading eigenvalues; built in "
                  f"{time.perf_counter() - t0:.1f} s)", file=sys.stderr, flush=True)

    def show(p):
        if bar is not None:
            bar.postfix[0] = p.machin
            bar.n = round(min(bar.total, max(0.0, math.log(p.machin / args.m_start))), 3)
            bar.refresh()
        elif progress:
            lam = p.leading
            print(f"  M = {p.machin:.5g}: leading eigenvalue {lam.real:+.3e} {abs(lam.imag):+.3g}i "
                  f"omega ({time.perf_counter() - t0:.0f} s)", file=sys.stderr, flush=True)

    try:
        res = critical_from_config(cfg, args.direction, m_start=args.m_start, m_max=m_max,
                                   factor=args.factor, rtol=args.rtol, on_point=show,
                                   on_start=start)
    finally:
        if bar is not None:
            bar.close()
    files = _write_mode(res, cfg, args)
    from flagwrap.stability.threshold import onset_prefactor, whirl_torque

    fil = cfg.filament
    t_core = whirl_torque(res) if res.converged else math.nan  # units of A/L
    s = res.summary()
    s.update(config=str(args.config), hydrodynamics=cfg.numerics.hydrodynamics,
             machin_critical_scaling=cfg.machin_critical_scaling, m_start=args.m_start,
             m_max=m_max, files=files, onset_prefactor=onset_prefactor(res.growth_slope),
             torque_c_reduced=t_core * fil.helix_radius / fil.length,
             torque_c=t_core * fil.bending_modulus / fil.length)
    if args.json:
        from flagwrap.sweep.store import jsonable

        print(json.dumps(jsonable(s), sort_keys=True, allow_nan=False))
        return 0 if res.converged else 1
    L = cfg.filament.length
    print(f"{args.config}: linear stability of the steady {args.direction.upper()} whirl "
          f"(HI {'on' if cfg.numerics.hydrodynamics else 'off'}), M from {args.m_start:g} to "
          f"{m_max:.4g}: {len(res.branch)} steady states, {res.wall_time:.1f} s")
    if not res.converged:
        print(f"NOT FOUND: {res.message}")
        return 1
    lo, hi = res.bracket
    lam = res.eigenvalue
    print(f"M_c     = {res.machin_c:.2f}  (bracket {lo:.2f} .. {hi:.2f})")
    print(f"omega_c = {res.omega_c:.5g} rad/s  (f_c = {res.frequency_c:.5g} Hz)")
    if res.crossing == "hopf":
        print(f"crossing: Hopf; critical pair {lam.real:+.2e} +- {abs(lam.imag):.4f}i omega at "
              f"M = {hi:.2f}: in the turning frame the mode oscillates at {res.mode_frequency:.4f} "
              f"omega_c = {res.mode_frequency * res.omega_c:.4g} rad/s")
    elif res.crossing == "fold":
        print(f"crossing: fold of the steady branch (real eigenvalue {lam.real:+.2e} omega at "
              f"M = {lo:.2f}, going to zero): beyond M_c this steady whirl does not exist")
    else:
        print(f"crossing: steady (real eigenvalue {lam.real:+.2e} omega at M = {hi:.2f}): a new "
              f"steadily turning shape branches off")
    tip = res.state.info.x[-1, 2] if res.state is not None else math.nan
    scale, unit = (1e3, "mm") if L >= 1e-3 else (1e6, "um")  # the rig's helix or a bacterium's
    print(f"steady shape at M_c: free end {(tip - res.tip_z0):+.4f} L above its rest height "
          f"({(tip - res.tip_z0) * L * scale:+.3g} {unit})")
    print(f"M_c / scaling line 0.06 (R/L)^-3 = {res.machin_c / cfg.machin_critical_scaling:.2f}")
    print(f"motor torque of the whirl at M_c: {_torque_text(cfg, t_core)} (the "
          "paper's scaling estimate: N_c ~ 0.5 A/R)")
    if res.growth_slope > 0:
        print(f"growth above M_c: d Re(lambda)/d eps = {res.growth_slope:.3g} omega (eps = "
              f"M/M_c - 1): a 1e-3 L seed grows to the 0.15 L rise in t_c/T ~ "
              f"{s['onset_prefactor']:.2f}/eps by linear growth (the paper's Fig. 6: 0.5/eps; a "
              "saturating Hopf cycle may never reach the rise: docs/stability.md)")
    if res.motor is not None:
        print(_motor_line(res.motor))
    for f in files:
        print(f"wrote {f}")
    return 0


def _motor_line(v) -> str:
    """The torque motor's verdict (:func:`flagwrap.stability.threshold.motor_verdict`)."""
    pn = 1e21  # N m -> pN nm
    curve = (f"stall {v['stall_torque'] * pn:.4g} pN nm, zero load {v['zero_load_speed']:.4g} Hz"
             if v["kind"] == "torque-speed" else f"{v['stall_torque'] * pn:.4g} pN nm")
    head = (f"motor ({v['kind']}, {curve}): the whirl at f_c needs {v['torque_c'] * pn:.4g} pN nm "
            f"and the motor gives {v['torque_available'] * pn:.4g} there: ")
    if v["buckles"]:
        return head + "it turns the filament past its threshold (it buckles)"
    need = v["stall_torque_needed"]
    more = (f"a stall torque above {need * pn:.4g} pN nm would" if math.isfinite(need) else
            "its zero-load speed is below f_c, so no stall torque would")
    return head + f"it stops short of the threshold; {more}"


def _write_mode(res, cfg, args) -> list:
    """The optional plot and VTK file of the critical mode (nothing when not converged)."""
    if res.state is None or not (args.mode or args.vtk):
        return []
    import numpy as np

    from flagwrap.stability.spectrum import mode_positions, spectrum

    sp = spectrum(res.frame, res.state, vectors=True)
    k = int(np.argmin(np.abs(sp.values - res.eigenvalue)))  # the critical one (a fold's is real)
    mode = mode_positions(res.frame, sp.vectors[:, k])
    x = res.state.info.x
    L = cfg.filament.length
    files = []
    if args.vtk:
        from flagwrap.io.vtk import _write, polydata_xml

        amp = 0.05  # the mode drawn at 0.05 L of largest displacement
        _write(args.vtk, polydata_xml(x * L, lines=[np.arange(len(x))], point_data={
            "mode_real": mode.real * amp * L, "mode_imag": mode.imag * amp * L,
            "mode_amplitude": np.linalg.norm(mode, axis=1)}))
        files.append(str(args.vtk))
    if args.mode:
        from flagwrap.plotting.stability import plot_mode

        plot_mode(x, mode, res, cfg, args.mode)
        files.append(str(args.mode))
    return files


def _run_sweep(args) -> int:
    import json
    import sys

    from flagwrap.stability.boundary import stability_boundary
    from flagwrap.sweep.spec import load_spec
    from flagwrap.sweep.store import jsonable, write_json_atomic

    spec = load_spec(args.config)
    far = bool(getattr(args, "far", False))
    out = args.out or f"out/stability/{spec.name}{'_far' if far else ''}.json"
    from flagwrap.io.outputs import check_output_file

    check_output_file(out, "--out", {".json"})
    bar = None
    if not (args.json or args.no_progress) and sys.stderr.isatty():
        from tqdm.auto import tqdm

        from flagwrap.stability.boundary import geometry_configs

        bar = tqdm(total=len(geometry_configs(spec)), unit="helix", desc=f"stability {spec.name}")

    def show(row):
        if bar is not None:
            bar.update(1)
        elif not args.json:
            print(_row_line(row), flush=True)

    try:
        kw = {"far": True} if far else {}
        res = stability_boundary(spec, workers=args.workers, on_row=show, rtol=args.rtol, **kw)
    finally:
        if bar is not None:
            bar.close()
    res = jsonable(res)
    write_json_atomic(res, out)
    if args.json:
        print(json.dumps(res, sort_keys=True, allow_nan=False))
    else:
        if bar is not None:
            for row in res["rows"]:
                print(_row_line(row))
        fit = res["fit"]
        if fit.get("exponent") is not None:
            print(f"fit over {fit['n']} helices: M_c = {fit['prefactor']:.3g} (R/L)^-"
                  f"{fit['exponent']:.3f} +- {fit['exponent_err']:.3f} (rms {fit['rms_ln']:.2f} in "
                  f"ln M_c); the paper's line: 0.06 (R/L)^-3")
        print(f"{len(res['rows'])} helices, {res['wall_time_s']:.1f} s on {res['workers']} "
              f"processes; wrote {out}")
    return 0 if all(r["converged"] for r in res["rows"]) else 1


def _row_line(row) -> str:
    mc = row.get("machin_c")
    head = f"  psi = {row['psi_deg']:5.1f} deg, n = {row['turns']:3.1f}, R/L = {row['r_over_l']:.4f}: "
    if mc is None:
        return head + row["message"]
    line = head + (f"M_c = {mc:8.1f} ({row['crossing']}, Omega = {row['mode_frequency']:.3f} omega), "
                   f"{row['ratio_to_scaling']:.2f}x the scaling line")
    if "far_found" in row:
        mf = row.get("machin_fold")
        line += (f"; far state's fold M_f = {mf:.1f} ({mf / row['machin_scaling']:.2f}x)"
                 if mf is not None else f"; no fold: {row['far_message']}")
    return line


def _torque_text(cfg, t_core) -> str:
    """A motor torque in core units (A/L) as A/R and SI (pN nm for a bacterium)."""
    fil = cfg.filament
    si = t_core * fil.bending_modulus / fil.length
    unit = f"{si * 1e21:.4g} pN nm" if fil.length < 1e-3 else f"{si:.3g} N m"
    return f"{t_core * fil.helix_radius / fil.length:.3f} A/R = {unit}"


def _run_far(args, cfg) -> int:
    """``--far``: the bifurcation diagram (:func:`flagwrap.stability.bifurcation.
    bifurcation_diagram`), printed, optionally plotted and as JSON."""
    import json
    import sys

    from flagwrap.stability.bifurcation import FarStateNotFound, bifurcation_diagram

    progress = not (args.json or args.no_progress)

    def say(line):
        if progress:
            print(f"  {line}", file=sys.stderr, flush=True)

    if progress:
        print(f"flagwrap stability {cfg.name} --far: the whirl's threshold, then a far state "
              f"from the time domain followed down to its fold (about a minute for the paper's "
              f"helix)", file=sys.stderr, flush=True)
    try:
        d = bifurcation_diagram(cfg, args.direction, m_far=args.m_far, m_lo=args.m_lo,
                                m_hi=args.m_hi, settle=args.settle, cycles=_cycles(args.cycles),
                                far_from=args.far_from, m_start=args.m_start, on_progress=say)
    except FarStateNotFound as exc:
        d = getattr(exc, "diagram", None)
        if args.json:
            from flagwrap.sweep.store import jsonable

            s = d.summary() if d is not None else {}
            s.update(found=False, message=str(exc), config=str(args.config))
            print(json.dumps(jsonable(s), sort_keys=True, allow_nan=False))
            return 1
        print(f"NOT FOUND: {exc}")
        if d is not None and d.hopf is not None and d.hopf.converged:
            print(f"(the whirl: {d.hopf.crossing} at M = {d.machin_hopf:.2f}; try another "
                  f"--m-far or --far-from a run that ended buckled)")
        return 1
    s = d.summary()
    s.update(config=str(args.config), hydrodynamics=cfg.numerics.hydrodynamics,
             machin_critical_scaling=cfg.machin_critical_scaling)
    fil = cfg.filament
    tq = d.torques()
    for k, v in tq.items():
        s[f"torque_{k}_reduced"] = v * fil.helix_radius / fil.length
        s[f"torque_{k}"] = v * fil.bending_modulus / fil.length
    files = []
    if args.diagram:
        from flagwrap.plotting.stability import plot_bifurcation

        files.append(str(plot_bifurcation(d, cfg, args.diagram)))
    s["files"] = files
    if args.json:
        from flagwrap.sweep.store import jsonable

        print(json.dumps(jsonable(s), sort_keys=True, allow_nan=False))
        return 0 if d.fold_found else 1
    line = cfg.machin_critical_scaling
    print(f"{args.config}: steady states of the {args.direction.upper()} motor in the turning "
          f"frame (HI {'on' if cfg.numerics.hydrodynamics else 'off'}), {d.wall_time:.1f} s")
    kind = {"hopf": "Hopf", "fold": "fold"}.get(d.hopf.crossing, "steady crossing")
    print(f"{'M_Hopf ' if kind == 'Hopf' else 'M_c    '} = {d.machin_hopf:.2f}  (the whirl's {kind}; {d.machin_hopf / line:.2f}x "
          f"the paper's line {line:.0f})" + (f"; whirl torque {_torque_text(cfg, tq['hopf'])}"
                                             if "hopf" in tq else ""))
    print(f"far state: from {d.far_source}; {len(d.far)} states by relaxation, "
          f"{len(d.saddle)} by arclength")
    if d.fold_found:
        a, b = d.fold_eigenvalues
        print(f"M_f     = {d.machin_fold:.2f}  (the far state's fold; "
              f"{d.machin_fold / d.machin_hopf:.3f} of the whirl's, {d.machin_fold / line:.2f}x the "
              f"line; a real eigenvalue {a:+.3g} -> {b:+.3g} omega across it)"
              + (f"; far-state torque {_torque_text(cfg, tq['fold'])}" if "fold" in tq else ""))
        print("between M_f and the whirl's threshold both states are stable: which one "
              "a run ends in depends on how hard the reversal kicks it")
    if d.message:
        print(f"note: {d.message}")
    for c in d.cycles:
        print(f"Hopf cycle at M = {c.machin:.1f} ({c.machin / d.machin_hopf:.3f} M_Hopf): "
              f"{c.amplitude:.3f} L from the whirl, free end {c.tip_min - d.tip_z0:+.3f} .. "
              f"{c.tip_max - d.tip_z0:+.3f} L" + (" (left for the far state)" if c.far else ""))
    for f_ in files:
        print(f"wrote {f_}")
    return 0 if d.fold_found else 1

