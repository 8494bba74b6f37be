"""The degree-of-freedom layout (flagwrap.system.layout): blocks, weights, error norm."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from flagwrap.system.rod_system import RodSystem
from flagwrap.system.layout import DofLayout

from conftest import make_config, paper_filament


def test_clamped_filament_layout_is_the_rod_systems():
    s = RodSystem(make_config(filament=paper_filament(n_beads=21)))
    lay = s.layout
    assert lay.size == s.ny == 4 * 21 - 7  # 3 (N - 2) + (N - 2) + 1
    assert lay["x"] == slice(0, 3 * 19) and lay["theta"] == slice(57, 76) and lay["phi"] == slice(76, 77)
    assert np.array_equal(lay.free(), np.arange(s.ny - 1))


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 40), st.integers(0, 40), st.floats(1e-8, 1e-2))
def test_error_norm_and_weights_agree(nb, ne, tol):
    # the norm is the max over unknowns of |err| / weight (prescribed ones have weight inf)
    lay = DofLayout.clamped_filament(nb, ne)
    rng = np.random.default_rng(nb * 41 + ne)
    err = rng.standard_normal(lay.size)
    w = lay.error_weights(tol)
    assert np.all(w[lay["x"]] == tol) and np.all(w[lay["theta"]] == 10 * tol) and np.isinf(w[-1])
    expect = float(np.max(np.abs(err) / w)) if lay.size > 1 else 0.0
    assert lay.scaled_error(err, tol) == pytest.approx(expect, rel=1e-15, abs=0.0)


def test_bad_layouts_are_refused():
    with pytest.raises(ValueError, match="duplicate"):
        DofLayout([("x", "position", 3), ("x", "angle", 1)])
    with pytest.raises(ValueError, match="unknown kind"):
        DofLayout([("x", "velocity", 3)])
    with pytest.raises(ValueError, match="negative"):
        DofLayout([("x", "position", -1)])


def test_locate_names_the_block_of_an_unknown():
    from flagwrap.system.layout import DofLayout

    lay = DofLayout.clamped_filament(3, 4)
    assert lay.locate(0) == ("x", 0) and lay.locate(8) == ("x", 8)
    assert lay.locate(9) == ("theta", 0) and lay.locate(13) == ("phi", 0)
    with pytest.raises(IndexError):
        lay.locate(14)
