"""Detect buckling, waiting time t_c and final state of run files; store them as attributes.

Prints a summary per run file and writes the results into it (attributes ``analysis_*``,
variables ``free_end_height``, ``winding_turns``, ``contact_fraction``, ``perversion_bead``;
the file is rewritten in place, atomically, and the output's last line per run says so)
unless ``--no-store`` (or its older name ``--no-write``). Criteria and defaults:
docs/analysis.md. A free swimmer's filament is analysed in its body's frame, and its swimming
is reported per motor phase (:mod:`flagwrap.observables.swimming`).

Examples::

    flagwrap analyze out/k600.nc
    flagwrap analyze out/*.nc --json --no-store
"""

from __future__ import annotations


def add_arguments(p):
    p.add_argument("runs", nargs="+", metavar="RUN.nc", help="run file(s) written by `flagwrap run`")
    p.add_argument("--json", action="store_true", help="print one JSON object per run instead of a table")
    p.add_argument("--no-store", "--no-write", dest="no_write", action="store_true",
                   help="leave the run file untouched (by default the results are stored in it: "
                        "attributes analysis_* and per-frame variables, the file rewritten in place)")
    p.add_argument("--figure", metavar="PNG", help="a free swimmer's run: draw its displacement, "
                   "motor and body rates and free-end height against time (one run only)")
    g = p.add_argument_group("criteria (defaults: docs/analysis.md)")
    g.add_argument("--threshold", type=float, default=0.15, help="buckling rise of the free end [L] (0.15)")
    g.add_argument("--hold-turns", type=float, default=1.0, help="rise must persist [turns] (1)")
    g.add_argument("--smooth-turns", type=float, default=1.0, help="running-mean window [turns] (1)")
    g.add_argument("--onset", choices=["hinge", "crossing"], default="hinge", help="t_c rule (hinge)")
    g.add_argument("--min-winding", type=float, default=0.5, help="wrapping: winding [turns] (0.5)")
    g.add_argument("--min-contact-fraction", type=float, default=0.3, help="wrapping: beads beside body (0.3)")
    g.add_argument("--contact-distance", type=float, default=0.5, help="beside body: distance [R_cell] (0.5)")
    g.add_argument("--final-turns", type=float, default=1.0, help="final-state window [turns] (1)")


ROWS = [
    ("state", "final state", "{}"),
    ("buckled", "buckled", "{}"),
    ("sustained", "rise lasts to the end", "{}"),
    ("switch_turns", "CCW->CW switch t_s/T", "{:.3f}"),
    ("waiting_time_turns", "waiting time t_c/T", "{:.3f}"),
    ("crossing_turns", "threshold crossing (t-t_s)/T", "{:.3f}"),
    ("perversion_turns", "first perversion (t-t_s)/T", "{:.3f}"),
    ("baseline_height", "baseline (z(L)-z(0))/L", "{:+.4f}"),
    ("max_height", "max height after switch", "{:+.4f}"),
    ("final_height", "final height", "{:+.4f}"),
    ("winding_turns", "final winding [turns]", "{:.3f}"),
    ("contact_fraction", "final beside-body fraction", "{:.3f}"),
    ("torque_peak_reduced", "CW torque peak N_m R/A", "{:+.3f}"),
    ("torque_peak_turns", "  at (t-t_s)/T", "{:.3f}"),
    ("torque_final_reduced", "final torque N_m R/A", "{:+.3f}"),
    ("joint", "joint", "{}"),
    ("hook_angle_final_deg", "joint angle final [deg]", "{:.2f}"),
    ("hook_angle_max_deg", "joint angle max [deg]", "{:.2f}"),
    ("hook_torque_max", "joint bending torque max [N m]", "{:.3g}"),
    ("hook_twist_torque_max", "joint twist torque max [N m]", "{:.3g}"),
]


