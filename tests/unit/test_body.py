"""Cell-body contact law: repulsive, monotone, smooth at the cut-off (wca-c2), exact gradient."""

import numpy as np
import pytest

from flagwrap.body.cell_body import CappedCylinder


def _profile(potential, d):
    """Energy and radial force of one bead at gap ``d`` below the cap's lowest point."""
    body = CappedCylinder(radius=0.2, length=0.5, cutoff=0.01, strength=2.0, first_bead=0,
                          potential=potential)
    x = np.zeros((len(d), 3))
    x[:, 2] = -np.asarray(d)  # below the cap: surface distance = -z
    E = np.empty(len(d))
    F = np.empty(len(d))
    for i in range(len(d)):
        g = np.zeros((1, 3))
        E[i] = body.energy_grad(x[i:i + 1], g, np.empty(1))
        F[i] = g[0, 2]  # dU/dz; z = -d, so dU/dd = -dU/dz
    return body, E, -F


def test_smoothed_wca_is_repulsive_monotone_and_exact_gradient():
    body, E, dU = _profile("wca-c2", np.linspace(0.002, 0.0105, 400))
    cut = body.cutoff
    inside = np.linspace(0.002, 0.0105, 400) < cut
    assert np.all(E[inside] > 0) and np.all(dU[inside] < 0)  # repulsive, energy positive
    assert np.all(np.diff(E[inside]) < 0)  # monotone
    assert np.all(E[~inside] == 0) and np.all(dU[~inside] == 0)
    # gradient = derivative of the energy (central differences, h = 1e-7 of a ~1e-2 gap)
    d = np.array([0.004, 0.007, 0.0095])
    h = 1e-7
    _, Ep, _ = _profile("wca-c2", d + h)
    _, Em, _ = _profile("wca-c2", d - h)
    _, _, g = _profile("wca-c2", d)
    np.testing.assert_allclose((Ep - Em) / (2 * h), g, rtol=1e-5)


@pytest.mark.parametrize("potential, jumps", [("wca", True), ("wca-c2", False)])
def test_stiffness_at_the_cut_off(potential, jumps):
    body, _, _ = _profile(potential, [0.005])
    cut = body.cutoff
    h = 1e-6 * cut
    _, _, g = _profile(potential, [cut - 2 * h, cut - h])
    stiffness_inside = (g[1] - g[0]) / h  # d^2U/dd^2 just inside; 0 just outside
    k_wca = 72 * body.strength / cut**2
    if jumps:
        assert stiffness_inside == pytest.approx(k_wca, rel=1e-3)
    else:
        assert abs(stiffness_inside) < 1e-3 * k_wca


def test_unknown_potential_is_rejected():
    from flagwrap.errors import UserInputError
    from flagwrap.params import Contact

    with pytest.raises(UserInputError, match="contact.potential"):
        Contact(potential="lj")
