"""Filament self-contact (flagwrap.interactions.self_contact): segment distance against brute
force, the gradient against finite differences, segments driven into each other stay apart
and never cross, and the crossing counter counts a crossing."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from flagwrap.interactions.self_contact import (SelfContact, count_crossings, segment_closest,
                                                self_contact_energy_grad)

coord = st.floats(-1.0, 1.0, allow_nan=False)
point = st.tuples(coord, coord, coord).map(np.array)


@settings(max_examples=60, deadline=None)
@given(point, point, point, point)
def test_segment_distance_is_the_minimum_over_both_segments(p0, p1, q0, q1):
    s, t, dx, dy, dz = segment_closest(p0, p1, q0, q1)
    d = np.sqrt(dx * dx + dy * dy + dz * dz)
    assert 0.0 <= s <= 1.0 and 0.0 <= t <= 1.0
    # the returned points are on the segments and d is their distance
    assert np.allclose((p0 + s * (p1 - p0)) - (q0 + t * (q1 - q0)), [dx, dy, dz], atol=1e-12)
    # no pair of sampled points is closer (grid 1/200: d can exceed the sample minimum by
    # at most the grid's reach, |p1 - p0| / 400 + |q1 - q0| / 400)
    u = np.linspace(0.0, 1.0, 201)
    P = p0 + u[:, None] * (p1 - p0)
    Q = q0 + u[:, None] * (q1 - q0)
    brute = np.sqrt(((P[:, None, :] - Q[None, :, :]) ** 2).sum(-1)).min()
    slack = (np.linalg.norm(p1 - p0) + np.linalg.norm(q1 - q0)) / 400 + 1e-12
    assert d <= brute + 1e-12 and brute - d <= slack


def _folded_chain(n=16, gap=0.025):
    """A hairpin: two straight arms ``gap`` apart (a = 0.01: inside the cut-off 0.03)."""
    half = n // 2
    arm = np.linspace(0.0, 1.0, half)
    up = np.column_stack([arm, np.zeros(half), np.zeros(half)])
    down = np.column_stack([arm[::-1], np.full(half, gap), np.zeros(half)])
    x = np.vstack([up, down])
    rng = np.random.default_rng(3)
    return x + 1e-3 * rng.standard_normal(x.shape)


def test_gradient_matches_finite_differences():
    sc = SelfContact(radius=0.01, bond=0.14, range=1.0, strength=1.0)
    x = _folded_chain()
    g = np.zeros_like(x)
    E, dmin = sc.energy_grad(x, g)
    assert E > 0 and dmin < sc.cut  # the arms interact
    h = 1e-7
    num = np.zeros_like(x)
    for k in range(x.shape[0]):
        for c in range(3):
            xp, xm = x.copy(), x.copy()
            xp[k, c] += h
            xm[k, c] -= h
            num[k, c] = (sc.energy_grad(xp, np.zeros_like(x))[0] - sc.energy_grad(xm, np.zeros_like(x))[0]) / (2 * h)
    # central differences: error ~ h^2 U''' ; relative 1e-5 of the largest component
    assert np.abs(num - g).max() <= 1e-5 * np.abs(g).max()
    # Newton's third law: the pair forces sum to zero
    assert np.abs(g.sum(axis=0)).max() <= 1e-9 * np.abs(g).max()


@pytest.mark.parametrize("push", [10.0, 1000.0])
def test_segments_driven_into_each_other_stay_apart_and_never_cross(push):
    # two crossed segments, one above the other, pushed together by a constant force on each
    # bead (overdamped, explicit Euler with a step far below the contact's relaxation time)
    a = 0.01
    x = np.array([[-0.5, 0.0, 0.05], [0.5, 0.0, 0.05],       # segment 0 (beads 0-1)
                  [0.5, 0.0, 0.6], [0.0, 0.5, 0.6],          # a far-away link (beads 2-3)
                  [0.0, -0.5, -0.05], [0.0, 0.5, -0.05]])    # segment 4 (beads 4-5)
    sc = SelfContact(radius=a, bond=0.1, range=1.0, strength=1.0)
    sc.exclude = 1  # only the two crossed segments are non-neighbours here
    F = np.zeros_like(x)
    F[[0, 1], 2] = -push
    F[[4, 5], 2] = +push
    moving = [0, 1, 4, 5]
    v0 = np.sign((x[4] - x[0]) @ np.cross(x[1] - x[0], x[5] - x[4]))
    dmin_seen = np.inf
    dt = 1e-8 if push > 100 else 1e-6
    for _ in range(20000):
        g = np.zeros_like(x)
        _, _ = sc.energy_grad(x, g)
        x[moving] += dt * (F - g)[moving]
        s, t, dx, dy, dz = segment_closest(x[0], x[1], x[4], x[5])
        dmin_seen = min(dmin_seen, np.sqrt(dx * dx + dy * dy + dz * dz))
        assert np.sign((x[4] - x[0]) @ np.cross(x[1] - x[0], x[5] - x[4])) == v0  # not crossed
    assert dmin_seen > 2 * a  # the surfaces never touch
    assert dmin_seen < sc.cut  # and the contact did act (they were pushed into range)


def test_crossing_counter_counts_a_pass_through_and_nothing_else():
    frames = []
    for z in np.linspace(0.05, -0.05, 11):  # segment 2 (beads 2-3) passes down through segment 0
        frames.append([[-0.5, 0.0, 0.0], [0.5, 0.0, 0.0], [0.6, 0.0, 0.3], [0.0, -0.5, z],
                       [0.0, 0.5, z], [1.0, 1.0, 1.0]])
    X = np.array(frames)
    # the chain's segments here: 0 (0-1), 1 (1-2), 2 (2-3), 3 (3-4), 4 (4-5); 0 and 3 cross
    assert count_crossings(X, exclude=1, near=0.2) == 1
    assert count_crossings(X[:5], exclude=1, near=0.2) == 0  # not yet through
    still = np.repeat(X[:1], 5, axis=0)
    assert count_crossings(still, exclude=1, near=0.2) == 0


def test_kernel_skips_contour_neighbours():
    # a straight chain with bonds shorter than the cut-off: neighbours are excluded, no energy
    x = np.column_stack([np.linspace(0, 1, 51), np.zeros(51), np.zeros(51)])
    sc = SelfContact(radius=0.01, bond=0.02, range=1.0)
    assert sc.exclude == 3
    g = np.zeros_like(x)
    E, dmin = self_contact_energy_grad(x, sc.cut, sc.sigma, sc.eps, sc.c2, sc.first(len(x) - 1), g,
                                     sc.skip(len(x) - 1))
    assert E == 0.0 and not g.any() and dmin >= 0.02 * (sc.exclude) - 1e-12


def test_crossing_counter_over_two_filaments_counts_their_pass_through_not_the_join():
    # filament A: beads 0-1 along x; filament B: beads 2-3 along y, passing down through A.
    # As one chain, segment 1 (the join 1-2) would be a segment; as two filaments it is not,
    # and the pass-through of B's only segment through A's is counted once
    frames = []
    for z in np.linspace(0.05, -0.05, 11):
        frames.append([[-0.5, 0.0, 0.0], [0.5, 0.0, 0.0], [0.0, -0.5, z], [0.0, 0.5, z]])
    X = np.array(frames)
    assert count_crossings(X, exclude=1, near=0.2, chains=[2, 2]) == 1
    # the neighbour exclusion holds within a filament only: with exclude = 5 the pair is
    # still counted (different filaments), where one chain of 4 beads would skip it
    assert count_crossings(X, exclude=5, near=0.2, chains=[2, 2]) == 1
    assert count_crossings(X, exclude=5, near=0.2) == 0
    with pytest.raises(ValueError, match="do not add up"):
        count_crossings(X, chains=[2, 3])
