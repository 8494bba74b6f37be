"""The flagellar hook (flagwrap.joints.hook): the clamp as a special hook, the torque balance
of a stiff rod on a soft hook against the analytic one (lumped and resolved), the hook's
energy gradient against finite differences, and the [joint] input checks."""

import dataclasses
import math

import numpy as np
import pytest

from flagwrap.elasticity.rod import elastic_energy, elastic_forces, initial_frames, rest_state
from flagwrap.errors import UserInputError
from flagwrap.io.config import load_config
from flagwrap.joints import LumpedHook, make_joint
from flagwrap.system.rod_system import RodSystem
from flagwrap.params import Joint, Phase
from flagwrap.simulation import Simulation, simulate

from conftest import fd_gradient


def fig4a(turns=1.0):
    cfg = load_config("examples/fig4a.toml")
    return cfg.replace(motor=dataclasses.replace(
        cfg.motor, protocol=(Phase("ccw", turns), Phase("cw", turns))))


class RodLawHook(LumpedHook):
    """A joint defined in this test: the lumped hook with the discrete rod's curvature
    measure (2 tan(psi/2)) kept at its vertex instead of the turning angle."""

    def rest(self, rest):
        return rest.with_vertex(1, cbend=self.k_bend, ctwist=self.k_twist)


def test_a_rod_law_hook_with_the_clamps_own_stiffness_is_the_clamp():
    # the clamp's vertex 1 bends with A/b and twists with C/b in the rod's measure: a hook that
    # keeps that measure with A_h/l_h = A/b, C_h/l_h = C/b is the same system, so the joint's
    # plumbing (kinematics, rest, observables) changes nothing: same steps, same frames to the
    # rounding of the coefficients (A_h L/(A l_h) vs 1/b). Fig. 4(a) shortened to 1 + 1 turns
    cfg = fig4a()
    fil = cfg.filament
    s0 = RodSystem(cfg)
    b = fil.bond_length / fil.length
    hook = RodLawHook(s0.x0, s0.theta0, k_bend=1.0 / b, k_twist=fil.twist_modulus / fil.bending_modulus / b)
    a = simulate(cfg)
    h = Simulation(cfg, system=RodSystem(cfg, joint=hook)).run()
    assert a.ok and h.ok and (a.n_steps, a.n_rejected) == (h.n_steps, h.n_rejected)
    xa, xh = a.arrays()["x"], h.arrays()["x"]
    assert np.abs(xa[:, -1] - xh[:, -1]).max() < 1e-9
    ta, th = a.arrays()["motor_torque"], h.arrays()["motor_torque"]
    assert np.abs(ta - th).max() < 1e-9 * np.abs(ta).max()


def test_stiff_hooks_converge_to_a_rigid_joint():
    # A_h/l_h = 100 A/b and 1e4 A/b: the vertex no longer bends. Both stiff hooks agree with
    # each other to 1e-3 L; they differ from the clamp by its own vertex compliance (measured
    # ~6e-3 L over 1 + 1 turns; docs/hook.md), which is why the clamp is "a hook with A/b"
    cfg = fig4a()
    fil = cfg.filament
    tips = []
    for stiff in (100.0, 1e4):
        c = cfg.replace(joint=Joint("hook", hook_length=fil.bond_length / stiff,
                                    hook_bending_modulus=fil.bending_modulus))
        tr = simulate(c)
        assert tr.ok
        tips.append(tr.arrays()["x"][:, -1])
    assert np.abs(tips[0] - tips[1]).max() < 1e-3


class TipForce:
    """A constant force on the free end (an interaction defined here: U = -F . x_N)."""

    name = "tip_force"
    nonlocal_hessian = False

    def __init__(self, F):
        self.F = np.asarray(F, float)

    def energy_grad(self, x, theta, grad_x, grad_theta):
        grad_x[-1] -= self.F
        return -float(self.F @ x[-1])

    def hessian_coo(self, x, theta):
        return None


def _tilt_balance(k, F, lever):
    """Hook angle psi of a nearly rigid rod (A = 1) on a spring k under a tip force F normal
    to the motor axis: k psi = F lever cos(psi) (1 - F lever^2 sin(psi) / 3), the last factor
    the rod's own bending to first order (its deflection F lever^3 cos(psi) / 3 shortens the
    lever arm by that times sin(psi)); neglected terms O((F lever^2)^2) ~ 1e-3."""
    lo, hi = 0.0, 0.5 * math.pi
    for _ in range(200):
        m = 0.5 * (lo + hi)
        if k * m - F * lever * math.cos(m) * (1 - F * lever**2 * math.sin(m) / 3) > 0:
            hi = m
        else:
            lo = m
    return lo


