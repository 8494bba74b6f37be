"""The free swimmer stepped in its motor's frame (flagwrap.system.swimmer.SwimmerRotating):
the same physics as the body frame's SwimmerSystem, state by state and run against run, and
the cases it cannot treat refused by name."""

import dataclasses

import numpy as np
import pytest

from conftest import NO_SLIP_BODY, tiny_toml
from flagwrap.io.config import config_from_dict, tomllib
from flagwrap.simulation import make_system, simulate
from flagwrap.system.swimmer import SwimmerRotating, SwimmerSystem

TORQUE_SPEED = "[motor]\nkind = 'torque-speed'\nstall_torque = 2e-3\nzero_load_speed = 40.0\n"


def _cfg(frame="lab", motor="", extra="", tol=1e-3, **kw):
    text = tiny_toml(**kw).replace("[numerics]\n", f"[numerics]\nframe = '{frame}'\n"
                                   f"tol = {tol}\n", 1).replace("tol = 1e-3\n", "", 1)
    if motor:  # a torque-speed motor: its reference turn set by frequency, not machin
        text = text.replace("[motor]\nmachin = 100\n", motor + "frequency = 10.0\n")
    return config_from_dict(tomllib.loads(text + NO_SLIP_BODY + "motion = 'free'\n" + extra))


#: a tube about the cell and a tilted wall beside it, each within the contact range of the
#: filament once the body is shifted 0.018 L along x (:func:`_state`'s ``shift``)
BOUNDARIES = {
    "tube": "[[tube]]\nradius = 0.07\nlength = 0.7\ncenter = [0.0, 0.0, -0.1]\n"
            "blob_spacing = 0.035\n",
    "tilted wall": "[[wall]]\npoint = [0.0715, 0.0, 0.0]\nnormal = [-1.0, 0.0, 0.02]\n",
}


def _state(rng, motor="", extra="", shift=0.0):
    """A body-frame swimmer's loaded state (beads and twists perturbed, the motor turned
    0.7 rad, the body shifted ``shift`` along x and turned 0.05 rad about z) and the same
    state in the turning frame."""
    body = make_system(_cfg("lab", motor, extra))
    turning = make_system(_cfg("rotating", motor, extra))
    assert type(body) is SwimmerSystem and type(turning) is SwimmerRotating
    y = body.initial_y()
    y[body.sl_x] += 0.01 * body.bond * rng.standard_normal(body.sl_x.stop - body.sl_x.start)
    y[body.sl_th] += 0.1 * rng.standard_normal(body.sl_th.stop - body.sl_th.start)
    y[body.i_phi] = 0.7
    y[body.sl_X] = [shift, 0.0, 0.0]
    y[body.sl_q] = [np.cos(0.025), 0.0, 0.0, np.sin(0.025)]
    info = body.forces(y, body.frames0)
    yr, base = turning.from_body_frame(y, info.frames)
    return body, y, info, turning, yr, turning.forces(yr, base)


@pytest.mark.parametrize("motor, boundary", [
    ("", None), (TORQUE_SPEED, None), ("", "tube"), ("", "tilted wall"),
    (TORQUE_SPEED, "tube")],
    ids=["speed motor", "torque-speed motor", "tube", "tilted wall", "torque-speed in a tube"])
def test_velocity_is_the_body_frames_turned(rng, motor, boundary):
    """At one physical state the turning frame's rates, turned back and with the frame's own
    rotation added, are the body frame's: beads, twists, motor rate and pose to 1e-9 of
    their scale (the rotation covariance of the blob mobility is exact, not the held shell
    of linear stability); the energy is the same. Beside a boundary the filament touches
    it (its contact placed in each frame at the state's own pose)."""
    extra = BOUNDARIES.get(boundary, "")
    body, y, info, s, yr, ir = _state(rng, motor, extra, 0.018 if boundary else 0.0)
    assert ir.elastic_energy == pytest.approx(info.elastic_energy, rel=1e-12)
    if boundary:
        assert info.interaction_energy > 0
        assert ir.interaction_energy == pytest.approx(info.interaction_energy, rel=1e-10)
    f = body.velocity(y, info, 1.0)
    g = s.velocity(yr, ir, 1.0)
    w = g[s.i_phi]
    assert w == pytest.approx(f[body.i_phi], rel=1e-12)
    if motor:
        assert abs(w - 1.0) > 1e-3  # the torque-speed motor's own rate
    R = s._turn(yr)
    v = (g[s.sl_x].reshape(-1, 3) + w * np.cross(s.axis, ir.x[s.nc:])) @ R.T
    vb = f[body.sl_x].reshape(-1, 3)
    assert np.abs(v - vb).max() < 1e-9 * np.abs(vb).max()
    twist = g[s.sl_th] + w * (ir.frames.t[s.ec:] @ s.axis)
    assert np.abs(twist - f[body.sl_th]).max() < 1e-9 * np.abs(f[body.sl_th]).max()
    pose = slice(body.n_in, body.ny)
    assert np.abs(g[pose] - f[pose]).max() < 1e-9 * np.abs(f[pose]).max()


