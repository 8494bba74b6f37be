"""Elastomer density (SI mixing rule): oracle = the rule's limits and its inverse."""

import numpy as np
import pytest

from flagwrap.errors import UserInputError
from flagwrap.experiment import density as den


def test_limits():
    # oracle: pure components; tolerance: round-off
    assert float(den.effective_density(1.0, 1.0, 0.0)) == pytest.approx(den.RHO_HTV, rel=1e-14)
    assert float(den.effective_density(1e-12, 0.0, 1.0)) == pytest.approx(den.RHO_FEO, rel=1e-9)


def test_powder_mass_inverts_mixing_rule():
    # oracle: effective_density of the computed recipe equals the target; tolerance: round-off
    targets = np.array([1150.0, 1200.0, 1250.0, 2000.0])
    for t in targets:
        m = float(den.powder_mass_for_density(100.0, t))
        assert float(den.effective_density(50.0, 50.0, m)) == pytest.approx(t, rel=1e-12)
    # the SI's materials and glycerin: 0.1112 g of iron oxide per g of polymer (hand calculation, 4 digits)
    assert float(den.powder_mass_for_density(1.0)) == pytest.approx(0.1112, abs=5e-5)


def test_mismatch_and_validation():
    assert float(den.density_mismatch(1262.5)) == pytest.approx(0.01, rel=1e-12)
    with pytest.raises(UserInputError, match="target_density"):
        den.powder_mass_for_density(1.0, 6000.0)
    with pytest.raises(UserInputError, match="masses"):
        den.effective_density(-1.0, 1.0, 1.0)