@pytest.mark.parametrize("segments, tol", [(0, 1e-3), (8, 2e-3)])
def test_rod_on_a_soft_hook_turned_slowly_bends_to_its_torque_balance(segments, tol):
    # a straight rod (N = 41, HI off, no body) on a hook of k = A_h/l_h = 0.05 A/L, a force
    # F = 0.028 A/L^2 on its free end along x, the motor turning slowly (M = 0.02: the tilt
    # relaxes in ~0.4/omega, 2 turns = 30 relaxation times; the rod spins about its own axis,
    # which adds only an axial torque). Lumped: the angle law makes the spring exact, the
    # tolerance is the neglected O((F L^2)^2). Resolved with 8 bonds: the discrete rod's
    # 2 tan(psi/2) per vertex adds ~(psi/8)^2/4 ~ 1e-3 (n^-2; 4 bonds: 2.2e-3 measured)
    cfg = load_config("examples/fig4a.toml")
    N = 41
    fil = dataclasses.replace(cfg.filament, n_beads=N, pitch_angle_deg=None, turns=None)
    k, F, lh = 0.05, 0.028, 0.01
    cfg = cfg.replace(
        filament=fil, body=dataclasses.replace(cfg.body, enabled=False),
        numerics=dataclasses.replace(cfg.numerics, hydrodynamics=False),
        motor=dataclasses.replace(cfg.motor, machin=0.02, protocol=(Phase("ccw", 2.0),)),
        joint=Joint("hook", hook_length=lh * fil.length,
                    hook_bending_modulus=k * fil.bending_modulus * lh, hook_segments=segments))
    x0 = np.zeros((N, 3))
    x0[:, 2] = -np.linspace(0.0, 1.0, N)
    s = RodSystem(cfg, x0=x0, interactions=[TipForce([F, 0.0, 0.0])])
    tr = Simulation(cfg, system=s).run()
    assert tr.ok
    psi = tr.arrays()["hook_angle"]
    # the rod beyond the pivot: L - b (the motor holds the first bond); resolved, the pivot
    # is the hook's middle, l_h/2 further up
    lever = 1.0 - fil.bond_length / fil.length + (0.5 * lh if segments else 0.0)
    want = _tilt_balance(k, F, lever)
    assert abs(psi[-1] / want - 1) < tol
    assert np.ptp(psi[-5:]) < 1e-4 * want  # steady
    if segments == 0:  # the recorded joint torque is the spring's k_h psi (straight rest)
        torque = tr.arrays()["hook_torque"][-1]
        assert torque == pytest.approx(k * psi[-1], rel=1e-6)


@pytest.mark.parametrize("bend", [0.3, 1.2, 2.2])
def test_hook_energy_gradient_matches_finite_differences(rng, bend):
    # the lumped hook's angle-law vertex, bent through large angles, with twist and a rest kink
    x = np.zeros((8, 3))
    x[1] = (0.0, 0.0, -0.1)
    for i in range(2, 8):  # leaves the axis at 0.5 rad (the rest kink), then straight
        x[i] = x[1] + 0.1 * (i - 1) * np.array([math.sin(0.5), 0.0, -math.cos(0.5)])
    th0 = np.zeros(7)
    fr = initial_frames(x)
    hook = LumpedHook(x, th0, k_bend=3.0, k_twist=2.0)
    rest = hook.rest(rest_state(x, fr, th0, 1.0, 0.7, 1e3))
    assert rest.angle_law[1] and not rest.angle_law[2:].any()
    # bend the hook: rotate everything beyond bead 1 about y by `bend`, then jiggle
    c, s_ = math.cos(bend), math.sin(bend)
    R = np.array([[c, 0, s_], [0, 1, 0], [-s_, 0, c]])
    xd = x.copy()
    xd[2:] = x[1] + (x[2:] - x[1]) @ R.T
    xd[2:] += 0.01 * rng.standard_normal((6, 3))
    th = 0.3 * rng.standard_normal(7)
    _, _, _, base = elastic_forces(xd, th, fr, rest)
    E, Fx, tau, _ = elastic_forces(xd, th, base, rest)
    g, gt = fd_gradient(lambda xx, tt: elastic_energy(xx, tt, base, rest), xd, th)
    # central differences: O(h^2) truncation and ~1e-10 rounding in E over h, relative 1e-6
    assert np.abs(Fx + g).max() <= 1e-6 * np.abs(g).max()
    assert np.abs(tau + gt).max() <= 1e-6 * np.abs(gt).max()


