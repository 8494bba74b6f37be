"""Helix stretching (main text Eq. 1, SI): oracle = direct numerical minimisation of the SI
energy functional over uniform helical configurations, independent of the closed form."""

import math

import numpy as np
import pytest

from flagwrap.errors import UserInputError
from flagwrap.theory import stretching as st

SI_HELIX = st.StretchedHelix(
    radius=15e-3, pitch=34e-3, length=305e-3, youngs_modulus=1.2 * 1.33e6,
    poisson_ratio=0.49, semi_axis_a=3.19e-3 / 2, semi_axis_b=2.88e-3 / 2,
)
ROUND_HELIX = st.StretchedHelix(
    radius=15e-3, pitch=34e-3, length=305e-3, youngs_modulus=1.33e6, poisson_ratio=0.49, semi_axis_a=1.5e-3,
)
FORCES = [0.02, 0.1, 0.5, 1.5, 4.0, -0.03]  # in units of A2 kappa0^2


@pytest.mark.parametrize("helix", [SI_HELIX, ROUND_HELIX], ids=["elliptic", "round"])
@pytest.mark.parametrize("f_red", FORCES)
def test_derived_law_matches_direct_minimisation(helix, f_red):
    # oracle: BFGS + Newton minimisation of the functional; tolerance 1e-6 (acceptance; the
    # minimiser's own precision is ~1e-8, limited by finite-difference derivatives)
    m = st.minimise_uniform_helix(helix, f_red * helix.force_scale)
    assert m.theta0 == pytest.approx(math.pi / 2, abs=1e-6)  # spontaneous curvature in the bending plane
    assert float(st.reduced_force(m.psi, helix.gamma_star, helix.lam)) == pytest.approx(f_red, rel=1e-6)


@pytest.mark.parametrize("f_red", FORCES)
def test_main_text_eq1_holds_for_round_section(f_red):
    # oracle: direct minimisation; Eq. 1 as printed with Gamma = 1/(1+nu), cot psi0; tolerance 1e-6
    h = ROUND_HELIX
    m = st.minimise_uniform_helix(h, f_red * h.force_scale)
    assert h.gamma_star == pytest.approx(1 / 1.49, rel=1e-14)
    assert float(st.main_text_eq1_force(m.psi, 1 / 1.49, h.psi0)) == pytest.approx(f_red, rel=1e-6)


def test_si_printed_form_does_not_hold():
    # oracle: direct minimisation; the SI's printed Eq. (HelicalForce) misses by O(1) in either
    # angle convention (psi from the axis, or from the plane); the curves can cross, so the
    # check is on the worst point of the force range: > 30 % is far outside any numerical error
    h = SI_HELIX
    psis = [st.minimise_uniform_helix(h, f * h.force_scale).psi for f in FORCES]
    for convert in (lambda p: p, lambda p: math.pi / 2 - p):
        rel = [abs(float(st.si_printed_force(convert(p), h.gamma_star, h.lam)) / f - 1) for p, f in zip(psis, FORCES)]
        assert max(rel) > 0.3
    # with psi from the axis (as z/L = cos psi requires) the printed form is not zero at rest
    assert abs(float(st.si_printed_force(h.psi0, h.gamma_star, h.lam))) > 0.3


def test_zero_force_at_rest_angle():
    # oracle: the rest shape minimises the F = 0 functional; tolerance ~ minimiser precision
    m = st.minimise_uniform_helix(SI_HELIX, 0.0)
    assert m.psi == pytest.approx(SI_HELIX.psi0, abs=1e-7)
    assert float(st.reduced_force(SI_HELIX.psi0, SI_HELIX.gamma_star, SI_HELIX.lam)) == pytest.approx(0.0, abs=1e-14)


def test_si_stretching_parameters():
    # oracle: SI's printed values (lambda = 0.36, Gamma* = 0.74, A2 kappa0^2 = 0.020 N);
    # tolerance = their printed precision (the force scale is 0.0208 N, i.e. 4 % above 0.020)
    h = SI_HELIX
    assert h.lam == pytest.approx(0.36, abs=0.005)
    assert h.gamma_star == pytest.approx(0.74, abs=0.005)
    assert h.force_scale == pytest.approx(0.020, rel=0.05)
    assert h.gamma_star == pytest.approx(2 / 1.49 / (1 + (2.88 / 3.19) ** 2), rel=1e-14)  # SI Eq. Gamma
    assert math.degrees(h.psi0) == pytest.approx(70.0, abs=0.5)


def test_round_limit_of_stiffnesses():
    # oracle: A = pi E a^4/4, C = A/(1+nu) (main text); tolerance: round-off
    h = ROUND_HELIX
    A = math.pi * 1.33e6 * 1.5e-3**4 / 4
    assert h.A1 == pytest.approx(A, rel=1e-14) and h.A2 == pytest.approx(A, rel=1e-14)
    assert h.C == pytest.approx(A / 1.49, rel=1e-14)


def test_pitch_angle_inversion_and_extension():
    # oracle: forward law; tolerance: brentq xtol 1e-15
    h = SI_HELIX
    F = 0.7 * h.force_scale
    psi = st.pitch_angle_at_force(h, F)
    assert float(h.force(psi)) == pytest.approx(F, rel=1e-10)
    z = float(h.extension(psi))
    assert z == pytest.approx(math.cos(psi) + F / (math.pi * h.youngs_modulus * h.semi_axis_a * h.b), rel=1e-14)


def test_extension_monotone_in_force():
    # oracle: physical requirement (stable stretching branch); no tolerance
    psi = np.linspace(SI_HELIX.psi0, 0.1, 200)
    z, F = SI_HELIX.force_extension(psi)
    assert np.all(np.diff(F) > 0) and np.all(np.diff(z) > 0)


def test_frame_twist_finite_length_correction_is_small():
    # oracle: minimisation with theta' free (non-uniform); documented few-% finite-length effect
    h = SI_HELIX
    m = st.minimise_uniform_helix(h, 0.3 * h.force_scale, allow_frame_twist=True)
    rel = float(st.reduced_force(m.psi, h.gamma_star, h.lam)) / 0.3 - 1
    assert 0.0 < abs(rel) < 0.05


def test_validation():
    with pytest.raises(UserInputError, match="semi_axis_b"):
        st.StretchedHelix(0.01, 0.03, 0.3, 1e6, 0.49, 1e-3, 2e-3)
    with pytest.raises(UserInputError, match="poisson_ratio"):
        st.StretchedHelix(0.01, 0.03, 0.3, 1e6, 0.7, 1e-3)
    with pytest.raises(UserInputError, match="radius"):
        st.helix_curvature_torsion(-1.0, 1.0)
