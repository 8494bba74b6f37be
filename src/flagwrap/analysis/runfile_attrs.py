"""Analyse a run file and store the results in it (``flagwrap analyze``).

Scalars go to global attributes prefixed ``analysis_`` (netCDF attributes cannot be None or
bool: undefined values are NaN, flags are 0/1); the criteria used go to
``analysis_params`` (JSON). Per-frame series go to small variables:

==========================  ======  =====================================================
variable                    dims    meaning
==========================  ======  =====================================================
free_end_height             time    ``(z(L) - z(0)) / L``
free_end_height_smoothed    time    running mean used by the onset detector
winding_turns               time    ``|W| / 2 pi`` of the beads beside the body [turns]
contact_fraction            time    fraction of beads beside the body
perversion_bead             time    bead of the perversion nearest the clamp, -1 if none
==========================  ======  =====================================================

Re-running replaces earlier results. The file is rewritten atomically: written to a
temporary file in the same folder, flushed, fsynced, then renamed over the original, so an
interrupted analysis never damages the run.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from flagwrap.analysis.buckling import BucklingAnalysis
from flagwrap.errors import UserInputError

PREFIX = "analysis_"
VARIABLES = ("free_end_height", "free_end_height_smoothed", "winding_turns", "contact_fraction",
             "perversion_bead")


def analyze_dataset(ds, analysis: BucklingAnalysis | None = None,
                    filament: int = 0) -> BucklingAnalysis:
    """Run :class:`BucklingAnalysis` on a run dataset (:func:`flagwrap.io.runfile.read_run`),
    on its flagellum ``filament`` (a run of several: :func:`~flagwrap.io.runfile.
    filament_slices`), with its own motor's torque and rate (``motor_torques``,
    ``motor_rates``; a file without them: the run's, all motors' sum, and motor 0's rate)."""
    from flagwrap.io.runfile import config_of, filament_slices

    need = ("position", "turns", "omega")
    missing = [v for v in need if v not in ds.variables]
    if missing or "length" not in ds.attrs:
        raise UserInputError(f"run dataset lacks {missing or ['length attribute']}")
    cfg = config_of(ds)
    R = cfg.filament.helix_radius
    if not cfg.body.enabled:
        raise UserInputError("run has no cell body (body.enabled = false): nothing to wrap around")
    if ds.sizes.get("time", 0) < 2:
        raise UserInputError("run file has fewer than 2 saved frames")
    a = analysis if analysis is not None else BucklingAnalysis()
    from flagwrap.geometry.helix import held_beads

    # the beads the motor holds (a connector's arm: at the pole) are not the filament's
    a.final.first_bead = max(a.final.first_bead, held_beads(cfg.filament, cfg.clamp))
    tq = ds["motor_torque_reduced"].values if "motor_torque_reduced" in ds.variables else None
    if "motor_torques" in ds.variables:  # several flagella: this one's motor
        tq = ds["motor_torques"].values[:, filament] * R / cfg.filament.bending_modulus
    x = ds["position"].values
    if "body_position" in ds.variables:  # a free swimmer: the filament seen from its body
        from flagwrap.observables.swimming import body_frame

        x = body_frame(x, ds["body_position"].values, ds["body_orientation"].values)
    x = x[:, filament_slices(ds)[filament]]
    # several flagella: this one's own motor rate (its protocol, its load); a motor that
    # never reverses ([[flagellum]] protocol) is read against the run's reversal: its state
    # after the others reversed, flagged motor_reversed = False
    om = ds["omega"].values
    a.motor_reversed = True
    if "motor_rates" in ds.variables:
        own = ds["motor_rates"].values[:, filament]
        if (own < 0).any() or not (om < 0).any():
            om = own
        else:
            a.motor_reversed = False
    if ds.attrs.get("status") == "failed" and not (om < 0).any():
        # a partial file (Ctrl-C, SIGTERM, a failure) that stopped before the reversal
        raise UserInputError(
            f"this is a partial run ({ds.attrs.get('message', 'stopped early')}) that ended "
            f"in the CCW phase, at turn {float(ds['turns'].values[-1]):.3g}: there is no CW "
            "phase to analyse yet (`flagwrap run ... --resume` continues it)")
    return a.compute(ds["turns"].values, x, om,
                     float(ds.attrs["length"]), cfg.body.resolved_radius(R),
                     cfg.body.resolved_length(R), tq, body_shape=cfg.body.shape)


