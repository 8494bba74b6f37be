"""Steady states, spectra and the linear threshold (flagwrap.stability), against independent
answers: the discrete rod's relaxation rates, the lab-frame integrator, Newton's fixed point."""

import dataclasses

import numpy as np
import pytest

from flagwrap.params import Phase
from flagwrap.simulation import Simulation
from flagwrap.stability.spectrum import mode_vector, spectrum
from flagwrap.stability.steady import branch, initial_guess, newton, retract
from flagwrap.stability.threshold import find_critical
from flagwrap.system.rod_system import RodSystem
from flagwrap.system.rotating import RotatingFrame, rotation

from test_rotating import small


def straight_rod(n_beads=21, machin=50.0):
    cfg = small(n_beads=n_beads, hydrodynamics=False, machin=machin)
    return cfg.replace(
        filament=dataclasses.replace(cfg.filament, shape="straight", turns=None,
                                     pitch_angle_deg=None),
        body=dataclasses.replace(cfg.body, enabled=False))


def rod_rates(cfg, N):
    """The discrete rod's relaxation rates at rest, built from the model's definition
    (docs/model.md), not from the code: bending ``(A/b) sum psi_i^2 / 2`` with the turning
    angle ``psi_i = (u_{i+1} - 2 u_i + u_{i-1}) / b`` of a transverse displacement ``u``,
    beads 0 and 1 held, Stokes drag ``6 pi a M`` per bead; twist ``(C/b) sum (theta_i -
    theta_{i-1})^2 / 2``, bond 0 held, rotational drag ``8 pi a^3 M w_j`` (``w = 1.5`` on the
    end bonds)."""
    fil = cfg.filament
    b, a, M = fil.bond_length / fil.length, fil.bead_radius / fil.length, cfg.machin
    C = fil.twist_modulus / fil.bending_modulus
    D = np.zeros((N - 2, N))
    for i in range(1, N - 1):
        D[i - 1, i - 1:i + 2] = (1.0, -2.0, 1.0)
    K = (D.T @ D / b**3)[2:, 2:]
    bend = -np.linalg.eigvalsh(K) / (6 * np.pi * a * M)
    T = np.zeros((N - 1, N - 1))
    for i in range(1, N - 1):
        T[i - 1:i + 1, i - 1:i + 1] += C / b * np.array([[1.0, -1.0], [-1.0, 1.0]])
    w = np.ones(N - 1)
    w[[0, -1]] += 0.5
    zeta = 8 * np.pi * a**3 * M * w[1:]
    # symmetric form of Z^-1 T: same eigenvalues
    S = T[1:, 1:] / np.sqrt(np.outer(zeta, zeta))
    twist = -np.linalg.eigvalsh(S)
    return np.sort(bend)[::-1], np.sort(twist)[::-1]


def test_rest_rod_spectrum_is_the_discrete_rods_bending_and_twist_relaxation():
    # omega = 0, straight rod, HI off, no body: the Jacobian's eigenvalues must contain the
    # bending rates (twice: two transverse directions) and the twist rates. Tolerance 1e-6:
    # the Jacobian's central differences are accurate to (delta/b)^2 ~ 4e-11 and rounding
    # (measured: 1e-8 on the slowest bending rate, 1e-14 on twist)
    N = 21
    cfg = straight_rod(N)
    frame = RotatingFrame(RodSystem(cfg), 0.0)
    z, base = initial_guess(frame)
    st = newton(frame, cfg.machin, z, base)
    assert st.converged and st.residual == 0.0  # the rest shape is the fixed point
    w = spectrum(frame, st).values
    assert np.max(np.abs(w.imag)) < 1e-8 * np.max(np.abs(w))
    bend, twist = rod_rates(cfg, N)
    for lam in bend[:6]:
        assert np.sum(np.abs(w - lam) < 1e-6 * abs(lam)) == 2, lam
    for lam in twist[:6]:
        assert np.sum(np.abs(w - lam) < 1e-6 * abs(lam)) >= 1, lam
    assert w[0].real == pytest.approx(bend[0], rel=1e-6)  # the slowest mode is bending