def test_from_body_frame_keeps_positions_and_material_frames(rng):
    """The converted state is the same filament: lab positions ``R x''`` and material
    vectors ``R m1''`` (reference frames turned about their tangents, twists less ``phi``)."""
    from flagwrap.elasticity import _kernels as EK

    body, y, info, s, yr, ir = _state(rng)
    R = s._turn(yr)
    assert np.abs(ir.x @ R.T - info.x).max() < 1e-14

    def m1(frames, theta):
        out1, out2 = np.empty_like(frames.t), np.empty_like(frames.t)
        EK.material_frames(frames.t, frames.d1, theta, out1, out2)
        return out1

    assert np.abs(m1(ir.frames, ir.theta) @ R.T - m1(info.frames, info.theta)).max() < 1e-12


@pytest.mark.parametrize("motor", ["", TORQUE_SPEED], ids=["speed motor", "torque-speed motor"])
def test_runs_in_both_frames_converge_to_one_answer(motor):
    """The same free cell run 0.2 turn CCW and 0.1 CW in both frames from rest: the run
    files' (lab frame) beads, body pose and motor angle differ by the two runs' own errors,
    which fall with the tolerance (measured 2.4e-5 L at tol 1e-6, 8.3e-7 L at 1e-8, the
    speed motor; 1.6e-5 and 2.7e-7 L with the torque-speed one): at 1e-8 the frames agree
    to 2e-6 L and at least 10x better than at 1e-6."""

    def gap(tol):
        a, b = [simulate(_cfg(frame, motor, tol=tol, ccw=0.2, cw=0.1))
                for frame in ("lab", "rotating")]
        assert a.status == b.status == "completed"
        return max(np.abs(np.asarray(a.x[-1]) - np.asarray(b.x[-1])).max(),
                   np.abs(np.asarray(a.body[-1])[:7] - np.asarray(b.body[-1])[:7]).max(),
                   abs(a.phi[-1] - b.phi[-1]))

    loose, tight = gap(1e-6), gap(1e-8)
    assert tight < 2e-6 and tight < 0.1 * loose