def test_the_angle_law_stores_k_psi_squared_over_two():
    # a plane bend of the hook vertex by psi from a straight rest: E = k psi^2 / 2 exactly
    x = np.array([[0, 0, 0], [0, 0, -1.0], [0, 0, -2.0]])
    th0 = np.zeros(2)
    fr = initial_frames(x)
    hook = LumpedHook(x, th0, k_bend=2.5, k_twist=1.0)
    rest = hook.rest(rest_state(x, fr, th0, 1.0, 1.0, 0.0))
    for psi in (0.1, 1.0, 2.0, 3.0):
        xb = x.copy()
        xb[2] = x[1] + np.array([math.sin(psi), 0.0, -math.cos(psi)])
        assert elastic_energy(xb, th0, fr, rest) == pytest.approx(0.5 * 2.5 * psi**2, rel=1e-12)


def test_resolved_hook_inserts_its_bonds_and_keeps_the_filament():
    cfg = load_config("examples/fig4a.toml")
    fil = cfg.filament
    cfg = cfg.replace(joint=Joint("hook", hook_length=0.01 * fil.length, hook_bending_modulus=
                                  0.1 * fil.bending_modulus * 0.01, hook_segments=4))
    s = RodSystem(cfg)
    assert s.N == fil.n_beads + 4
    l0 = s.rest.l0
    assert np.allclose(l0[1:5], 0.0025) and np.allclose(np.delete(l0, [1, 2, 3, 4]), fil.bond_length / fil.length)
    # total bending compliance of the hook's vertices (less the filament's half bond) is l_h/A_h
    comp = (1.0 / s.rest.cbend[1:6]).sum() - 0.5 * fil.bond_length / fil.length
    assert comp == pytest.approx(0.01 / 0.001, rel=1e-12)
    # the stress-free state is an equilibrium
    info = s.forces(s.initial_y(), s.frames0)
    assert np.abs(info.G).max() < 1e-8


@pytest.mark.parametrize("joint, key", [
    (dict(kind="hook", hook_length=-1e-3, hook_bending_modulus=1e-9), "joint.hook_length"),
    (dict(kind="hook", hook_length=0.0, hook_bending_modulus=1e-9), "joint.hook_length"),
    (dict(kind="hook", hook_length=1e-3, hook_bending_modulus=0.0), "joint.hook_bending_modulus"),
    (dict(kind="hook", hook_length=1e-3, hook_bending_modulus=-1.0), "joint.hook_bending_modulus"),
    (dict(kind="hook", hook_length=1e-3, hook_bending_modulus=1e-9, hook_twist_modulus=0.0),
     "joint.hook_twist_modulus"),
    (dict(kind="hook", hook_length=1.0, hook_bending_modulus=1e-9), "joint.hook_length"),
    (dict(kind="hook", hook_bending_modulus=1e-9), "joint.hook_length"),
    (dict(kind="hook", hook_length=1e-3, hook_bending_modulus=1e-9, hook_segments=1),
     "joint.hook_segments"),
    (dict(kind="clamp", hook_length=1e-3), "joint.hook_length"),
    (dict(kind="spring"), "joint.kind"),
])
def test_bad_hook_input_names_the_key(joint, key):
    cfg = load_config("examples/fig4a.toml")
    with pytest.raises(UserInputError, match=key.replace(".", r"\.")):
        cfg.replace(joint=Joint(**joint))


def test_make_joint_builds_the_kind_asked_for():
    cfg = load_config("examples/fig4a.toml")
    x0 = np.zeros((5, 3))
    x0[:, 2] = -np.arange(5.0)
    j, x, th = make_joint(cfg, x0, np.zeros(4))
    assert j.kind == "joint" and x is x0
    fil = cfg.filament
    hook = cfg.replace(joint=Joint("hook", hook_length=1e-3, hook_bending_modulus=fil.bending_modulus))
    j, x, th = make_joint(hook, x0, np.zeros(4))
    # k = A_h L / (A l_h) = 0.4 / 1e-3; C_h defaults to the filament's C
    assert isinstance(j, LumpedHook) and j.k_bend == pytest.approx(400.0)
    assert j.k_twist == pytest.approx(400.0 * fil.twist_modulus / fil.bending_modulus)