def test_retract_keeps_bond_lengths_to_first_order():
    frame = RotatingFrame(RodSystem(small()), -1.0)
    z, _ = initial_guess(frame)
    rng = np.random.default_rng(3)
    dz = np.zeros_like(z)
    dz[: frame.n3] = 0.001 * rng.standard_normal(frame.n3)  # 3 % of a bond per component
    s = frame.system
    x0 = s.unpack(frame.full(z))[0]
    x1 = s.unpack(frame.full(retract(frame, z, dz)))[0]
    xl = s.unpack(frame.full(z + dz))[0]
    l0, l1, ll = (np.linalg.norm(np.diff(v, axis=0), axis=1) for v in (x0, x1, xl))
    e = np.diff(x0, axis=0)
    de = np.diff(xl - x0, axis=0)
    first = l0 + np.einsum("ij,ij->i", e, de) / l0
    np.testing.assert_allclose(l1, first, rtol=1e-12)
    assert np.max(np.abs(ll / first - 1)) > 5e-4  # the linear step: second-order strain


@pytest.fixture(scope="module")
def cw31():
    """N = 31, HI on, CW: the threshold and the frame."""
    frame = RotatingFrame(RodSystem(small(n_beads=31)), -1.0)
    return frame, find_critical(frame, m_max=3000.0)


def test_steady_state_is_a_fixed_point(cw31):
    # Newton's residual: 1e-10 L omega, the rounding floor of the stretching forces
    # (k_s eps |x| through the mobility, steady.py) is ~1e-11 here (measured 2.2e-11)
    frame, r = cw31
    st = branch(frame, [0.8 * r.machin_c])[0.8 * r.machin_c]
    f, _ = frame.velocity(st.z, st.base, st.machin)
    assert st.converged
    assert np.max(np.abs(f)) < 1e-10


def test_threshold_is_a_hopf_crossing_bracketed_to_rtol(cw31):
    _, r = cw31
    assert r.converged and r.crossing == "hopf"
    lo, hi = r.bracket
    assert lo < r.machin_c < hi and hi / lo - 1 <= 1e-3
    assert r.eigenvalue.real >= 0 and abs(r.eigenvalue.imag) > 0.1
    below = [p for p in r.branch if p.machin <= lo]
    assert all(p.leading.real < 0 for p in below)


def _lab_run(frame, st, dz, turns, tol=1e-8):
    """The lab-frame integrator from the steady state ``st`` (+ ``dz``); returns times and
    the largest bead distance from the steady shape, in the turning frame."""
    s = frame.system
    cfg = s.config.replace(
        motor=dataclasses.replace(s.config.motor, machin=st.machin,
                                  protocol=(Phase("cw", turns, 1.0),)),
        numerics=dataclasses.replace(s.config.numerics, tol=tol, save_every=0.05))
    lab = RodSystem(cfg)
    y0 = frame.full(retract(frame, st.z, dz))
    tr = Simulation(cfg, system=lab).run(y0=y0, base=st.base)
    assert tr.ok
    A = tr.arrays()
    x_star = s.unpack(frame.full(st.z))[0]
    dev = np.array([np.max(np.linalg.norm(A["x"][k] @ rotation(frame.axis, -A["phi"][k]).T
                                          - x_star, axis=1)) for k in range(len(A["t"]))])
    return A["t"], dev


