"""Slow physics validations of the full model (run with ``pytest -m slow``).

Oracles: the paper's qualitative claims (buckling only under CW rotation, above a critical
frequency; below it the helix only twirls/whirls). The paper's threshold itself is NOT
reproduced at the printed M = 283 (see docs/model.md): our model's M_c for the Fig. 4(a)
geometry lies between 283 and 600, so the buckling check runs at M = 600 (~2x the paper's
scaling estimate M_c = 0.06 (R/L)^-3 = 142 would be 283; we use the first M we measured to
buckle) and the stable check at M = 71 (0.5 x the paper's M_c).
"""

import dataclasses

import numpy as np
import pytest

from flagwrap.cases import get_case
from flagwrap.params import Phase
from flagwrap.simulation import simulate

pytestmark = pytest.mark.slow


def run_fig4a(machin, ccw=4, cw=10, hi=True):
    cfg = get_case("fig4a")
    motor = dataclasses.replace(cfg.motor, machin=machin,
                                protocol=(Phase("ccw", ccw), Phase("cw", cw)))
    cfg = cfg.replace(motor=motor, numerics=dataclasses.replace(cfg.numerics, hydrodynamics=hi))
    traj = simulate(cfg)
    assert traj.ok, traj.message
    a = traj.arrays()
    turns = a["t"] / (2 * np.pi)
    height = a["x"][:, -1, 2] - a["x"][:, 0, 2]  # core units: L = 1
    return turns, height, a["motor_torque"] * cfg.filament.helix_radius / cfg.filament.length, ccw


def test_fig4a_geometry_buckles_under_cw_above_threshold():
    turns, h, torque, ccw = run_fig4a(600.0)
    hanging = h[0]
    ccw_phase = turns <= ccw
    cw_phase = turns > ccw
    # CCW keeps the helix hanging (whirling only), CW makes the free end rise > 0.2 L
    assert np.max(h[ccw_phase] - hanging) < 0.1
    assert np.max(h[cw_phase] - hanging) > 0.2
    # the buckling torque is of order A/R (paper: peak ~ 0.9-1 A/R)
    assert 0.5 < np.max(-torque[cw_phase]) < 2.0


def test_half_critical_frequency_only_twirls():
    turns, h, torque, ccw = run_fig4a(71.0)
    assert np.all(h < 0)  # free end stays below the clamp
    assert np.max(np.abs(h - h[0])) < 0.1