def run(args) -> int:
    import json
    import math
    import sys

    from flagwrap.analysis.buckling import BucklingAnalysis, FinalState, WaitingTime
    from flagwrap.analysis.runfile_attrs import analyze_run_file, jsonable

    figure = None
    if args.figure is not None:
        from flagwrap.errors import UserInputError
        from flagwrap.io.outputs import check_output_file

        if len(args.runs) != 1:
            raise UserInputError(f"--figure draws one run; got {len(args.runs)}")
        figure = check_output_file(args.figure, "--figure", suffixes=(".png", ".pdf"))
    from flagwrap.errors import UserInputError

    try:  # checked once, before any file is read; the message names the option as typed
        analysis = BucklingAnalysis(
            WaitingTime(threshold=args.threshold, hold_turns=args.hold_turns,
                        smooth_turns=args.smooth_turns, onset=args.onset),
            FinalState(min_winding_turns=args.min_winding,
                       min_contact_fraction=args.min_contact_fraction,
                       contact_distance=args.contact_distance, final_turns=args.final_turns),
        )
    except UserInputError as exc:
        msg = str(exc)
        for name, opt in (("min_winding_turns", "--min-winding"), ("threshold", "--threshold"),
                          ("hold_turns", "--hold-turns"), ("smooth_turns", "--smooth-turns"),
                          ("min_contact_fraction", "--min-contact-fraction"),
                          ("contact_distance", "--contact-distance"), ("final_turns", "--final-turns")):
            if msg.startswith(name + " "):
                msg = opt + msg[len(name):]
        raise UserInputError(msg) from None
    for path in args.runs:
        if figure is not None:  # refused before anything is written
            from flagwrap.io.runfile import read_run

            if "body_position" not in read_run(path).variables:
                raise UserInputError(f"--figure needs a free swimmer's run (body.motion = 'free'); "
                                     f"{path} has a fixed body")
        res = analyze_run_file(path, analysis, write=not args.no_write)
        if figure is not None:
            from flagwrap.plotting.swimming import plot_swimming

            plot_swimming(read_run(path), figure)
        if args.json:
            print(json.dumps(jsonable(res), sort_keys=True))
            if not args.no_write:  # stdout stays one JSON object per run
                print(stored_line(path), file=sys.stderr)
            continue
        print(f"{path} (run status: {res['run_status']})")
        for key, label, fmt in ROWS:
            v = res[key]
            print(f"  {label:<30s} {fmt.format(v) if not (isinstance(v, float) and v != v) else '-'}")
        if "filaments" in res:  # several flagella: each, and the bundle they make
            which = "the first to buckle" if res["n_buckled"] else "none buckled"
            print(f"  (the rows above: flagellum {res['filament']}, {which}; "
                  f"{res['n_buckled']} of {len(res['filaments'])} buckled)")
            for k, f in enumerate(res["filaments"]):
                tc = f["waiting_time_turns"]
                print(f"  flagellum {k}: {f['state']}, buckled {f['buckled']}, t_c/T "
                      f"{'-' if tc != tc else format(tc, '.3f')}, final height "
                      f"{f['final_height']:+.4f}, winding {f['winding_turns']:.3f} turns"
                      + ("" if f.get("motor_reversed", True) else
                         " (its motor never reversed: read against the run's reversal)"))
            b = res["bundle"]
            lags = ", ".join(f"{math.degrees(v):+.0f}" for v in b["phase_lag"])
            print(f"  bundle (final turns): separation {b['separation']:.3f} R "
                  f"({'bundled' if b['bundled'] else 'not bundled'}: < 1 R), phase lags "
                  f"to flagellum 0 [deg] {lags}; segments passed through each other: "
                  f"{b['crossings']}")
        if res["buckled"] and not res["sustained"]:
            rise = res["final_height"] - res["baseline_height"]
            print(f"  note: the rise did not last: over the final {args.final_turns:g} turn(s) the "
                  f"free end is {rise:+.3f} L from its CCW baseline, under the {args.threshold:g} L "
                  "threshold (a transient, or a decaying wobble on a soft hook); 'buckled' is the "
                  "paper's rule (docs/analysis.md)")
        if res.get("wall"):
            for line in boundary_lines(res["wall"]):
                print("  " + line)
        if res.get("polymorph"):
            pm = res["polymorph"]
            many = res.get("polymorph_filaments") or [pm]
            for k, p in enumerate(many):
                print("  " + (f"flagellum {k}: " if len(many) > 1 else "") + polymorph_line(p))
            if any(p["fraction_b_max"] > 0 for p in many) and res.get("buckled"):
                print(f"  note: the filament changed form; a helix of form {pm['polymorph_a']} hangs "
                      f"to a height {pm['height_a']:+.3f}, of {pm['polymorph_b']} to "
                      f"{pm['height_b']:+.3f}: the free end's rise, and so 'buckled', includes "
                      "the change of form")
        for ph in res["swimming"]:  # a free swimmer, phase by phase (second half of each)
            what = "last turns" if ph["direction"] == "final" else f"{ph['direction']} phase"
            print(f"  swimming, {what} ({ph['t0']:.3g}-{ph['t1']:.3g} s): "
                  f"speed {ph['speed'] * 1e6:+.4g} um/s (+ body first; "
                  f"{ph['screw_speed'] * 1e6:+.4g} along the path's screw axis), body rotation "
                  f"{ph['body_rotation_hz']:+.4g} Hz, motor {ph['motor_rate_hz']:+.4g} Hz, "
                  f"{ph['displacement_per_turn'] * 1e9:+.4g} nm per motor turn, motor power "
                  f"{ph['motor_power']:.4g} W, Lighthill efficiency "
                  f"{ph['efficiency'] * 100:.3g} %")
        print(f"  not stored (--no-store): {path} unchanged" if args.no_write
              else f"  {stored_line(path)}")
    return 0


