"""The turning-frame equations (flagwrap.system.rotating): Jacobian, refusals, and the
turning-frame run against the lab-frame one."""

import dataclasses

import numpy as np
import pytest

from conftest import fd_frame_jacobian
from flagwrap.errors import UserInputError
from flagwrap.io.config import load_config
from flagwrap.params import Phase
from flagwrap.simulation import simulate
from flagwrap.system.rod_system import RodSystem
from flagwrap.system.rotating import RotatingFrame, RotatingSystem, rotation


def small(n_beads=31, hydrodynamics=True, machin=283.0, protocol=None, **numerics):
    cfg = load_config("examples/fig4a.toml")
    return cfg.replace(
        filament=dataclasses.replace(cfg.filament, n_beads=n_beads, pitch_angle_deg=None,
                                     turns=None),
        motor=dataclasses.replace(cfg.motor, machin=machin,
                                  protocol=protocol or cfg.motor.protocol),
        numerics=dataclasses.replace(cfg.numerics, hydrodynamics=hydrodynamics, **numerics))


@pytest.mark.parametrize("hydrodynamics", [True, False])
def test_jacobian_matches_central_differences_of_the_velocity(hydrodynamics):
    # an independent check of the assembled J (Mob dG + dMob[G] + rotation terms): central
    # differences of the velocity itself, column by column. Their truncation and rounding
    # errors are ~1e-9 of the largest entry at these steps
    s = RodSystem(small(hydrodynamics=hydrodynamics))
    fr = RotatingFrame(s, -1.0)
    rng = np.random.default_rng(1)
    z = s.initial_y()[:-1].copy()
    z[: fr.n3] += 1e-4 * rng.standard_normal(fr.n3)  # a strained, bent, twisted state
    z[fr.n3:] += 0.02 * rng.standard_normal(fr.n - fr.n3)
    f, info = fr.velocity(z, s.frames0, 400.0)
    base = info.frames
    J = fr.jacobian(z, base, 400.0, info)
    Jb = fd_frame_jacobian(fr, z, base, 400.0)
    assert np.max(np.abs(J - Jb)) < 1e-7 * np.max(np.abs(J))


def test_velocity_is_the_lab_velocity_seen_from_the_turning_frame():
    # at phi = 0 the frames coincide: dz/dt = v_lab - omega a x x for the beads, and the twist
    # rates differ by omega (a . t) (the transported directors' relative turn)
    s = RodSystem(small())
    fr = RotatingFrame(s, 1.0)
    y = s.initial_y()
    f_lab, info = s.rhs(y, s.frames0, 1.0)
    f_rot, _ = fr.velocity(y[:-1], s.frames0)
    a = np.array([0.0, 0.0, -1.0])
    np.testing.assert_allclose(f_rot[: fr.n3], f_lab[: fr.n3] - np.cross(a, info.x[s.nc:]).ravel(),
                               atol=1e-12)
    np.testing.assert_allclose(f_rot[fr.n3:], f_lab[fr.n3:-1] - info.frames.t[s.ec:] @ a, atol=1e-12)


def test_rotation_matrix_is_right_handed():
    R = rotation([0.0, 0.0, 1.0], np.pi / 2)
    np.testing.assert_allclose(R @ [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], atol=1e-15)


class NotInvariant:
    name = "tether"

    def energy_grad(self, x, theta, grad_x, grad_theta):
        return 0.0


def test_an_interaction_not_known_to_be_rotation_invariant_is_refused():
    cfg = small()
    with pytest.raises(UserInputError, match="'tether'.*rotation_invariant"):
        RotatingSystem(RodSystem(cfg, interactions=[NotInvariant()]))


def test_numerics_frame_is_validated():
    cfg = load_config("examples/fig4a.toml")
    with pytest.raises(UserInputError, match="numerics.frame must be 'lab' or 'rotating'"):
        dataclasses.replace(cfg.numerics, frame="corotating")


def test_the_default_frame_keeps_result_keys():
    cfg = load_config("examples/fig4a.toml")
    rot = cfg.replace(numerics=dataclasses.replace(cfg.numerics, frame="rotating"))
    assert "frame" not in cfg.to_dict(for_hash=True)["numerics"]
    assert rot.to_dict(for_hash=True)["numerics"]["frame"] == "rotating"


