import numpy as np
import pytest

from flagwrap.params import Config, Filament, Motor, Numerics, Phase


def paper_filament(**kw):
    """The Fig. 4(a) helix: psi = 70 deg, n = 2, L = 0.4 m, a = 1.5 mm, E = 1.5 MPa (SI Movie 3)."""
    base = dict(length=0.4, helix_radius=0.03, turns=2.0, cross_section_radius=1.5e-3,
                youngs_modulus=1.5e6)
    base.update(kw)
    return Filament(**base)


def make_config(machin=283.0, protocol=(("ccw", 10), ("cw", 10)), hi=True, **kw):
    fil = kw.pop("filament", None) or paper_filament()
    phases = tuple(Phase(d, t) for d, t in protocol)
    num = kw.pop("numerics", None) or Numerics(hydrodynamics=hi)
    return Config(filament=fil, motor=Motor(machin=machin, protocol=phases), numerics=num, **kw)


@pytest.fixture
def rng():
    return np.random.default_rng(12345)
