"""Parameter validation: every impossible value is a clear error naming the parameter."""

import math

import pytest

from flagwrap.errors import UserInputError
from flagwrap.params import CellBody, Config, Contact, Filament, Motor, Numerics, Phase

from conftest import make_config, paper_filament


def test_derived_geometry_and_numbers():
    fil = paper_filament()
    assert fil.pitch_angle_deg == pytest.approx(70.47, abs=0.01)  # SI Movie 3: psi = 70 deg
    assert fil.turns == pytest.approx(2.0)
    A = math.pi * 1.5e6 * 1.5e-3**4 / 4
    assert fil.bending_modulus == pytest.approx(A)
    assert fil.twist_modulus == pytest.approx(A / 1.49)
    cfg = make_config(machin=283.0)
    assert cfg.machin == pytest.approx(283.0)
    # T ~ 105 s for M = 283 with eta = 1.1 Pa s, L = 0.4 m (issue 3's number)
    assert cfg.scales.period == pytest.approx(105, rel=0.01)
    # Re = rho R^2 omega / eta; main text: R = 15 mm, f = 0.01 Hz, glycerin -> Re ~ 2e-2
    from flagwrap.units import reynolds_number

    assert reynolds_number(1250, 0.015, 2 * math.pi * 0.01, 1.1) == pytest.approx(1.6e-2, rel=0.05)
    assert cfg.reynolds == pytest.approx(1250 * 0.03**2 * cfg.omega / 1.1)
    # kappa0 and tau0 satisfy kappa0^2 + tau0^2 = 1/(R^2 + p^2) (helix identity)
    p = fil.pitch / (2 * math.pi)
    assert fil.curvature0**2 + fil.torsion0**2 == pytest.approx(1 / (fil.helix_radius**2 + p**2))


@pytest.mark.parametrize(
    "kw,needle",
    [
        (dict(length=-1.0), "filament.length"),
        (dict(length=0.0), "filament.length"),
        (dict(helix_radius=float("nan")), "filament.helix_radius"),
        (dict(cross_section_radius=0.05), "cross_section_radius"),
        (dict(turns=None, pitch=0.002), "filament.pitch"),
        (dict(n_beads=3), "filament.n_beads"),
        (dict(n_beads=2.5), "filament.n_beads"),
        (dict(poisson_ratio=0.7), "filament.poisson_ratio"),
        (dict(handedness="up"), "filament.handedness"),
        (dict(turns=None), "exactly one of pitch"),
        (dict(pitch=0.05), "exactly one of pitch"),
        (dict(turns=50.0), "filament.turns"),
        (dict(youngs_modulus="soft"), "filament.youngs_modulus"),
    ],
)
def test_filament_rejects(kw, needle):
    with pytest.raises(UserInputError, match=needle):
        paper_filament(**kw)


def test_other_sections_reject():
    with pytest.raises(UserInputError, match="motor"):
        Motor()
    with pytest.raises(UserInputError, match="motor"):
        Motor(frequency=0.01, machin=10)
    with pytest.raises(UserInputError, match="direction"):
        Phase("left", 1)
    with pytest.raises(UserInputError, match="turns"):
        Phase("cw", -1)
    with pytest.raises(UserInputError, match="contact.range"):
        Contact(range=0)
    with pytest.raises(UserInputError, match="numerics.integrator"):
        Numerics(integrator="rk4")
    with pytest.raises(UserInputError, match="numerics.tol"):
        Numerics(tol=1.0)
    with pytest.raises(UserInputError, match="body.radius"):
        CellBody(radius=-2)
    # "give either": both is an error (radius_ratio used to be dropped silently), neither 0.6
    with pytest.raises(UserInputError, match="not both"):
        CellBody(radius=0.05, radius_ratio=0.3)
    assert CellBody().radius_ratio == 0.6 and CellBody(radius=0.05).radius_ratio is None
    import dataclasses  # replacing the default body's size by a radius still works

    assert dataclasses.replace(CellBody(), radius=0.05) == CellBody(radius=0.05)


def test_nonlocal_distance_of_a_tight_helix_is_the_pitch():
    # oracle: successive turns of a nearly flat coil (psi ~ 89.7 deg) are P apart
    from flagwrap.geometry.helix import min_nonlocal_distance
    from flagwrap.params import Clamp

    fil = Filament(length=0.4, helix_radius=0.03, pitch=0.0032, cross_section_radius=1.5e-3,
                   youngs_modulus=1.5e6, n_beads=400)
    d = min_nonlocal_distance(fil, Clamp(lead="kink"))
    assert d == pytest.approx(0.0032, rel=0.02)
    Config(filament=fil, motor=Motor(machin=10))  # P > 2a: accepted


@pytest.mark.parametrize("kw, match", [
    ({"mobility_backend": "gpu"}, "mobility_backend"),
    ({"mobility_tol": 0.5}, "mobility_tol"),
    ({"linear_solver": "lu"}, "linear_solver"),
    ({"linear_solver": "sparse"}, "hydrodynamics"),
    ({"linear_solver": "banded"}, "hydrodynamics"),
])
def test_numerics_backend_choices_are_checked(kw, match):
    from flagwrap.params import Numerics

    with pytest.raises(UserInputError, match=match):
        Numerics(**kw)


def test_numerics_backend_missing_package_is_named(monkeypatch):
    import importlib.util

    from flagwrap.params import Numerics

    real = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec", lambda name, *a: None if name == "fmm3dpy" else real(name, *a))
    with pytest.raises(UserInputError, match="pip install fmm3dpy"):
        Numerics(mobility_backend="fmm")