def test_turning_frame_run_equals_the_lab_run_rotated():
    # 0.5 CCW + 0.5 CW turns, N = 31, HI on, both at tol 1e-8: the recorded lab-frame
    # positions, material directors and motor torque agree to the integration error.
    # Measured: the frames differ by 4.8e-5, 7.7e-6, 2.6e-6 L at tol 1e-6, 1e-7, 1e-8
    # (converging together), and the lab run at 1e-7 is itself 1.1e-5 L from the one at 1e-8,
    # so 1e-5 L is the lab frame's own error one decade of tol looser
    proto = (Phase("ccw", 0.5, 1.0), Phase("cw", 0.5, 1.0))
    out = {}
    for frame in ("lab", "rotating"):
        tr = simulate(small(protocol=proto, frame=frame, tol=1e-8, save_every=0.1))
        assert tr.ok
        out[frame] = tr.arrays()
    a, b = out["lab"], out["rotating"]
    np.testing.assert_allclose(a["t"], b["t"])
    np.testing.assert_allclose(a["phi"], b["phi"], atol=1e-12)
    assert np.max(np.abs(a["x"] - b["x"])) < 1e-5
    assert np.max(np.abs(a["m1"] - b["m1"])) < 1e-4  # 3.1e-5: angles are held to 10x tol
    np.testing.assert_allclose(a["motor_torque"], b["motor_torque"], rtol=0,
                               atol=1e-4 * np.max(np.abs(a["motor_torque"])))  # 2.4e-5


@pytest.mark.slow
def test_buckling_run_in_the_turning_frame_has_the_lab_runs_onset_and_torque(tmp_path):
    # the buckling case: the Fig. 4(a) helix at M = 600, 5 CCW + 10 CW turns, HI on,
    # default tol 1e-5, both frames. The rise criterion's t_c is read off frames 0.05 T
    # apart: it must agree to a frame. The peak CW torque falls in the buckled phase (5.75 T
    # after the switch), where the lab frame at tol 1e-5 is itself 3.2 % from its tol-1e-6
    # run (-15.99 vs -16.52 A/L; the turning frame: -16.67 and -16.62, 0.6 % from the lab's
    # 1e-6): 5 % allows for that error
    import flagwrap
    from flagwrap.io.runfile import write_run

    cfg = load_config("examples/fig4a.toml")
    proto = (Phase("ccw", 5.0, 1.0), Phase("cw", 10.0, 1.0))
    res = {}
    for frame in ("lab", "rotating"):
        c = cfg.replace(motor=dataclasses.replace(cfg.motor, machin=600.0, protocol=proto),
                        numerics=dataclasses.replace(cfg.numerics, frame=frame))
        tr = simulate(c)
        assert tr.ok
        write_run(tr, tmp_path / f"{frame}.nc")
        res[frame] = flagwrap.analyze(tmp_path / f"{frame}.nc", write=False)
    a, b = res["lab"], res["rotating"]
    assert a["buckled"] and b["buckled"]
    assert abs(a["waiting_time_turns"] - b["waiting_time_turns"]) <= 0.05 + 1e-9
    assert b["torque_peak_reduced"] == pytest.approx(a["torque_peak_reduced"], rel=5e-2)


def test_the_turning_frame_is_the_system_transformed_not_a_wrapper():
    # the same RodSystem data under this frame's equations: nothing forwarded, every method
    # of the protocol its own; pack takes lab positions and record_view gives them back
    lab = RodSystem(small(n_beads=21))
    s = RotatingSystem(lab)
    assert isinstance(s, RodSystem) and "__getattr__" not in vars(RotatingSystem)
    assert s.parts is lab.parts and s.layout is lab.layout
    rng = np.random.default_rng(5)
    x, theta, _ = lab.unpack(lab.initial_y())
    x[lab.free_beads] += 1e-3 * rng.standard_normal((lab.nb, 3))
    phi = 1.234
    x[:lab.nc] = lab.joint.positions(phi)  # the clamp where the motor holds it in the lab
    y = s.pack(x, theta, phi)
    info = s.record_view(y, s.forces(y, s.frames0))
    np.testing.assert_allclose(info.x, x, atol=1e-14)
    # in the frame the clamp is where the lab clamp is at phi = 0
    np.testing.assert_allclose(s.unpack(y)[0][:lab.nc], lab.joint.positions(0.0), atol=1e-15)
