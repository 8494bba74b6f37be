"""Observables on synthetic geometries with known answers (oracles: closed forms)."""

import numpy as np
import pytest

from flagwrap import observables as o
from flagwrap.errors import UserInputError


def helix(n, R=1.0, c=0.3, turns=3.0, sign=+1, z0=0.0, x0=0.0):
    """Helix (x0 + R cos s, R sin s, z0 + sign c s); sign=+1 right-handed."""
    s = np.linspace(0, 2 * np.pi * turns, n)
    return np.stack([x0 + R * np.cos(s), R * np.sin(s), z0 + sign * c * s], axis=1)


def test_free_end_height_and_tip():
    x = np.zeros((2, 5, 3))
    x[:, :, 2] = -np.linspace(0, 2.0, 5)
    x[1, -1] = [0.3, 0.4, -0.5]
    np.testing.assert_allclose(o.free_end_height(x, 2.0), [-1.0, -0.25])
    np.testing.assert_allclose(o.tip_trajectory(x, 2.0)[1], [0.15, 0.2, -0.25])
    with pytest.raises(UserInputError):
        o.free_end_height(x, 0.0)


def test_torsion_of_helix_matches_closed_form_and_sign():
    R, c = 1.0, 0.3
    rh = helix(400, R, c, sign=+1)
    tau = o.discrete_torsion(rh)
    np.testing.assert_allclose(tau, c / (R**2 + c**2), rtol=1e-3)
    assert np.all(o.local_handedness(rh) == 1)
    assert np.all(o.local_handedness(helix(100, R, c, sign=-1)) == -1)
    # straight line: torsion undefined -> handedness 0
    line = np.stack([np.zeros(10), np.zeros(10), np.arange(10.0)], axis=1)
    assert np.all(o.local_handedness(line) == 0)


def perverted(n, p, R=1.0, c=0.3):
    """LH helix for beads 0..p, mirrored (RH) from bead p on, continuous at bead p."""
    s = np.arange(n) * 0.4
    sp = s[p]
    # LH: (R cos s, R sin s, -c s) (angle grows as z decreases); RH: angle runs back
    ang = np.where(s <= sp, s, 2 * sp - s)
    return np.stack([R * np.cos(ang), R * np.sin(ang), -c * s], axis=1)


@pytest.mark.parametrize("p", [8, 15, 30])
def test_perversion_at_known_bead(p):
    x = perverted(50, p)
    h = o.local_handedness(x)
    assert h[0] == -1 and h[-1] == 1
    assert abs(o.perversions(h)[0] - p) <= 1
    assert abs(int(o.perversion_index(h)) - p) <= 1
    # one misread bond (noise) does not create or move a perversion
    h2 = h.copy()
    h2[3] = -h2[3] if p > 8 else h2[3]
    h2[40] = -h2[40]
    assert abs(int(o.perversion_index(h2)) - p) <= 1
    assert o.perversions(h2) == o.perversions(h)


def test_no_perversion_in_homochiral_helix_and_rh_section():
    h = o.local_handedness(helix(60, sign=-1))
    assert o.perversion_index(h) == -1 and o.perversions(h) == []
    assert o.right_handed_fraction(h) == 0.0
    # LH | RH section | LH (the stored M=600 runs): two kinks
    seq = np.array([-1] * 10 + [1] * 8 + [-1] * 20)
    assert o.perversions(seq) == [11, 19]
    frames = np.stack([seq, -np.ones_like(seq)])
    np.testing.assert_array_equal(o.perversion_index(frames), [11, -1])


@pytest.mark.parametrize("k", [1, 2, 3])
def test_winding_k_turns_around_cylinder(k):
    x = helix(40 * k + 1, R=1.2, c=0.05, turns=k, z0=0.5)
    np.testing.assert_allclose(o.winding_turns(x), k, atol=1e-12)
    np.testing.assert_allclose(o.winding_turns(x[::-1]), -k, atol=1e-12)
    W = o.winding_angle(x)
    assert W[0] == 0 and W[-1] == pytest.approx(2 * np.pi * k)
    # masked beads do not count
    m = np.ones(len(x), bool)
    m[: len(x) // 2] = False
    assert 0 < o.winding_turns(x, m) < k


def test_body_distance_known_points():
    Rc, H = 1.0, 5.0
    pts = np.array([
        [0, 0, -0.3],          # below the cap bottom
        [1.2, 0, 3.0],         # beside the cylinder
        [0, 0, 1.0],           # cap centre (inside)
        [0, 0, 6.5],           # above the top face
        [0.6, 0.8, 1.0 + 0.2],  # beside, just above the cap equator
    ])
    np.testing.assert_allclose(o.body_distance(pts, Rc, H), [0.3, 0.2, -1.0, 0.5, 0.0], atol=1e-12)
    # time axis is kept
    assert o.body_distance(np.stack([pts, pts]), Rc, H).shape == (2, 5)
    m = o.near_body_mask(pts[None], Rc, H, 0.25, first_bead=0)
    np.testing.assert_array_equal(m[0], [False, True, True, False, True])
    assert o.near_body_fraction(m, first_bead=0)[0] == pytest.approx(0.6)


def test_torque_helpers():
    np.testing.assert_allclose(o.reduced_torque([2.0], 0.5, 4.0), [0.25])
    t = np.arange(0, 5, 0.1)
    tq = -np.sin(t)
    v, when = o.torque_peak(t, tq, start=3.0)
    sel = t >= 3.0
    assert v == pytest.approx(tq[sel][np.argmax(np.abs(tq[sel]))]) and when >= 3.0
    assert o.plateau_value(t, np.r_[np.zeros(40), np.ones(10)], 0.8) == 1.0
    assert np.isnan(o.torque_peak(t, tq, start=10)[0])


def test_cw_torque_peak_is_the_most_negative_value_after_the_switch():
    from flagwrap.observables import cw_torque_peak

    t = np.arange(0.0, 4.01, 0.5)
    tq = np.array([0.9, 0.9, 0.9, 0.9, 0.9, -0.3, -0.7, -0.5, -0.6])  # switch at t = 2
    assert cw_torque_peak(t, tq, 2.0) == (-0.7, 1.0)
    assert np.isnan(cw_torque_peak(t, tq, 4.0)[0])


def test_free_end_heights_of_flagella_laid_one_after_the_other():
    # two chains of 3 beads: (z(L) - z(0)) / L of each
    x = np.array([[0, 0, 0], [0, 0, -1], [0, 0, -2], [5, 0, 1], [5, 0, 0.5], [5, 0, 0.0]], float)
    two = [slice(0, 3), slice(3, 6)]
    np.testing.assert_allclose(o.free_end_heights(x, 2.0, two), [-1.0, -0.5])
    np.testing.assert_allclose(o.free_end_heights(x[None], 2.0), [[0.0]])  # one chain of 6
    with pytest.raises(ValueError, match="do not fit"):
        o.free_end_heights(x, 2.0, [slice(0, 3), slice(3, 8)])
