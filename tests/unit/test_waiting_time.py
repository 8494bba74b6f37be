"""Power-law fit of t_c/T = c eps^-beta on synthetic noisy data (oracle: the generating c, beta)."""

from __future__ import annotations

import numpy as np
import pytest

from flagwrap.analysis.critical import RunCache
from flagwrap.analysis.waiting_time import PowerLawFit, default_cw_turns, waiting_time_sweep
from flagwrap.errors import UserInputError


def synthetic(c=0.5, beta=1.0, noise=0.1, n=8, seed=0):
    rng = np.random.default_rng(seed)
    eps = np.geomspace(0.05, 2.0, n)
    return eps, c * eps**-beta * np.exp(noise * rng.standard_normal(n))


def test_exact_data_recovered():
    eps, t = synthetic(noise=0.0)
    f = PowerLawFit().compute(eps, t)
    assert f.c == pytest.approx(0.5, rel=1e-8) and f.beta == pytest.approx(1.0, rel=1e-8)


@pytest.mark.parametrize("seed", range(5))
def test_recovers_within_uncertainty(seed):
    eps, t = synthetic(c=0.7, beta=1.2, noise=0.15, seed=seed)
    f = PowerLawFit().compute(eps, t)
    assert abs(f.beta - 1.2) < 3 * f.beta_err
    assert abs(f.c - 0.7) < 3 * f.c_err
    assert 0 < f.beta_err < 0.5 and f.n == 8


def test_error_bars_are_calibrated():
    """Over many noise draws, ~68 % of 1-sigma intervals contain the truth (t-distribution: a bit less)."""
    hits = 0
    for seed in range(200):
        eps, t = synthetic(noise=0.1, n=10, seed=100 + seed)
        f = PowerLawFit().compute(eps, t, sigma_log=0.1)
        hits += abs(f.beta - 1.0) < f.beta_err
    assert 0.58 < hits / 200 < 0.78


def test_fixed_beta_and_nan_dropped():
    eps, t = synthetic(noise=0.05)
    t[0] = np.nan  # a run that did not buckle
    f = PowerLawFit(fix_beta=1.0).compute(eps, t)
    assert f.n == 7 and f.beta == 1.0 and f.beta_err == 0.0
    assert abs(f.c - 0.5) < 3 * f.c_err


def test_free_threshold_fit():
    mc = 480.0
    eps = np.array([0.1, 0.2, 0.35, 0.6, 1.0, 1.5, 2.0])
    m = (1 + eps) * mc
    t = 0.5 / eps * np.exp(0.03 * np.random.default_rng(1).standard_normal(eps.size))
    f = PowerLawFit().compute(waiting_time=t, machin=m, machin_c0=520.0)
    assert abs(f.machin_c - mc) < 3 * f.machin_c_err + 1.0
    assert abs(f.beta - 1.0) < 3 * f.beta_err + 0.02


def test_guards():
    with pytest.raises(UserInputError):
        PowerLawFit().compute([0.1, 0.2], [5.0, 2.5])  # 2 points, 2 parameters
    with pytest.raises(UserInputError):
        PowerLawFit().compute([-0.1, 0.2, 0.3], [5.0, 2.5, 1.0])
    with pytest.raises(AttributeError):
        PowerLawFit().predict(1.0)


def test_default_cw_turns():
    assert default_cw_turns(2.0) == 10.0
    assert default_cw_turns(0.05) == 35.0


def test_sweep_on_fake_runner(tmp_path):
    from flagwrap.cases import get_case

    def fake(cfg, path):
        eps = cfg.machin / 400.0 - 1
        return {"buckled": True, "waiting_time_turns": 0.5 / eps, "state": "wrapping",
                "run_status": "completed"}

    rows = waiting_time_sweep(get_case("movie7"), 400.0, [0.25, 1.0], cache=RunCache(tmp_path, runner=fake))
    assert [r["waiting_time"] for r in rows] == pytest.approx([2.0, 0.5])
    assert [r["machin"] for r in rows] == pytest.approx([500.0, 800.0])
    assert rows[0]["cw_turns"] == 11.0