def joint_summary(ds) -> dict:
    """The joint's observables (issue 15): its kind, the angle between the motor's bond and the
    filament's first bond at the end and its largest value [deg], and the largest bending and
    twist torques at the joint [N m] (NaN for run files written before they were recorded)."""
    nan = float("nan")
    out = {"joint": str(ds.attrs.get("joint", "clamp")), "hook_angle_final_deg": nan,
           "hook_angle_max_deg": nan, "hook_torque_max": nan, "hook_twist_torque_max": nan}
    if "hook_angle" in ds.variables and ds.sizes.get("time", 0):
        ang = np.degrees(ds["hook_angle"].values)
        out["hook_angle_final_deg"] = float(ang[-1])
        out["hook_angle_max_deg"] = float(ang.max())
        out["hook_torque_max"] = float(np.abs(ds["hook_torque"].values).max())
        out["hook_twist_torque_max"] = float(np.abs(ds["hook_twist_torque"].values).max())
    return out


def annotate(ds, analysis, bundle: dict | None = None):
    """Return a copy of ``ds`` with the results of a computed ``analysis`` stored in it; a
    run of several flagella: ``analysis`` one per flagellum (the series get a ``filament``
    dimension, the attributes are the first to buckle's, :func:`combined_summary`, with every
    flagellum's in ``analysis_filaments`` as JSON) and ``bundle`` (:func:`flagwrap.
    observables.bundle.bundle_summary`)."""
    many = isinstance(analysis, (list, tuple))
    each = list(analysis) if many else [analysis]
    out = ds.drop_vars([v for v in VARIABLES + ("bundle_separation", "bundle_phase_lag")
                        if v in ds.variables])
    out.attrs = {k: v for k, v in ds.attrs.items() if not k.startswith(PREFIX)}
    summary = combined_summary(each) if many else each[0].summary()
    for k, v in {**summary, **joint_summary(ds)}.items():
        if isinstance(v, bool):
            v = int(v)
        out.attrs[PREFIX + k] = v
    out.attrs[PREFIX + "params"] = json.dumps(each[0].params(), sort_keys=True)
    if many:
        from flagwrap.sweep.store import jsonable as _jsonable

        out.attrs[PREFIX + "filaments"] = json.dumps(_jsonable([flagellum_summary(a)
                                                                 for a in each]))
    from flagwrap import __version__

    out.attrs[PREFIX + "version"] = __version__
    dims = ("filament", "time") if many else ("time",)

    def series(get):
        v = [np.asarray(get(a)) for a in each]
        return np.stack(v) if many else v[0]

    out["free_end_height"] = (dims, series(lambda a: a.height),
                              {"units": "1", "long_name": "(z(L)-z(0))/L"})
    out["free_end_height_smoothed"] = (dims, series(lambda a: a.waiting.smoothed), {"units": "1"})
    out["winding_turns"] = (dims, series(lambda a: a.final.winding_series),
                            {"units": "1", "long_name": "|winding| of beads beside the body [turns]"})
    out["contact_fraction"] = (dims, series(lambda a: a.final.contact_series), {"units": "1"})
    out["perversion_bead"] = (dims, series(lambda a: a.perversion_bead.astype(np.int32)),
                              {"units": "1", "long_name": "perversion bead nearest the clamp (-1 none)"})
    if bundle is not None:
        out["bundle_separation"] = ("time", bundle["separation_series"],
                                    {"units": "1", "long_name": "distal centroid separation / R"})
        out["bundle_phase_lag"] = (("time", "filament"), bundle["phase_lag_series"],
                                   {"units": "rad", "long_name": "free-end phase minus flagellum 0's"})
        for k in ("separation", "bundled", "crossings"):
            if k in bundle:
                out.attrs[PREFIX + "bundle_" + k] = (int(bundle[k]) if k != "separation"
                                                     else bundle[k])
    return out


def flagellum_summary(a) -> dict:
    """One flagellum's :meth:`BucklingAnalysis.summary` and whether its own motor reversed
    (:func:`analyze_dataset`)."""
    return {**a.summary(), "motor_reversed": bool(getattr(a, "motor_reversed", True))}


