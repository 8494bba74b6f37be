"""The extension test of issue 15: an interaction defined in this file, with no edit of src/,
runs through the system, the integrator and the loop, and gives the analytic answer.

The toy: a harmonic tether pulling the free end of a straight clamped rod towards a point
``p`` off its axis, ``U = k |x_N - p|^2 / 2``. Small deflection: the rod is a cantilever, the tip
deflects by ``delta = F L_e^3 / (3 A)`` under ``F = k (p_x - delta)``, so
``delta = k p_x L_e^3/3 / (1 + k L_e^3/3)``. The discrete rod's cantilever has ``L_e = L - b/2``
(the motor holds the first bond, and the vertex where the rod leaves it carries a full bond's
compliance): measured 1.4e-4 (N = 41) and 5e-5 (N = 81) from that, against 2.8e-2 from L.
"""

import dataclasses

import numpy as np
import pytest

from flagwrap.io.config import load_config
from flagwrap.system.rod_system import RodSystem
from flagwrap.params import Phase
from flagwrap.simulation import Simulation


class Tether:
    """``U = k |x_N - p|^2 / 2`` on the last bead (core units)."""

    name = "tether"
    nonlocal_hessian = False

    def __init__(self, k, p):
        self.k = float(k)
        self.p = np.asarray(p, float)

    def energy_grad(self, x, theta, grad_x, grad_theta):
        d = x[-1] - self.p
        grad_x[-1] += self.k * d
        return 0.5 * self.k * float(d @ d)

    def hessian_coo(self, x, theta):
        r = 3 * (len(x) - 1) + np.arange(3)
        return r, r, np.full(3, self.k)


@pytest.mark.parametrize("with_hessian", [True, False])
def test_a_tether_defined_here_pulls_the_tip_to_the_cantilever_answer(with_hessian):
    cfg = load_config("examples/fig4a.toml")
    N = 41
    fil = dataclasses.replace(cfg.filament, n_beads=N, pitch_angle_deg=None, turns=None)
    cfg = cfg.replace(filament=fil, body=dataclasses.replace(cfg.body, enabled=False),
                      numerics=dataclasses.replace(cfg.numerics, hydrodynamics=False),
                      motor=dataclasses.replace(cfg.motor, machin=0.05, protocol=(Phase("ccw", 2.0),)))
    x0 = np.zeros((N, 3))
    x0[:, 2] = -np.linspace(0.0, 1.0, N)
    k, px = 1.0, 0.02
    tether = Tether(k, [px, 0.0, -1.0])
    if not with_hessian:  # then W lacks the term: the W-method must still converge to it
        tether.hessian_coo = lambda x, theta: None
    s = RodSystem(cfg, x0=x0, interactions=[tether])
    tr = Simulation(cfg, system=s).run()
    assert tr.ok
    a = tr.arrays()
    Le = 1.0 - 0.5 / (N - 1)
    want = k * px * Le**3 / 3 / (1 + k * Le**3 / 3)
    # tolerance: the discrete cantilever's O(b^2) and the nonlinear O(delta^2) terms, ~1e-4
    assert a["x"][-1, -1, 0] == pytest.approx(want, rel=1e-3)
    assert a["interaction_energy"][-1] == pytest.approx(0.5 * k * (px - a["x"][-1, -1, 0]) ** 2, rel=1e-3)
    assert np.all(np.isfinite(a["motor_torque"]))


class KneeDrive:
    """A motor law defined here: the bacterial motor's torque-speed curve with its knee
    (Chen & Berg 2000), flat at ``tau_s`` up to ``omega_k``, then falling linearly to zero at
    ``omega_0`` (core units, CCW phases). The rotor's balance ``zeta_r w = tau_m(w) + G`` is
    piecewise linear in ``w``: the flat branch while its rate stays below the knee."""

    kind = "knee"
    free = True

    def __init__(self, tau_s, omega_k, omega_0, zeta):
        self.tau_s, self.omega_k, self.omega_0, self.zeta = tau_s, omega_k, omega_0, zeta
        self.slope = tau_s / (omega_0 - omega_k)  # -d tau_m / d w on the falling branch
        self._falling = False

    def rate(self, omega, G_phi):
        w = (self.tau_s + G_phi) / self.zeta
        self._falling = w > self.omega_k
        if self._falling:
            w = (self.slope * self.omega_0 + G_phi) / (self.zeta + self.slope)
        return w

    def mobility(self, omega):
        return 1.0 / (self.zeta + self.slope) if self._falling else 1.0 / self.zeta

    def torque(self, rate, omega):
        return self.tau_s if rate <= self.omega_k else self.slope * (self.omega_0 - rate)


def test_a_motor_law_defined_here_turns_a_rod_at_its_load_line_crossing():
    # a straight rod twirled about its axis without HI: its whole drag is local,
    # zeta_tot = M 8 pi a^3 N (each bead's rotational drag, docs/model.md), so the steady
    # rate solves zeta_tot w = tau_m(w). Parameters put the crossing on the falling branch:
    # w* = slope omega_0 / (zeta_tot + slope), between omega_k and omega_0. Tolerance: the
    # twist's approach to steady twirling decays as exp(-t/tau) with tau ~ zeta_tot L^2/(C N)
    # << the 3 turns run; 1e-6 relative is the step controller's tol (1e-7) with margin
    cfg = load_config("examples/fig4a.toml")
    cfg = cfg.replace(
        filament=dataclasses.replace(cfg.filament, shape="straight", n_beads=21,
                                     pitch_angle_deg=None, turns=None),
        body=dataclasses.replace(cfg.body, enabled=False),
        motor=dataclasses.replace(cfg.motor, protocol=(Phase("ccw", 3.0),)),
        numerics=dataclasses.replace(cfg.numerics, hydrodynamics=False, tol=1e-7))
    probe = RodSystem(cfg)
    zeta_r = cfg.machin * probe.rot_drag[0]
    zeta_tot = cfg.machin * probe.rot_drag.sum()
    tau_s, omega_k, omega_0 = 1.2 * zeta_tot, 0.5, 2.0  # the load line meets the falling part
    drive = KneeDrive(tau_s, omega_k, omega_0, zeta_r)
    expected = drive.slope * omega_0 / (zeta_tot + drive.slope)
    assert omega_k < expected < omega_0
    system = RodSystem(cfg, drive=drive)
    assert system.layout.block("phi").kind == "angle"  # a free motor angle: error-controlled
    traj = Simulation(cfg, system=system).run()
    assert traj.ok
    rate = np.asarray(traj.omega)  # the motor's own rate, recorded every frame
    assert rate[-1] == pytest.approx(expected, rel=1e-6)
    tq = np.asarray(traj.motor_torque)[-1]
    assert tq == pytest.approx(drive.torque(expected, 1.0), rel=1e-5)
