"""Issue-4 figure functions on tiny synthetic run datasets (fast; oracle: files written, labels set)."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

from flagwrap.analysis.waiting_time import PowerLawFit
from flagwrap.plotting import figures


def fake_run(rise_at=None, n=6, ccw=2.0, cw=3.0, dt=0.05, L=0.4):
    """A helix-like bead chain hanging at h = -0.35 L whose tip rises 0.35 L after `rise_at` CW turns."""
    turns = np.arange(0, ccw + cw + dt / 2, dt)
    omega = np.where(turns <= ccw, 1.0, -1.0)
    s = np.linspace(0, 1, n)
    h = np.full(turns.shape, -0.35)
    if rise_at is not None:
        h = h + 0.35 * np.clip((turns - ccw - rise_at) / 0.5, 0, 1)
    pos = np.zeros((turns.size, n, 3))
    ang = 2 * np.pi * turns
    pos[:, :, 0] = 0.03 * np.cos(ang)[:, None] * s
    pos[:, :, 1] = 0.03 * np.sin(ang)[:, None] * s
    pos[:, :, 2] = (h[:, None] * s) * L
    tq = np.where(omega > 0, 0.3, -0.5) + 0.01 * np.sin(ang)
    return xr.Dataset(
        {"turns": ("time", turns), "omega": ("time", omega), "position": (("time", "bead", "xyz"), pos),
         "motor_torque_reduced": ("time", tq)},
        attrs={"length": L})


def _labels(fig):
    return [ax.get_xlabel() + ax.get_ylabel() for ax in fig.axes]


def test_fig4(tmp_path):
    runs = {(0.85, True): fake_run(), (0.85, False): fake_run(),
            (2.05, True): fake_run(rise_at=1.0), (2.05, False): fake_run(rise_at=0.5)}
    fig = figures.plot_fig4(runs, tmp_path / "f4")
    assert (tmp_path / "f4.png").stat().st_size > 0 and (tmp_path / "f4.pdf").stat().st_size > 0
    labs = _labels(fig)
    assert any("N_m R/A" in s for s in labs) and any("z(L)" in s for s in labs)
    # the data drawn are the runs': (c) every run's torque against turns, (d) the largest
    # ratio's free-end heights, which start at -0.35 and rise to 0 one CW turn (HI) and half
    # a turn (no HI) after the switch at 2 turns (fake_run's construction)
    ac, ad = fig.axes[0], fig.axes[1]
    torques = [ln for ln in ac.lines if len(ln.get_xdata()) > 2]
    assert len(torques) == 4
    for ln in torques:
        np.testing.assert_allclose(ln.get_ydata(), runs[(0.85, True)]["motor_torque_reduced"])
    heights = {ln.get_label(): ln for ln in ad.lines if len(ln.get_xdata()) > 2}
    assert set(heights) == {"with HI", "without HI"}
    for label, rise in (("with HI", 1.0), ("without HI", 0.5)):
        t, h = heights[label].get_xdata(), heights[label].get_ydata()
        np.testing.assert_allclose(h[t <= 2.0], -0.35, atol=1e-12)
        np.testing.assert_allclose(h[t >= 2.0 + rise + 0.5], 0.0, atol=1e-12)
        assert np.all(h[(t > 2.0 + rise + 0.01) & (t < 2.0 + rise + 0.49)] > -0.35)


def test_fig6(tmp_path):
    eps = np.array([0.1, 0.25, 0.5, 1.0, 2.0])
    tc = 0.5 / eps * np.exp(0.05 * np.random.default_rng(0).standard_normal(eps.size))
    tc[0] = np.nan
    fit = PowerLawFit().compute(eps, tc)
    fig = figures.plot_fig6(eps, tc, fit, tmp_path / "f6")
    assert (tmp_path / "f6.png").is_file() and (tmp_path / "f6.pdf").is_file()
    assert "epsilon" in fig.axes[0].get_xlabel() and "t_c/T" in fig.axes[0].get_ylabel()
    inset = fig.axes[0].child_axes[0]
    assert inset.get_xscale() == "log" and inset.get_yscale() == "log"


def test_figS7(tmp_path):
    runs = [(1.2, fake_run(rise_at=2.0), 2.0), (2.0, fake_run(rise_at=0.5), 0.5), (0.9, fake_run(), np.nan)]
    fig = figures.plot_figS7(runs, tmp_path / "s7")
    assert (tmp_path / "s7.png").is_file()
    ax = fig.axes[0]
    assert len([ln for ln in ax.lines if ln.get_marker() == "v"]) == 2


def test_registered():
    from flagwrap.cli.figure import FIGURES

    for name in ("fig4", "fig6", "figS7"):
        assert name in FIGURES


@pytest.fixture(autouse=True)
def _close():
    yield
    import matplotlib.pyplot as plt

    plt.close("all")


def test_departure_time():
    from flagwrap.analysis.waiting_time import departure_time

    ds = fake_run(rise_at=1.0)  # linear rise of 0.35 L over 0.5 T starting 1 T after the switch
    td = departure_time(ds)
    # 1-turn centred mean reaches +0.05 L about half a window before the raw ramp does
    assert 0.5 < td < 1.3
    assert np.isnan(departure_time(fake_run()))


def test_fig6_fits_count_only_the_times_a_power_law_can_use():
    # t_c = 0 (buckled at the switch) is finite but dropped by PowerLawFit: counting it let
    # figure fig6 / figS7 call a 3-point fit on 1 usable point and abort
    from flagwrap.errors import UserInputError

    tc = np.array([2.0, 0.0, 0.0, np.nan])
    assert figures._n_fittable(tc) == 1
    with pytest.raises(UserInputError):
        PowerLawFit().compute(np.array([0.1, 0.5, 1.0, 2.0]), tc)
