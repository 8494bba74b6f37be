"""Scaling theory (main text): oracle = the paper's printed numbers and algebraic identities."""

import math

import pytest

from flagwrap.errors import UserInputError
from flagwrap.theory import scaling as sc
from flagwrap.units import PN_UM2, machin_number as units_machin


def test_paper_numbers_match_main_text():
    # oracle: numbers printed in the main text; tolerance = their quoted precision (2 significant figures)
    p = sc.paper_numbers()
    assert p.machin_bacterium == pytest.approx(750, rel=0.01)
    assert p.critical_torque_pn_nm == pytest.approx(2500, rel=1e-12)
    assert p.peak_torque_pn_nm == pytest.approx(4500, rel=1e-12)
    # orders of magnitude only ("Re ~ 1e-4", "Re ~ 2e-2"): within a factor 2
    assert 0.5e-4 < p.reynolds_bacterium < 2e-4
    assert 1e-2 < p.reynolds_model < 4e-2
    # "0.01 - 0.1 Hz" for the model with the RFT form of Eq. 2
    assert 0.01 < p.omega_c_model_rft / (2 * math.pi) < 0.1


def test_two_forms_of_eq2_differ_by_log_factor():
    # oracle: algebra, A = pi E a^4/4 and zeta = pi eta / ln(0.18 P/a); tolerance: float round-off
    E, eta, a, R, L, P = 1.3e6, 1.1, 1.5e-3, 30e-3, 300e-3, 34e-3
    A = sc.bending_stiffness(E, a)
    w1 = sc.critical_angular_frequency(A, sc.rft_friction(eta, P, a), R, L)
    w2 = sc.critical_angular_frequency_material(E, eta, a, R, L)
    assert w1 / w2 == pytest.approx(math.log(0.18 * P / a) / 4, rel=1e-12)


def test_machin_at_omega_c_equals_prefactor_mapping():
    # oracle: M_c = eta omega_c L^4/A = (c_w ln(0.18P/a)/pi)(R/L)^-3; tolerance: round-off
    E, eta, a, R, L, P, c_w = 4.5e8, 1e-3, 10e-9, 0.6e-6, 7e-6, 1.5e-6, 0.3
    A = sc.bending_stiffness(E, a)
    wc = sc.critical_angular_frequency(A, sc.rft_friction(eta, P, a), R, L, prefactor=c_w)
    Mc = sc.machin_number(eta, wc, L, A)
    assert Mc == pytest.approx(sc.critical_machin_number(R / L, sc.machin_prefactor_from_omega(c_w, P, a)), rel=1e-12)


def test_machin_agrees_with_units_module():
    # oracle: flagwrap.units.machin_number (the simulator's nondimensionalisation); tolerance: round-off
    assert sc.machin_number(2e-3, 300.0, 6e-6, 3 * PN_UM2) == pytest.approx(units_machin(2e-3, 300.0, 6e-6, 3 * PN_UM2), rel=1e-14)


def test_critical_machin_and_torques():
    # oracle: the definitions M_c = 0.06 (R/L)^-3, N = c A/R; tolerance: round-off
    assert sc.critical_machin_number(0.1) == pytest.approx(60.0, rel=1e-14)
    assert sc.torque_pn_nm(3.0, 0.6) == pytest.approx(2500.0, rel=1e-12)
    assert sc.peak_torque(3 * PN_UM2, 0.6e-6) == pytest.approx(4.5e-18, rel=1e-12)


@pytest.mark.parametrize("bad", [0.0, -1.0, float("nan"), float("inf")])
def test_invalid_inputs_name_the_parameter(bad):
    with pytest.raises(UserInputError, match="viscosity"):
        sc.machin_number(bad, 1.0, 1.0, 1.0)


def test_rft_friction_needs_slender_helix():
    with pytest.raises(UserInputError, match="0.18 P / a"):
        sc.rft_friction(1.0, 1.0, 1.0)