def boundary_lines(w: dict) -> list[str]:
    """The wall's or tube's lines (:func:`flagwrap.observables.wall.wall_summary`)."""
    where = (f"free end {w['tip_height_final']:.3g} m above it" if w["boundary"] == "wall" else
             f"free end {w['tip_axis_distance_final']:.3g} m from its axis")
    out = [f"{w['boundary']}: closest bead surface {w['gap_min']:+.3g} m from it (at turn "
           f"{w['gap_min_turns']:.2f}), {w['gap_final']:+.3g} m at the end; {where}"]
    if "body_height_final" in w:
        out.append(f"{w['boundary']}: body centre {w['body_height_final']:.3g} m above it at the "
                   f"end (closest {w['body_height_min']:.3g} m), axis {w['body_tilt_final_deg']:+.1f} "
                   f"deg to its plane; last turns: {w['speed_parallel'] * 1e6:.4g} um/s along it, "
                   f"{w['speed_normal'] * 1e6:+.3g} um/s away from it")
    if "body_axis_distance_final" in w:
        out.append(f"tube: body centre {w['body_axis_distance_final']:.3g} m from its axis at "
                   f"the end (farthest {w['body_axis_distance_max']:.3g} m), body axis "
                   f"{w['body_tilt_final_deg']:.1f} deg to the tube's; last turns: "
                   f"{w['speed_along'] * 1e6:+.4g} um/s along it, {w['speed_radial'] * 1e6:+.3g} "
                   "um/s away from its axis")
    return out


def polymorph_line(p: dict) -> str:
    """The polymorph state's one line (:func:`flagwrap.observables.polymorph.polymorph_summary`)."""
    head = (f"polymorph {p['polymorph_a']} -> {p['polymorph_b']}: fraction in "
            f"{p['polymorph_b']} {p['fraction_b_final']:.3f} at the end (max {p['fraction_b_max']:.3f})")
    if p["start_turns"] is None:
        return head + f"; never entered {p['polymorph_b']}"
    front = ("no moving front" if p["front_speed_m_s"] is None
             else f"front {p['front_speed_m_s'] * 1e6:+.3g} um/s")
    if p["start_position_m"] is None:  # the initial state already held B
        return head + f"; {p['polymorph_b']} present from the start, {front}"
    return (head + f"; began at turn {p['start_turns']:.2f} ({p['start_time_s']:.3g} s), "
            f"{p['start_position_m'] * 1e6:.3g} um from the filament's first bead (the "
            f"{p['starts_at']}), {front}")


def stored_line(path) -> str:
    """The one line that says the run file was rewritten."""
    return (f"summary stored in {path} (attributes analysis_*, variables free_end_height, "
            "winding_turns, contact_fraction, perversion_bead; rewritten in place, --no-store "
            "leaves it untouched)")
