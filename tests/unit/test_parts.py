"""A system of several filaments (flagwrap.system.parts): each on its own motor and anchor,
one mobility over all beads. Oracles: the single filament (far apart, HI off), the RPY far
field (HI on), the symmetry of a symmetric tuft, the sum of the motors' torques."""

import dataclasses
import math

import numpy as np
import pytest

from flagwrap.body.cell_body import CappedCylinder
from flagwrap.errors import UserInputError
from flagwrap.params import CellBody
from flagwrap.simulation import Simulation
from flagwrap.system.parts import Placement, cap_placement
from flagwrap.system.rod_system import RodSystem, SeveralFilaments
from conftest import make_config, paper_filament


def _cfg(hi=False, body=False, n_beads=21, protocol=(("ccw", 0.3), ("cw", 0.2)), **kw):
    cfg = make_config(machin=283.0, protocol=protocol, hi=hi,
                      filament=paper_filament(n_beads=n_beads), **kw)
    cfg = cfg.replace(body=dataclasses.replace(cfg.body, enabled=body),
                      initial=dataclasses.replace(cfg.initial, perturbation=0.004, seed=3))
    return cfg


def _run(cfg, placements=None):
    system = RodSystem(cfg, placements=placements)
    return system, Simulation(cfg, system=system).run()


def test_one_placement_at_the_origin_is_the_single_filament():
    cfg = _cfg()
    a = RodSystem(cfg)
    b = RodSystem(cfg, placements=[Placement()])
    y = a.initial_y()
    assert np.array_equal(y, b.initial_y()) and a.layout.size == b.layout.size
    assert np.array_equal(a.forces(y, a.frames0).G, b.forces(y, b.frames0).G)


def test_two_filaments_far_apart_without_hi_are_each_the_single_filament():
    # HI off: nothing couples them but the layout, the shared step sizes and the banded LU
    # of the whole system; their trajectories are the single run's to rounding (1e-12 L).
    # Unperturbed (filament k would take seed + k: two different filaments)
    cfg = _cfg(hi=False)
    cfg = cfg.replace(initial=dataclasses.replace(cfg.initial, perturbation=0.0))
    _, one = _run(cfg)
    d = np.array([3.0, 0.0, 0.0])  # 3 L apart, beyond any contact
    s, two = _run(cfg, [Placement(), Placement(origin=tuple(d))])
    assert one.ok and two.ok and len(one.t) == len(two.t)
    x1, x2 = np.asarray(one.x), np.asarray(two.x)
    N = s.parts[0].N
    np.testing.assert_allclose(x2[:, :N], x1, atol=1e-12, rtol=0)
    np.testing.assert_allclose(x2[:, N:] - d, x1, atol=1e-12, rtol=0)
    # the recorded torque is the two motors' sum
    np.testing.assert_allclose(np.asarray(two.motor_torque), 2 * np.asarray(one.motor_torque),
                               rtol=1e-9)


def test_hi_between_two_filaments_is_the_rpy_far_field():
    # the second filament's beads move the first one's through the RPY tensor. Far away that
    # is a multipole series in 1/d: the Stokeslet of the second filament's net force F (the
    # clamp's reaction, non-zero off the rest shape), dv = (I + e e) F / (8 pi M d) for every
    # bead of the first, then its force dipole, ~1/d^2. So |dv| falls with slope -1 and
    # |dv - Stokeslet| with slope -2 (fits over d = 250..1000 L; the next orders move the
    # slopes by O(l/d) with l ~ 30 L the dipole's length: 0.05)
    cfg = _cfg(hi=True)
    single = RodSystem(cfg)
    y1 = single.initial_y()
    v1 = single.velocity(y1, single.forces(y1, single.frames0), 1.0)[single.sl_x]
    ds = np.array([250.0, 500.0, 1000.0])
    dev, rest = [], []
    for d in ds:
        s = RodSystem(cfg, placements=[Placement(), Placement(origin=(d, 0.0, 0.0))])
        y = s.initial_y()
        info = s.forces(y, s.frames0)
        v = s.velocity(y, info, 1.0)[s.sl_x]
        n = v1.size
        dv = (v[:n] - v1).reshape(-1, 3)
        F = info.G[s.sl_x][n:].reshape(-1, 3).sum(axis=0)
        e = np.array([1.0, 0.0, 0.0])
        stokeslet = (F + e * (e @ F)) / (8 * math.pi * cfg.machin * d)
        dev.append(np.linalg.norm(dv))
        rest.append(np.linalg.norm(dv - stokeslet))
    assert np.polyfit(np.log(ds), np.log(dev), 1)[0] == pytest.approx(-1.0, abs=0.05), dev
    assert np.polyfit(np.log(ds), np.log(rest), 1)[0] == pytest.approx(-2.0, abs=0.05), rest