@pytest.mark.parametrize("extra, key", [
    ("".join(f"[[flagellum]]\npolar_deg = 30\nazimuth_deg = {az}\n" for az in (0, 180)),
     "[[flagellum]]"),
])
def test_what_the_turning_frame_cannot_treat_is_refused_by_name(tmp_path, capsys, extra, key):
    """A free cell with flagella off the axis: one line naming the key and the lab frame,
    exit 2, before any work."""
    from flagwrap.cli.main import main

    cfg = tmp_path / "c.toml"
    text = tiny_toml().replace("[numerics]\n", "[numerics]\nframe = 'rotating'\n", 1)
    cfg.write_text(text + NO_SLIP_BODY + "motion = 'free'\n" + extra)
    out = tmp_path / "r.nc"
    assert main(["run", str(cfg), "-o", str(out), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert key in err and "numerics.frame = 'lab'" in err and err.count("\n") == 1
    assert not out.exists()


def test_stage_solver_carries_the_frames_turn_at_the_motors_load(rng):
    """With a torque motor the frame turns at the motor's rate ``w(y)``, so each rate's
    frame term ``-w c`` (``c = a x x''``, ``a . t``) moves with the load: ``W^T`` gains
    ``gamma h (dw/dy) c^T``. Checked against ``c`` from the velocity's own frame term
    (:func:`~flagwrap.system.rotating.subtract_rotation`) and ``dw/dy`` by central
    differences of the motor's rate, to 1e-7 (the differences' error)."""
    from flagwrap.system.rotating import subtract_rotation

    _, _, _, s, y, info = _state(rng, TORQUE_SPEED)
    n, i, gh, h = s.n_in, s.i_phi, 0.3, 1e-6
    dw = np.empty(n)
    for k in range(n):
        yp, ym = y.copy(), y.copy()
        yp[k] += h
        ym[k] -= h
        dw[k] = (s.motor_rate(yp, s.forces(yp, info.frames), 1.0)
                 - s.motor_rate(ym, s.forces(ym, info.frames), 1.0)) / (2 * h)
    assert abs(dw[i]) < 1e-9 * np.abs(dw).max()  # no force depends on the motor angle here
    minus_c = np.zeros(s.ny)
    subtract_rotation(minus_c, s, info, 1.0, s.axis, s._A)
    WT = np.eye(n)
    WT[:, i] -= gh * dw
    before = WT.copy()
    s.frame_rows(WT, y[:n])
    expect = gh * np.outer(dw, -minus_c[:i])
    assert np.abs((WT - before)[:, :i] - expect).max() < 1e-7 * np.abs(expect).max()
    assert np.array_equal(WT[:, i:], before[:, i:])


# --- the matrix-free stage solver (SwimmerKrylovW) on every kind of free cell ---------------

FREE_KINDS = ("free cell", "free cell, turning frame", "two flagella on a free cell")


def _kind_cfg(kind, solver, tol=1e-7, **kw):
    from conftest import system_kinds

    num, tables = system_kinds()[kind]
    text = tiny_toml(**kw).replace("[numerics]\n", f"[numerics]\n{num}linear_solver = "
                                   f"'{solver}'\n").replace("tol = 1e-3", f"tol = {tol}")
    return config_from_dict(tomllib.loads(text + tables))


@pytest.mark.parametrize("kind", FREE_KINDS)
def test_krylov_stage_solver_runs_as_the_dense_one(kind):
    """``numerics.linear_solver = "krylov"`` on a free cell: a W-method with another W, so
    the run takes about the dense one's steps (within 5 %) and lands within both runs' own
    error of it at tol 1e-7 (measured 4.5e-7, 2.2e-6 and 8.0e-7 L apart; 1e-5 allows 4x)."""
    from flagwrap.system.swimmer import SwimmerKrylovW

    a, b = [simulate(_kind_cfg(kind, solver, ccw=0.2, cw=0.1)) for solver in ("dense", "krylov")]
    assert a.status == b.status == "completed"
    assert abs(b.n_steps / a.n_steps - 1.0) < 0.05
    assert np.abs(np.asarray(a.x[-1]) - np.asarray(b.x[-1])).max() < 1e-5
    assert np.abs(np.asarray(a.body[-1])[:7] - np.asarray(b.body[-1])[:7]).max() < 1e-5
    s = make_system(_kind_cfg(kind, "krylov"))
    y = s.initial_y()
    info = s.forces(y, s.frames0)
    assert isinstance(s.make_w("krylov", y, info.frames, info.G, 0.01), SwimmerKrylovW)


def _loaded_krylov_w(kind, rng, gh=0.05):
    """``(system, y, info, gamma h, W)``: the matrix-free stage solver of ``kind`` at a state
    loaded by moving its beads 0.01 bond at random."""
    s = make_system(_kind_cfg(kind, "krylov"))
    y = s.initial_y()
    y[s.sl_x] += 0.01 * s.bond * rng.standard_normal(s.sl_x.stop - s.sl_x.start)
    info = s.forces(y, s.frames0)
    return s, y, info, gh, s.make_w("krylov", y, info.frames, info.G, gh)


@pytest.mark.parametrize("kind", FREE_KINDS)
def test_krylov_solve_meets_its_residual_and_the_dense_pose_rows(kind, rng):
    """One solve at a loaded state: the filaments' rows leave a relative residual of ``W``
    (its own matrix-free product) below the 1e-3 it stops at, and the pose rows are the
    dense solver's ``gamma h P J u`` for that ``u`` (:class:`SwimmerW`, built from the
    body's rows, an independent route) to 1e-10."""
    from flagwrap.system.swimmer import SwimmerW

    s, y, info, gh, W = _loaded_krylov_w(kind, rng)
    rhs = rng.standard_normal(s.ny)
    n = s.n_in
    rhs[s.i_phi] = 0.0
    u = W.solve(rhs)
    r = W.matvec(u[:n]) - rhs[:n]
    assert np.linalg.norm(r) <= 1e-3 * np.linalg.norm(rhs[:n])
    assert W.iterations > 0
    dense = SwimmerW(s, y, info.frames, info.G, gh)
    pose = rhs[n:] + dense.PJ @ u[:n]
    assert np.abs(u[n:] - pose).max() < 1e-10 * max(1.0, np.abs(pose).max())


@pytest.mark.parametrize("kind", FREE_KINDS)
def test_krylov_preconditioner_inverts_the_filaments_and_the_body_motion(kind, rng):
    """The preconditioner is the exact inverse of ``I - gamma h A_P J``, ``A_P`` each
    filament's free-space RPY and twist drag plus the body's rigid motion under all of them.
    That motion is taken here from the dense route: the whole mobility (:meth:`mobility_matrix`,
    screening exact) less the beads' own RPY and the body's screening
    (:func:`~flagwrap.body.solver.screening_matrix`); ``J`` with its motor-angle columns.
    To 1e-9 (a dense solve of a well-conditioned system, ~1e-13 in exact rounding)."""
    from flagwrap.body.solver import screening_matrix

    s, y, _, gh, W = _loaded_krylov_w(kind, rng)
    n, n3 = s.n_in, 3 * s.nb
    xf, _, C = s._geometry(y)
    Mff = s.mobility.matrix(xf)
    motion = s.mobility_matrix(y, screening=True)
    motion[:n3, :n3] -= (Mff - screening_matrix(s._body(y)[0], C)) / s.machin
    tw = np.arange(n3, n3 + s.ne)
    motion[tw, tw] -= s.twist_mobility
    A = motion
    for p in s.parts:  # each filament's own beads' free-space RPY (none between filaments)
        idx = np.arange(p.ny) if p.ymap is None else p.ymap
        pos, twk = idx[:3 * p.nb], idx[3 * p.nb:3 * p.nb + p.ne]
        A[np.ix_(pos, pos)] += Mff[np.ix_(pos, pos)] / s.machin
        A[twk, twk] += np.broadcast_to(s.twist_mobility, (s.ne,))[twk - n3]
    P = np.eye(n) - gh * (A @ W.J.toarray())
    r = rng.standard_normal(n)
    want = np.linalg.solve(P, r)
    assert np.abs(W.P.solve(r) - want).max() < 1e-9 * np.abs(want).max()


def test_a_free_cell_refuses_a_stage_solver_it_has_not(tmp_path, capsys):
    from flagwrap.cli.main import main

    cfg = tmp_path / "c.toml"
    text = tiny_toml().replace("[numerics]\n", "[numerics]\nlinear_solver = 'near'\n", 1)
    cfg.write_text(text + NO_SLIP_BODY + "motion = 'free'\n")
    assert main(["run", str(cfg), "-o", str(tmp_path / "r.nc"), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert "numerics.linear_solver" in err and "'krylov'" in err and err.count("\n") == 1


def test_auto_picks_the_matrix_free_solver_above_the_crossover(monkeypatch):
    """``linear_solver = "auto"`` on a free cell: dense up to ``AUTO_KRYLOV_NY`` filament
    unknowns, matrix-free above (speed motors); a torque motor keeps the dense one."""
    import flagwrap.system.swimmer as sw

    for motor in ("", TORQUE_SPEED):
        s = make_system(_cfg("lab", motor))
        y = s.initial_y()
        info = s.forces(y, s.frames0)
        assert isinstance(s.make_w("auto", y, info.frames, info.G, 0.01, omega=1.0), sw.SwimmerW)
        monkeypatch.setattr(sw, "AUTO_KRYLOV_NY", s.n_in - 1)
        picked = s.make_w("auto", y, info.frames, info.G, 0.01, omega=1.0)
        assert isinstance(picked, sw.SwimmerW if motor else sw.SwimmerKrylovW)
        monkeypatch.undo()
