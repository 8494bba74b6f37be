"""Viscosity (SI): oracle = the SI's printed measurements and synthetic data of known parameters."""

import numpy as np
import pytest

from flagwrap.errors import UserInputError
from flagwrap.experiment import viscosity as vis


def test_sphere_reproduces_si_value():
    # oracle: SI, eta = 1.14 +- 0.01 Pa s from U = 73.7 +- 0.8 mm/s; tolerance = printed digits
    r = vis.sphere_viscosity(73.7e-3, 2.5e-3, 7420.0, 1250.0, velocity_error=0.8e-3)
    assert round(r.viscosity, 2) == 1.14
    assert round(r.viscosity_error, 2) == 0.01
    # and the inverse: U = 73.7 mm/s from eta = 1.14 Pa s (printed to 3 digits -> 0.5 % tolerance)
    assert vis.sphere_terminal_velocity(1.14, 2.5e-3, 7420.0, 1250.0) == pytest.approx(73.7e-3, rel=5e-3)
    # SI quotes Re ~ 0.3 (liquid density gives 0.40; reported, not asserted beyond order of magnitude)
    assert 0.1 < r.reynolds_fluid < 1.0


def test_terminal_velocity_fit():
    # oracle: exact linear track after a transient; tolerance: round-off
    t = np.linspace(0, 2, 41)
    z = np.where(t < 0.3, 0.0, 0.0737 * (t - 0.3))
    assert vis.terminal_velocity_fit(t, z, t_min=0.5).slope == pytest.approx(0.0737, rel=1e-10)


def test_rod_fit_recovers_viscosity():
    # oracle: SI Eq. Force:Stokes:LongRod:all with eta = 1.02 (SI's value) and 0.2 % noise; 4 sigma
    rng = np.random.default_rng(7)
    L = np.linspace(0.03, 0.2, 15)
    F = vis.rod_force(L, 1.02, 5e-3, 2e-3, 1250.0)
    err = 2e-3 * np.abs(F)
    for fit_density in (False, True):
        res = vis.fit_rod_viscosity(L, F + rng.normal(0, err), 5e-3, 2e-3, 1250.0,
                                    fit_density=fit_density, force_error=err)
        assert abs(res.viscosity - 1.02) < 4 * res.viscosity_error
        if fit_density:
            assert abs(res.fluid_density - 1250.0) < 4 * res.fluid_density_error


def test_andrade_fit_recovers_parameters_within_uncertainty():
    # oracle: synthetic data from the SI's constants with 1 % noise; a single draw within 3 sigma,
    # and the reported sigma has the right coverage over 400 draws (68 % +- 7 % at 3 binomial sigma)
    rng = np.random.default_rng(11)
    T = np.linspace(285.0, 305.0, 10)
    true = vis.andrade_viscosity(T)
    inside_u = inside_eta = 0
    n = 400
    for _ in range(n):
        eta = true * np.exp(0.01 * rng.normal(size=T.size))
        f = vis.fit_andrade(T, eta, 0.01 * eta)
        inside_u += abs(f.energy - vis.ANDRADE_ENERGY) < f.energy_error
        inside_eta += abs(f.log_eta_inf - np.log(vis.ANDRADE_ETA_INF)) < f.log_eta_inf_error
    assert abs(f.energy - vis.ANDRADE_ENERGY) < 3 * f.energy_error
    assert abs(f.eta_inf - vis.ANDRADE_ETA_INF) < 3 * f.eta_inf_error * 1.5  # lognormal asymmetry
    assert 0.61 < inside_u / n < 0.75
    assert 0.61 < inside_eta / n < 0.75


def test_andrade_si_constants_near_measurements():
    # oracle: SI's measured 1.14 Pa s at 19.2 C; the SI's fitted curve gives 1.12 (2 % off), reported in docs
    assert float(vis.andrade_viscosity(273.15 + 19.2)) == pytest.approx(1.14, rel=0.03)


def test_machin_temperature_correction():
    # oracle: ratio of Andrade viscosities; identity at the reference; tolerance: round-off
    assert vis.machin_at_temperature(100.0, vis.REFERENCE_TEMPERATURE) == pytest.approx(100.0, rel=1e-14)
    T = 296.15
    expect = 100.0 * float(vis.andrade_viscosity(T) / vis.andrade_viscosity(293.15))
    assert vis.machin_at_temperature(100.0, T) == pytest.approx(expect, rel=1e-14)
    assert vis.machin_at_temperature(100.0, T) < 100.0  # warmer -> thinner -> smaller M


def test_errors():
    with pytest.raises(UserInputError, match="sphere_density"):
        vis.sphere_viscosity(0.07, 2.5e-3, 1000.0, 1250.0)
    with pytest.raises(UserInputError, match="kelvin"):
        vis.andrade_viscosity(-3.0)
