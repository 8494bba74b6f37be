"""Waiting-time detector and final-state classifier on synthetic runs with known answers."""

import numpy as np
import pytest

from flagwrap.analysis import BucklingAnalysis, FinalState, WaitingTime, find_switch
from flagwrap.errors import UserInputError

DT = 0.05
T = np.arange(0, 20 + DT / 2, DT)             # t/T; CCW for t <= 10, CW after
OMEGA = np.where(T <= 10.0 + 1e-9, 1.0, -1.0)


def noisy(h, seed=0, whirl=0.01, noise=0.005):
    rng = np.random.default_rng(seed)
    return h + whirl * np.sin(2 * np.pi * T) + noise * rng.standard_normal(T.size)


def test_switch_found():
    assert T[find_switch(T, OMEGA) - 1] == pytest.approx(10.0)
    assert find_switch(T, -np.ones_like(T)) == 0
    with pytest.raises(UserInputError):
        find_switch(T, np.ones_like(T))


@pytest.mark.parametrize("seed", [0, 1, 2])
@pytest.mark.parametrize("t_step", [10.6, 13.5, 17.0])
def test_step_at_known_time_with_noise(seed, t_step):
    h = noisy(np.where(T >= t_step, -0.05, -0.35), seed)
    w = WaitingTime().compute(T, h, OMEGA)
    assert w.buckled
    assert w.switch_turns == pytest.approx(10.0)
    assert w.baseline == pytest.approx(-0.35, abs=0.01)
    assert w.waiting_time == pytest.approx(t_step - 10.0, abs=2.5 * DT)
    c = WaitingTime(onset="crossing").compute(T, h, OMEGA)
    assert c.waiting_time == pytest.approx(t_step - 10.0, abs=0.5)


def test_ramp_onset_and_threshold_independence():
    h = noisy(-0.35 + np.clip(0.1 * (T - 13.0), 0, 0.35), seed=3)
    for thr in (0.1, 0.15, 0.2):
        assert WaitingTime(threshold=thr).compute(T, h, OMEGA).waiting_time == pytest.approx(3.0, abs=0.3)


def test_stable_small_offset_and_spike_are_not_buckling():
    # CW re-twisting offset of 0.03 L (stored M=600 run) and a one-sample spike of 0.5 L
    h = noisy(-0.35 + 0.03 * (T > 10.0))
    h[300] += 0.5
    w = WaitingTime().compute(T, h, OMEGA)
    assert not w.buckled and np.isnan(w.waiting_time) and np.isnan(w.crossing_turns)
    # a transient excursion shorter than hold_turns is rejected
    h2 = noisy(-0.35 + 0.3 * ((T > 14) & (T < 14.6)))
    assert not WaitingTime().compute(T, h2, OMEGA).buckled


def test_guarded_results_and_bad_parameters():
    with pytest.raises(AttributeError):
        WaitingTime().waiting_time
    with pytest.raises(UserInputError):
        WaitingTime(threshold=-1)
    with pytest.raises(UserInputError):
        WaitingTime(onset="eye")
    with pytest.raises(UserInputError):
        FinalState(min_contact_fraction=2)
    with pytest.raises(UserInputError):
        WaitingTime().compute(T[::-1], T, OMEGA)


# ---- final state -------------------------------------------------------------------------
L, N, RC, H = 1.0, 41, 0.2, 1.0


def hanging(n=N):
    s = np.linspace(0, 1, n)
    return np.stack([0.1 * np.cos(12 * s) - 0.1, 0.1 * np.sin(12 * s), -0.9 * s], axis=1)


def wound(k, n=N):
    """Clamp at the origin, then k turns around the body at radius 1.1 R_cell, above z = 0."""
    th = np.linspace(0, 2 * np.pi * k, n - 2)
    coil = np.stack([1.1 * RC * np.cos(th), 1.1 * RC * np.sin(th), 0.25 + 0.05 * th], axis=1)
    return np.vstack([[0, 0, 0], [0.5 * RC, 0, 0.0], coil])


def folded(n=N):
    """Hairpin: down, then back up beside the body on one side (no encircling)."""
    m = n // 2
    down = np.stack([np.full(m, 1.1 * RC), np.zeros(m), np.linspace(0, -0.4, m)], axis=1)
    up = np.stack([np.full(n - m, 1.15 * RC), np.full(n - m, 0.02), np.linspace(-0.4, 0.5, n - m)], axis=1)
    return np.vstack([down, up])