@pytest.mark.parametrize("ratio", [0.9, 1.1])
def test_growth_rate_in_the_lab_frame_integrator_is_the_leading_eigenvalue(cw31, ratio):
    # Independent of the Jacobian: the lab-frame time integrator, started on the steady state
    # (turned into the lab at phi = 0) plus 1e-4 L along the critical mode, at 0.9 and 1.1
    # M_c. The unperturbed steady state must stay put (to the integration error), and the
    # perturbation decays / grows at Re lambda. The rate is fitted to the log-deviation
    # averaged over the mode's period 2 pi / Omega, over 6 turns. The tolerance is 25 %:
    # the deviation is a max over beads of a rotating pattern, and the next mode, 3x faster
    # in decay, is excited by the kick too (measured 4-15 % on the fit without the average)
    frame, r = cw31
    M = ratio * r.machin_c
    st = branch(frame, [M])[M]
    sp = spectrum(frame, st, vectors=True)
    lam = sp.leading
    t, dev0 = _lab_run(frame, st, np.zeros_like(st.z), 1.0)
    assert dev0.max() < 1e-5  # the lab integrator keeps the steady state
    v = mode_vector(frame, sp.vectors[:, 0]).real
    t, dev = _lab_run(frame, st, 1e-4 * v, 6.0)
    period = 2 * np.pi / abs(lam.imag)
    n = max(1, int(round(period / (t[1] - t[0]))))
    logd = np.convolve(np.log(dev), np.ones(n) / n, mode="valid")
    tm = np.convolve(t, np.ones(n) / n, mode="valid")
    rate = np.polyfit(tm, logd, 1)[0]
    assert rate == pytest.approx(lam.real, rel=0.25)
    assert np.sign(rate) == np.sign(ratio - 1)


def test_arnoldi_finds_the_dense_leading_eigenvalues(cw31):
    # long chains use shift-invert ARPACK around 0: the slow modes it returns must be the
    # dense spectrum's leading ones (to ARPACK's tolerance, ~1e-10 relative here)
    frame, r = cw31
    st = branch(frame, [0.8 * r.machin_c])[0.8 * r.machin_c]
    dense = spectrum(frame, st, method="dense").values
    arn = spectrum(frame, st, method="arnoldi", k=8).values
    for lam in dense[:4]:
        assert np.min(np.abs(arn - lam)) < 1e-8 * max(1.0, abs(lam))


def test_a_buoyant_helix_starts_by_switching_gravity_on_in_steps():
    # 2 % lighter than the fluid (G = 18.6): the static shape lifts far from the rest shape,
    # by an amount that does not shrink with M, so Newton from the rest shape fails at every
    # M; the gravity homotopy of start_state reaches the steady state, a true fixed point
    from flagwrap.stability.steady import NewtonFailure, start_state

    cfg = small(n_beads=31)
    cfg = cfg.replace(filament=dataclasses.replace(cfg.filament, density=None,
                                                   density_mismatch=-0.02, turns=None,
                                                   pitch_angle_deg=None))
    frame = RotatingFrame(RodSystem(cfg), -1.0)
    z, base = initial_guess(frame)
    with pytest.raises(NewtonFailure):
        newton(frame, 10.0, z, base)
    g0 = frame.system.gravity.copy()
    st = start_state(frame, 10.0)
    np.testing.assert_array_equal(frame.system.gravity, g0)  # gravity restored
    # a fixed point: the Newton update still left, J^-1 f, is at rounding (measured 1e-15 L;
    # 1e-12 is far below Newton's 1e-10 step tolerance). The velocity itself sits at the
    # stiff stretching forces' rounding floor (~1e-9 L omega here), which moves with the BLAS
    f, _ = frame.velocity(st.z, st.base, st.machin)
    J = frame.jacobian(st.z, st.base, st.machin)
    assert st.converged and np.max(np.abs(np.linalg.solve(J, f))) < 1e-12


def test_whirl_torque_is_the_lab_integrators_motor_torque(cw31):
    # independent of the frame's formula: the lab-frame time integrator started on the steady
    # whirl at the top of the bracket records the motor torque its own way (its torque
    # balance on the driven angle, every saved step). Over one turn the whirl stays put to
    # the integration error (tol 1e-8), so the two agree to 1e-5
    from flagwrap.stability.threshold import whirl_torque

    frame, r = cw31
    st = r.state
    s = frame.system
    cfg = s.config.replace(
        motor=dataclasses.replace(s.config.motor, machin=st.machin, protocol=(Phase("cw", 1.0, 1.0),)),
        numerics=dataclasses.replace(s.config.numerics, tol=1e-8, save_every=0.25))
    tr = Simulation(cfg, system=RodSystem(cfg)).run(y0=frame.full(st.z), base=st.base)
    assert tr.ok
    tq = np.abs(tr.arrays()["motor_torque"])
    assert np.allclose(tq, whirl_torque(r), rtol=1e-5)