def combined_summary(analyses) -> dict:
    """A run of several flagella as one verdict: the summary of the first flagellum to buckle
    (earliest threshold crossing; flagellum 0 if none does), with ``filament`` its index and
    ``n_buckled`` how many buckled. Critical-M searches and sweeps read this."""
    sums = [flagellum_summary(a) for a in analyses]
    buckled = [k for k, s in enumerate(sums) if s["buckled"]]
    first = min(buckled, key=lambda k: sums[k]["crossing_turns"]) if buckled else 0
    return {**sums[first], "filament": first, "n_buckled": len(buckled)}


def analyze_run_file(path, analysis: BucklingAnalysis | None = None, write: bool = True) -> dict:
    """Analyse the run file ``path``; store the results in it unless ``write`` is false.

    Returns
    -------
    dict
        :meth:`BucklingAnalysis.summary` plus ``params`` (the criteria) and ``path``.

    Raises
    ------
    UserInputError
        unreadable file, no CW phase, no cell body, too few frames.
    """
    from flagwrap.io.runfile import read_run, write_dataset_atomic

    from flagwrap.io.runfile import filament_slices

    path = Path(path)
    ds = read_run(path)
    slices = filament_slices(ds)
    if len(slices) == 1:
        a = analyze_dataset(ds, analysis)
        if write:
            write_dataset_atomic(annotate(ds, a), path)
        res = {**a.summary(), **joint_summary(ds)}
    else:
        res = _analyze_flagella(ds, analysis, slices, path, write)
        a = res.pop("_first")
    from flagwrap.observables.swimming import swimming_summary

    res["swimming"] = swimming_summary(ds, final_turns=a.final.final_turns)
    from flagwrap.observables.wall import wall_summary

    wall = wall_summary(ds, final_turns=a.final.final_turns)
    res["wall"] = None if wall is None else {k: v for k, v in wall.items()
                                             if k not in ("gap_series", "body_height",
                                                          "body_axis_distance")}
    from flagwrap.observables.polymorph import polymorph_summaries

    poly = polymorph_summaries(ds)  # one per flagellum
    poly = None if poly is None else [{k: v for k, v in p.items() if k != "fraction_series"}
                                      for p in poly]
    res["polymorph"] = None if poly is None else poly[0]
    res["polymorph_filaments"] = poly if poly is not None and len(poly) > 1 else None
    res["params"] = a.params()
    res["path"] = str(path)
    res["run_status"] = str(ds.attrs.get("status", ""))
    return res


def _analyze_flagella(ds, analysis, slices, path, write: bool) -> dict:
    """Every flagellum of a run of several, and the bundle they make (module docstring of
    :mod:`flagwrap.observables.bundle`)."""
    import copy

    from flagwrap.io.runfile import config_of, write_dataset_atomic
    from flagwrap.observables.bundle import bundle_summary, last_turn

    base = analysis if analysis is not None else BucklingAnalysis()
    each = [analyze_dataset(ds, copy.deepcopy(base), k) for k in range(len(slices))]
    x = ds["position"].values
    if "body_position" in ds.variables:
        from flagwrap.observables.swimming import body_frame

        x = body_frame(x, ds["body_position"].values, ds["body_orientation"].values)
    cfg = config_of(ds)
    fil = cfg.filament
    bundle = bundle_summary(ds["turns"].values, x, slices, fil.helix_radius,
                            final_turns=base.final.final_turns,
                            distal=last_turn(fil.helix_radius, fil.pitch, fil.length))
    from flagwrap.interactions.self_contact import count_crossings

    # segments passing through each other between saved frames, within and between flagella
    bundle["crossings"] = count_crossings(x, chains=[s.stop - s.start for s in slices])
    if write:
        write_dataset_atomic(annotate(ds, each, bundle), path)
    res = {**combined_summary(each), **joint_summary(ds)}
    res["filaments"] = [flagellum_summary(a) for a in each]
    res["bundle"] = {k: v for k, v in bundle.items() if not k.endswith("_series")}
    res["_first"] = each[res["filament"]]
    return res


def jsonable(res):
    """NaN -> None at every depth, so that the result is valid JSON (the sweep store's)."""
    from flagwrap.sweep.store import jsonable as _jsonable

    return _jsonable(res)