def run_of(final):
    """Hanging in CCW and early CW, the final configuration from t/T = 14 on."""
    x = np.repeat(hanging()[None], T.size, axis=0)
    x[T >= 14] = final
    return x


@pytest.mark.parametrize("k", [1, 2])
def test_wound_filament_is_wrapping(k):
    fs = FinalState().compute(T, run_of(wound(k)), True, RC, H)
    assert fs.state == "wrapping"
    assert fs.winding == pytest.approx(k, abs=0.05)
    assert fs.contact_fraction > 0.9


def test_folded_and_stable_classes():
    fs = FinalState().compute(T, run_of(folded()), True, RC, H)
    assert fs.state == "folding" and fs.winding < 0.1 and fs.contact_fraction > 0.2
    assert FinalState().compute(T, run_of(wound(1)), False, RC, H).state == "stable"
    # a half-turn coil passes the default 0.5-turn criterion only when asked for less
    assert FinalState(min_winding_turns=0.6).compute(T, run_of(wound(0.55)), True, RC, H).state == "folding"


def test_full_analysis_end_to_end():
    x = run_of(wound(1))
    a = BucklingAnalysis().compute(T, x, OMEGA, L, RC, H, torque_reduced=-np.abs(np.sin(T)))
    s = a.summary()
    assert s["state"] == "wrapping" and s["buckled"]
    assert s["waiting_time_turns"] == pytest.approx(4.0, abs=2 * DT)
    assert s["baseline_height"] == pytest.approx(-0.9)
    assert np.isnan(s["perversion_turns"])        # no torsion flip in these shapes
    stable = BucklingAnalysis().compute(T, np.repeat(hanging()[None], T.size, 0), OMEGA, L, RC, H)
    assert stable.summary()["state"] == "stable"
    assert np.isnan(stable.summary()["waiting_time_turns"])


def test_a_rise_that_comes_back_is_buckled_but_not_sustained():
    # the hanging helix lifted rigidly: by 0.3 L from 12 T on (a buckle that lasts), or by a
    # wobble 0.3 L peak to peak (3-turn period, C. insecticola's) decaying to 0.1 L by the
    # end: both cross 0.15 L for over a turn after the switch, only the first ends above it
    lift = {"lasting": np.where(T >= 12, 0.3, 0.0),
            "wobble": np.where(T >= 10, 0.15 * (1 - np.cos(2 * np.pi * (T - 10) / 3))
                               * np.exp(-(T - 10) / 6), 0.0)}
    out = {}
    for name, dz in lift.items():
        x = np.repeat(hanging()[None], T.size, axis=0)
        x[:, 1:, 2] += dz[:, None]  # the clamp stays: the free end's height rises by dz
        out[name] = BucklingAnalysis().compute(T, x, OMEGA, L, RC, H).summary()
    assert out["lasting"]["buckled"] and out["lasting"]["sustained"]
    assert out["wobble"]["buckled"] and not out["wobble"]["sustained"]
    assert out["wobble"]["final_height"] - out["wobble"]["baseline_height"] < 0.15


def test_baseline_is_the_relaxed_ccw_state_even_with_a_stop_phase_before_cw():
    # CCW to 10 T (the free end relaxes from -0.55 to -0.35 L), stop to 12 T, then CW with
    # no change: not buckled. A baseline window ending at the switch saw only the stop phase
    # and fell back to the first frame (-0.55), calling the run buckled at t = 0.
    t = np.arange(0, 20 + 1e-9, 0.05)
    om = np.where(t <= 10, 1.0, np.where(t <= 12, 0.0, -1.0))
    h = -0.35 - 0.2 * np.exp(-t / 0.5)
    w = WaitingTime().compute(t, h, om)
    assert w.baseline == pytest.approx(-0.35, abs=1e-6)
    assert not w.buckled


def test_cw_torque_peak_is_the_most_negative_cw_value():
    # a CCW torque larger in magnitude than the CW one: the peak must still be the CW value
    t = np.arange(0, 20 + 1e-9, 0.05)
    om = np.where(t <= 10, 1.0, -1.0)
    N = 21
    x = np.zeros((t.size, N, 3))
    x[:, :, 2] = -np.linspace(0, 0.35, N)[None, :]
    x[:, 1:, 0] = 0.03
    tq = np.where(t <= 10, 0.9, -0.5)
    tq[t > 15] = -0.3
    s = BucklingAnalysis().compute(t, x, om, 1.0, 0.05, 0.1, tq).summary()
    assert s["torque_peak_reduced"] == -0.5
    assert 0 < s["torque_peak_turns"] <= 0.05 + 1e-9