def test_motor_verdict_compares_the_motors_torque_at_f_c_with_the_whirls(cw31):
    # a torque-speed line just above / below the stall torque T_c / (1 - f_c / f_0) the
    # whirl needs, a constant torque just above / below T_c
    from flagwrap.params import Motor
    from flagwrap.stability.threshold import motor_verdict

    frame, r = cw31
    cfg = frame.system.config
    r = dataclasses.replace(r, frequency_c=0.5)  # Hz: the test's own (the verdict works in SI)
    probe = motor_verdict(Motor(machin=100.0, kind="torque", stall_torque=1.0), cfg, r)
    T_c = probe["torque_c"]
    f0 = 2.0
    need = T_c / (1 - r.frequency_c / f0)
    for k, expect in ((1.01, True), (0.99, False)):
        v = motor_verdict(Motor(machin=100.0, kind="torque-speed", stall_torque=k * need,
                                zero_load_speed=f0), cfg, r)
        assert v["buckles"] is expect and v["stall_torque_needed"] == pytest.approx(need)
        v = motor_verdict(Motor(machin=100.0, kind="torque", stall_torque=k * T_c), cfg, r)
        assert v["buckles"] is expect
    slow = motor_verdict(Motor(machin=100.0, kind="torque-speed", stall_torque=1e3 * need,
                               zero_load_speed=0.4), cfg, r)  # f_0 below f_c: never
    assert slow["buckles"] is False and slow["stall_torque_needed"] == float("inf")


def test_a_lost_branch_keeps_the_states_that_converged(monkeypatch):
    # branch() lost every computed state when a later target failed (issue 29: the Fig. 4(a)
    # branch at M = 1164); now the exception carries the targets reached before it
    from flagwrap.stability import steady

    frame = RotatingFrame(RodSystem(small(n_beads=21, hydrodynamics=False)), -1.0)
    real = steady.newton

    def newton_failing_above_300(frame, machin, *a, **k):
        if machin > 300.0:
            raise steady.NewtonFailure("forced", None)
        return real(frame, machin, *a, **k)

    monkeypatch.setattr(steady, "newton", newton_failing_above_300)
    with pytest.raises(steady.BranchLost) as info:
        steady.branch(frame, [100.0, 250.0, 400.0])
    exc = info.value
    assert sorted(exc.states) == [100.0, 250.0]
    assert all(st.converged for st in exc.states.values())
    assert exc.state.machin == pytest.approx(300.0, rel=1e-2) and exc.m_failed > 300.0


def test_growth_slope_is_the_leading_eigenvalues_derivative_in_eps(cw31):
    # the slope from the bracket's two states against central differences of the leading
    # eigenvalue's real part from two steady states solved afresh at M_c (1 +- 2 %): Re is
    # smooth in M through a Hopf, so they agree to its curvature over the step (measured
    # 0.38244 against 0.38327, 0.2 %)
    import math

    from flagwrap.stability.threshold import onset_prefactor

    frame, r = cw31
    assert r.growth_slope > 0
    res = []
    for f in (0.98, 1.02):
        st = newton(frame, r.machin_c * f, r.state.z, r.state.base)
        res.append(spectrum(frame, st).leading.real)
    fd = (res[1] - res[0]) / math.log(1.02 / 0.98)
    assert r.growth_slope == pytest.approx(fd, rel=0.01)
    # the waiting-time prefactor: ln(rise/seed) / (2 pi s), the formula itself
    assert onset_prefactor(r.growth_slope) == pytest.approx(
        math.log(150.0) / (2 * math.pi * r.growth_slope))
    assert math.isnan(onset_prefactor(-1.0)) and math.isnan(onset_prefactor(0.5, seed=0.2))
