"""Stereo triangulation (SI "3D tracking"): oracle = synthetic projections of known points
through the forward model, and Snell's law reversibility."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st_

from flagwrap.errors import UserInputError
from flagwrap.experiment import triangulation as tr

UNIFORM = tr.StereoRig(1.0, 1.2, 1680.0)
TANK = tr.StereoRig(1.0, 1.2, 1680.0, wall_1=0.82, wall_2=1.0)  # walls 0.18 / 0.20 from the origin

coord = st_.floats(-0.15, 0.15, allow_nan=False)
points = st_.lists(st_.tuples(coord, coord, coord), min_size=1, max_size=8)


@settings(max_examples=60, deadline=None)
@given(points)
@pytest.mark.parametrize("rig", [UNIFORM, TANK], ids=["uniform", "refracting"])
def test_triangulation_recovers_points(rig, pts):
    # oracle: forward projection of known points; tolerance 1e-9 relative to the tank scale (acceptance)
    P = np.array(pts)
    X, gap = tr.triangulate(rig, tr.project(rig, P), return_gap=True)
    assert np.max(np.abs(X - P)) <= 1e-9 * 0.15
    assert np.all(gap < 1e-9)


@settings(max_examples=40, deadline=None)
@given(points)
@pytest.mark.parametrize("rig", [UNIFORM, TANK], ids=["uniform", "refracting"])
def test_corrected_si_closed_form_agrees(rig, pts):
    # oracle: the general ray intersection; the closed form divides by tan(theta_2), so points near
    # the camera height are excluded; tolerance 1e-9 relative
    P = np.array(pts)
    P = P[np.abs(P[:, 2]) > 1e-3]
    if P.size == 0:
        return
    X = tr.triangulate_closed_form(rig, tr.project(rig, P))
    assert np.max(np.abs(X - P)) <= 1e-9 * 0.15


@settings(max_examples=100, deadline=None)
@given(st_.floats(0.0, 1.5), st_.floats(1.0, 1.6), st_.floats(1.0, 1.6))
def test_snell_round_trip(angle, n1, n2):
    # oracle: Snell's law is its own inverse with swapped indices; tolerance: arcsin round-off
    if n1 * math.sin(angle) > n2:
        with pytest.raises(UserInputError):
            tr.snell_angle(angle, n1, n2)
        return
    back = float(tr.snell_angle(tr.snell_angle(angle, n1, n2), n2, n1))
    assert back == pytest.approx(angle, abs=1e-9)
    assert n1 * math.sin(angle) == pytest.approx(n2 * math.sin(float(tr.snell_angle(angle, n1, n2))), abs=1e-12)


def test_refraction_matters():
    # oracle: ignoring the wall shifts an off-axis point by millimetres (SI: "corrections ... subtle")
    P = np.array([[0.05, 0.08, 0.1]])
    wrong = tr.triangulate(UNIFORM, tr.project(TANK, P))
    assert np.max(np.abs(wrong - P)) > 1e-4


@pytest.mark.parametrize("rig", [UNIFORM, TANK], ids=["uniform", "refracting"])
def test_calibration_recovers_rig(rig):
    # oracle: synthetic known points; noise-free -> 1e-9 relative; 0.3 px noise -> within 4 sigma
    rng = np.random.default_rng(3)
    P = rng.uniform(-0.1, 0.1, (12, 3))
    guess = tr.StereoRig(1.05, 1.1, 1600.0, wall_1=rig.wall_1, wall_2=rig.wall_2)
    exact = tr.calibrate(guess, P, tr.project(rig, P))
    assert exact.values == pytest.approx((1.0, 1.2, 1680.0), rel=1e-9)
    noisy = tr.calibrate(guess, P, tr.project(rig, P) + rng.normal(0, 0.3, (12, 4)))
    for v, e, true in zip(noisy.values, noisy.errors, (1.0, 1.2, 1680.0)):
        assert abs(v - true) < 4 * e


def test_rig_validation():
    with pytest.raises(UserInputError, match="wall_1"):
        tr.StereoRig(1.0, 1.0, 1680.0, wall_1=2.0, wall_2=0.5)
    with pytest.raises(UserInputError, match="both"):
        tr.StereoRig(1.0, 1.0, 1680.0, wall_1=0.5)
    with pytest.raises(UserInputError, match="behind"):
        tr.project(UNIFORM, [[2.0, 0.0, 0.0]])
