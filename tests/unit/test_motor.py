"""Motor protocol and the physics of the two rotation senses."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from flagwrap.motor.protocol import Schedule
from flagwrap.params import Numerics, Phase
from flagwrap.simulation import Simulation

from conftest import make_config, paper_filament


def test_schedule_piecewise_and_angle():
    s = Schedule((Phase("ccw", 2), Phase("cw", 1, speed=2.0), Phase("stop", 0.5)))
    assert s(0.1) == 1.0 and s(4 * math.pi + 0.1) == -2.0 and s(5 * math.pi + 0.1) == 0.0
    assert s.t_end == pytest.approx(2 * math.pi * 2 + 2 * math.pi * 0.5 + 2 * math.pi * 0.5)
    assert s.angle(s.t_end) == pytest.approx(2 * math.pi * (2 - 1))


def mean_torsion(x, lo, hi):
    """Mean discrete torsion (signed turning of the binormal per length) of vertices lo..hi."""
    e = np.diff(x, axis=0)
    b = np.cross(e[:-1], e[1:])
    b /= np.linalg.norm(b, axis=1)[:, None]
    t = e[1:-1] / np.linalg.norm(e[1:-1], axis=1)[:, None]
    ang = np.arctan2(np.einsum("ij,ij->i", np.cross(b[:-1], b[1:]), t),
                     np.einsum("ij,ij->i", b[:-1], b[1:]))
    return float(np.mean(ang[lo:hi] / np.linalg.norm(e[1:-1], axis=1)[lo:hi]))


def test_ccw_keeps_left_handed_helix_and_cw_unwinds_it_near_motor():
    # a left-handed helix has negative torsion. Seen from the free end, CCW rotation makes the
    # base lead the drag-retarded distal part in the sense that adds turns (overwinds: |tau| up),
    # CW removes turns (unwinds: |tau| down) -- the paper's mechanism of the CW instability.
    cfg = make_config(machin=283, protocol=(("ccw", 1.5), ("cw", 1.5)),
                      filament=paper_filament(n_beads=31), numerics=Numerics(save_every=0.5))
    traj = Simulation(cfg).run()
    assert traj.ok, traj.message
    x = np.asarray(traj.x)
    t = np.asarray(traj.t) / (2 * math.pi)
    rest = mean_torsion(x[0], 2, 14)
    ccw = mean_torsion(x[np.argmin(abs(t - 1.5))], 2, 14)
    cw = mean_torsion(x[-1], 2, 14)
    assert rest < 0 and ccw < 0 and cw < 0  # still left-handed on average (no buckling here)
    assert ccw < rest * 1.05  # overwound by more than 5 %
    assert cw > rest * 0.95  # unwound by more than 5 %


@given(phi=st.floats(-50.0, 50.0),
       axis=st.tuples(*[st.floats(-1.0, 1.0)] * 3).filter(lambda a: np.linalg.norm(a) > 0.1))
@settings(max_examples=50, deadline=None)
def test_clamp_positions_are_rotations_about_the_motor_axis(phi, axis):
    """The precomputed Rodrigues split equals the rotation matrix (an independent formula)."""
    from flagwrap.geometry.frames import rotation_matrix
    from flagwrap.joints.clamp import AxialClamp

    x0 = np.array([[0.1, -0.2, 0.3], [0.4, 0.5, -0.6], [1.0, 1.0, 1.0]])
    clamp = AxialClamp(x0, np.zeros(2), axis=axis)
    Rm = rotation_matrix(np.asarray(axis), phi)
    np.testing.assert_allclose(clamp.positions(phi), x0[:2] @ Rm.T, rtol=0, atol=1e-13)
