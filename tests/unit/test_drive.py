"""Motor drives: prescribed rate, torque, linear torque-speed curve (flagwrap.motor.drive)."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from conftest import make_config, paper_filament
from flagwrap.errors import UserInputError
from flagwrap.motor.drive import TorqueDrive, TorqueSpeedDrive
from flagwrap.params import Motor, Numerics, Phase

finite = st.floats(-1e3, 1e3, allow_nan=False)


@settings(max_examples=60, deadline=None)
@given(tau=st.floats(1e-3, 1e3), om0=st.floats(1e-3, 1e3), zeta=st.floats(1e-6, 1e2),
       G=finite, omega=st.sampled_from([1.0, -2.0, 0.0]))
def test_rotor_torque_balance_holds_at_the_rate(tau, om0, zeta, G, omega):
    # zeta r = tau_m(r) + G_phi: the rotor has no inertia
    for d in (TorqueDrive(tau, zeta), TorqueSpeedDrive(tau, om0, zeta)):
        r = d.rate(omega, G)
        tm = d.torque(r, omega) if omega != 0 else 0.0
        assert np.isclose(zeta * r, tm + G, rtol=1e-9, atol=1e-9 * (tau + abs(G)))


def test_torque_speed_curve_ends():
    d = TorqueSpeedDrive(2.0, 5.0, 1e-3)
    assert d.torque(0.0, 1.0) == 2.0 and d.torque(5.0, 1.0) == 0.0  # stall, zero load
    assert d.torque(-5.0, -1.0) == 0.0 and d.torque(0.0, -1.0) == -2.0  # CW mirrors CCW


def _base(M=100.0, turns=1.0):
    return make_config(machin=M, protocol=(("ccw", turns),), filament=paper_filament(n_beads=21),
                       numerics=Numerics(tol=1e-5))


def test_torque_speed_motor_runs_where_its_curve_meets_the_load():
    # independent answer: a speed motor at omega = 1 needs the torque N1 (its steady whirl);
    # a torque-speed motor whose line passes through (1, N1) (stall 2 N1, zero load 2) must
    # settle at rate 1. Tolerance 1 %: the whirl's torque still drifts by ~0.1 % per turn
    # at 1 turn (measured 1.001 at 1.5 turns)
    from flagwrap.simulation import simulate

    base = _base()
    speed = simulate(base)
    N1 = float(np.mean(speed.motor_torque[-4:]))
    sc = base.scales
    m = Motor(machin=100.0, protocol=(Phase("ccw", 1.0),), kind="torque-speed",
              stall_torque=sc.from_torque(2 * N1), zero_load_speed=2 * base.omega / (2 * np.pi))
    tr = simulate(base.replace(motor=m))
    assert tr.ok, tr.message
    t, phi = np.asarray(tr.t), np.asarray(tr.phi)
    rate = (phi[-1] - phi[-5]) / (t[-1] - t[-5])
    assert abs(rate - 1.0) < 0.01
    assert abs(tr.motor_torque[-1] / N1 - 1.0) < 0.01


def test_motor_row_of_w_is_the_derivative_of_the_rate():
    # W = I - gamma h d(dy/dt)/dy on the motor's row: against central differences of the rate
    from flagwrap.integrators.linear import DenseW
    from flagwrap.system.rod_system import RodSystem

    base = _base()
    m = Motor(machin=100.0, protocol=(Phase("ccw", 1.0),), kind="torque", stall_torque=1e-9)
    s = RodSystem(base.replace(motor=m))
    rng = np.random.default_rng(3)
    y = s.initial_y()
    y[s.sl_x] += 1e-3 * s.bond * rng.standard_normal(s.sl_x.stop)
    y[s.i_phi] = 0.2
    info = s.forces(y, s.frames0)
    gh = 1e-3
    W = DenseW(s, y, s.frames0, info.G, gh, omega=1.0)
    Wd = sla_unpack(W, s.ny)
    h = s.fd_step
    fd = np.zeros(s.ny)
    for k in range(s.ny):
        yp, ym = y.copy(), y.copy()
        yp[k] += h
        ym[k] -= h
        fd[k] = (s.velocity(yp, s.forces(yp, s.frames0), 1.0)[s.i_phi]
                 - s.velocity(ym, s.forces(ym, s.frames0), 1.0)[s.i_phi]) / (2 * h)
    expect = -gh * fd
    expect[s.i_phi] += 1.0
    assert np.allclose(Wd[s.i_phi], expect, rtol=1e-5, atol=1e-6 * np.abs(expect).max())


def sla_unpack(W, n):
    """The dense matrix a DenseW factorised (rebuilt from its LU)."""
    lu, piv = W.lu
    L = np.tril(lu, -1) + np.eye(n)
    U = np.triu(lu)
    A = L @ U
    for i in range(n - 1, -1, -1):  # undo the row swaps
        j = piv[i]
        A[[i, j]] = A[[j, i]]
    return A


@pytest.mark.parametrize("motor, match", [
    (dict(kind="torque"), "motor.stall_torque"),
    (dict(kind="torque", stall_torque=-1e-3), "motor.stall_torque must be > 0"),
    (dict(kind="torque-speed", stall_torque=1e-3), "motor.zero_load_speed"),
    (dict(kind="speed", stall_torque=1e-3), "needs motor.kind"),
    (dict(kind="whirl"), "motor.kind must be one of"),
])
def test_bad_motor_input_names_the_key(motor, match):
    with pytest.raises(UserInputError, match=match):
        Motor(machin=100.0, **motor)


def test_torque_motor_refuses_solvers_and_frames_it_cannot_use():
    m = Motor(machin=100.0, kind="torque", stall_torque=1e-3)
    with pytest.raises(UserInputError, match="linear_solver = 'banded'"):
        make_config(hi=False).replace(motor=m, numerics=Numerics(hydrodynamics=False,
                                                                 linear_solver="banded"))
    with pytest.raises(UserInputError, match="needs motor.kind = 'speed'"):
        make_config().replace(motor=m, numerics=Numerics(frame="rotating"))
    with pytest.raises(UserInputError, match="speed = 2"):
        Motor(machin=100.0, kind="torque", stall_torque=1e-3, protocol=(Phase("ccw", 1, 2.0),))


def test_motor_column_of_w_is_the_derivative_of_the_velocity():
    # the whole W of a torque motor against central differences of the full velocity:
    # W = I - gamma h d(dy/dt)/dy up to W's approximations, which leave the mobility frozen
    # (Mob (dG/dy) without (dMob/dy) G); a torque motor's column must not count twice
    from flagwrap.integrators.linear import DenseW
    from flagwrap.system.rod_system import RodSystem

    m = Motor(machin=100.0, protocol=(Phase("ccw", 1.0),), kind="torque", stall_torque=1e-9)
    s = RodSystem(_base().replace(motor=m, numerics=Numerics(hydrodynamics=False)))
    y = s.initial_y()
    y[s.sl_x] += 1e-3 * s.bond * np.random.default_rng(4).standard_normal(s.sl_x.stop)
    info = s.forces(y, s.frames0)
    gh = 1e-3
    Wd = sla_unpack(DenseW(s, y, s.frames0, info.G, gh, omega=1.0), s.ny)
    h = s.fd_step
    k = s.i_phi
    yp, ym = y.copy(), y.copy()
    yp[k] += h
    ym[k] -= h
    col = (s.velocity(yp, s.forces(yp, s.frames0), 1.0)
           - s.velocity(ym, s.forces(ym, s.frames0), 1.0)) / (2 * h)
    expect = -gh * col
    expect[k] += 1.0
    # HI off: the mobility is constant, so W's column is exact up to the differences
    assert np.allclose(Wd[:, k], expect, rtol=1e-4, atol=1e-6 * np.abs(expect).max())
