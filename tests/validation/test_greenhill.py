"""Validation of buoyancy against Greenhill's heavy column (flagwrap.analysis.static_buckling).

Oracle: a straight clamped-free column under a uniform load q per length toward its clamp
buckles at q L^3 / A = 7.837 (Greenhill 1881; Timoshenko & Gere 1961, section 2.13). Here a
straight rest shape hangs below the clamp and is made lighter than the fluid, so the model's
own gravity force compresses it; the threshold is found by bisection in G on the sign of the
lowest stiffness eigenvalue at the equilibrium, and the time loop must see the same threshold
(perturbations decay below it and grow above it at the linearised rate).
"""

import numpy as np
import pytest

from flagwrap.analysis.static_buckling import (
    GREENHILL_CLAMPED_FREE,
    critical_gravity,
    equilibrium,
    straight_rod_system,
    with_gravity_number,
)
from flagwrap.io.config import config_from_dict
from flagwrap.simulation import Simulation

from conftest import make_config


def _config(n_beads, machin=283.0, turns=3.0, hi=True):
    d = make_config(machin=machin).to_dict()
    d["filament"]["n_beads"] = n_beads
    d["numerics"]["hydrodynamics"] = hi
    d["motor"] = {"machin": machin, "protocol": [{"direction": "stop", "turns": turns}]}
    return config_from_dict(d)


@pytest.fixture(scope="module")
def thresholds():
    return {N: critical_gravity(_config(N), 5.0, 12.0, rtol=1e-6)[0] for N in (31, 61, 121)}


def test_greenhill_threshold_converges(thresholds):
    # first-order discretisation error from the clamp (the elastic rod starts at the midpoint of
    # the rigid clamped bond, the Voronoi cell of bead 1): G_c(N) = 7.837 (1 - b/2L)^-3 + O(b^2).
    # Richardson extrapolation of N = 61 and 121 removes the O(b) term; its O(b^2) remainder,
    # measured from N = 31/61/121, is < 0.05 %, so 0.2 % is the bisection (1e-6) + remainder
    # with a 4x margin, and an error in the gravity force of 1 % or more fails.
    g61, g121 = thresholds[61], thresholds[121]
    assert 2 * g121 - g61 == pytest.approx(GREENHILL_CLAMPED_FREE, rel=2e-3)
    for N, g in thresholds.items():
        b = 1.0 / (N - 1)
        assert g * (1 - b / 2) ** 3 == pytest.approx(GREENHILL_CLAMPED_FREE, rel=2e-3), N
    # and the plain values approach it from above as O(b)
    assert thresholds[31] > g61 > g121 > GREENHILL_CLAMPED_FREE


def test_threshold_does_not_depend_on_hydrodynamics():
    # a static threshold: the mobility only sets the rates (module docstring of static_buckling)
    a = critical_gravity(_config(31, hi=True), 5.0, 12.0, rtol=1e-6)[0]
    b = critical_gravity(_config(31, hi=False), 5.0, 12.0, rtol=1e-6)[0]
    assert a == pytest.approx(b, rel=1e-5)


@pytest.mark.parametrize("factor", [0.8, 1.2])
def test_time_loop_grows_or_decays_at_the_linear_rate(thresholds, factor):
    # HI off: the mobility is diagonal and constant, so the linearised rates are the eigenvalues
    # of -Mob K; the integrator (tol 1e-5) must reproduce the rate of the lowest lateral
    # mode to 1 % (its O(amplitude^2) nonlinearity at tip offsets <= 1e-3 L is ~1e-6).
    cfg = with_gravity_number(_config(31, machin=1.0, turns=1.0, hi=False), factor * thresholds[31])
    s = straight_rod_system(cfg)
    e = equilibrium(s, n_modes=6)
    n = s.ny - 1
    nb3 = 3 * s.nb
    # the lowest bending mode: the first of the lowest modes that moves the tip sideways
    k = next(i for i in range(6) if np.hypot(*e.modes[nb3 - 3:nb3 - 1, i]) > 1e-3)
    mode = e.modes[:, k] / np.abs(e.modes[:nb3, k]).max()
    # straight rod: bending does not couple to twist and every free bead has the same
    # translational mobility, so the mode's rate is -mu_x times its stiffness eigenvalue
    mu_x = s.mobility_matrix(e.y)[0, 0]
    predicted = -mu_x * e.eigenvalues[k]
    y0 = e.y.copy()
    y0[:n] += 1e-6 * mode
    traj = Simulation(cfg, system=s).run(y0=y0, base=e.base)
    assert traj.ok, traj.message
    a = traj.arrays()
    t = np.asarray(a["t"])
    tip = np.hypot(a["x"][:, -1, 0], a["x"][:, -1, 1])
    sel = t > 0.3 * t[-1]  # after the faster modes of the seed have died out
    measured = np.polyfit(t[sel], np.log(tip[sel]), 1)[0]
    assert np.sign(measured) == np.sign(factor - 1)
    assert measured == pytest.approx(predicted, rel=1e-2)
    assert tip.max() < 1e-2  # stayed linear