def _tuft(cfg, n, polar_deg=35.0):
    Rc = cfg.body.resolved_radius(cfg.filament.helix_radius) / cfg.filament.length
    return [cap_placement(Rc, math.radians(polar_deg), 2 * math.pi * k / n) for k in range(n)]


def test_anchors_sit_on_the_cap_with_the_motor_axis_along_the_normal():
    cfg = _cfg(body=True)
    s = RodSystem(cfg, placements=_tuft(cfg, 3))
    body = s.body
    assert isinstance(body, CappedCylinder)
    for p in s.parts:
        # the anchor bead on the surface; the motor axis along the outward normal there
        assert abs(body.distance(p.x0[:1])[0]) < 1e-12
        n = p.joint.origin - np.array([0.0, 0.0, body.radius])
        np.testing.assert_allclose(p.joint.axis, n / np.linalg.norm(n), atol=1e-12)
        assert np.all(body.distance(p.x0[p.nc:]) > 0)


def test_a_symmetric_pair_on_the_body_keeps_its_symmetry():
    # two flagella at azimuths 0 and pi on the pole cap, HI on, transparent body: the whole
    # problem is invariant under the half turn about the body axis, so the run is too (the
    # perturbation is off: it would break the symmetry). Not to rounding: the coloured
    # Jacobian in W differences Cartesian components, so W is not rotation covariant and the
    # two halves differ at the steps' local error, which the controller holds to tol
    cfg = _cfg(hi=True, body=True, protocol=(("ccw", 0.5), ("cw", 0.5)))
    cfg = cfg.replace(initial=dataclasses.replace(cfg.initial, perturbation=0.0))
    s, tr = _run(cfg, _tuft(cfg, 2))
    assert tr.ok
    x = np.asarray(tr.x)
    N = s.parts[0].N
    half = np.diag([-1.0, -1.0, 1.0])
    np.testing.assert_allclose(x[:, N:], x[:, :N] @ half.T, atol=cfg.numerics.tol, rtol=0)
    assert np.abs(x[-1, N:] - x[0, N:]).max() > 1e-3  # and they moved


def test_single_filament_attributes_refuse_by_name_on_several():
    cfg = _cfg()
    s = RodSystem(cfg, placements=[Placement(), Placement(origin=(1.0, 0.0, 0.0))])
    for name in ("joint", "rest", "nc", "ec"):
        with pytest.raises(SeveralFilaments, match=f"RodSystem.{name}: this system has 2"):
            getattr(s, name)


def test_several_filaments_refuse_a_torque_motor():
    cfg = _cfg()
    cfg = cfg.replace(motor=dataclasses.replace(cfg.motor, kind="torque", stall_torque=1e-4))
    with pytest.raises(UserInputError, match="motor.kind = 'torque': several flagella"):
        RodSystem(cfg, placements=[Placement(), Placement(origin=(1.0, 0.0, 0.0))])


def test_placement_turns_the_default_axis_onto_the_given_one():
    rng = np.random.default_rng(7)
    for _ in range(5):
        a = rng.standard_normal(3)
        p = Placement.from_axis((0.1, 0.2, 0.3), a, spin=rng.uniform(0, 6))
        np.testing.assert_allclose(p.axis, a / np.linalg.norm(a), atol=1e-13)
        np.testing.assert_allclose(p.R @ p.R.T, np.eye(3), atol=1e-13)
        assert np.linalg.det(p.R) == pytest.approx(1.0)
    with pytest.raises(ValueError, match="motor axis"):
        Placement.from_axis((0, 0, 0), (0, 0, 0))
