"""Built-in paper cases (also shipped as TOML files under ``examples/``).

Geometry from the SI movie list and figure captions; the motor speed is set by the Machin
number where the main text prints it (Fig. 4), else by the SI frequency. Where the paper's
numbers disagree (e.g. Fig. 4(a)'s M = 283 against SI Movie 3's f = 0.006 Hz, which gives
M = 178), the printed main-text value wins and the disagreement is listed in docs/model.md.
"""

from __future__ import annotations

from flagwrap.errors import UserInputError
from flagwrap.params import Config, Filament, Fluid, Motor

# the paper's elastomer and glycerin (Methods): E = 1.5 MPa, a = 1.5 mm, nu = 0.49, eta = 1.1 Pa s
_MATERIAL = dict(cross_section_radius=1.5e-3, youngs_modulus=1.5e6, poisson_ratio=0.49)


def _cfg(name, L, R, n, **motor):
    fil = Filament(length=L, helix_radius=R, turns=n, **_MATERIAL)
    return Config(name=name, filament=fil, motor=Motor(**motor), fluid=Fluid(1.1, 1250.0))


CASES = {
    # Fig. 4(a): psi = 70 deg, n = 2, M = 283 (SI Movie 3 geometry: L = 400 mm, R = 30 mm)
    "fig4a": lambda: _cfg("fig4a", 0.400, 0.030, 2.0, machin=283.0),
    # Fig. 4(b): psi = 33 deg, n = 2.5, M = 2348 (SI Movie 6 geometry: L = 359 mm, R = 12.5 mm)
    "fig4b": lambda: _cfg("fig4b", 0.359, 0.0125, 2.5, machin=2348.0),
    # SI Movie 2: twirling coil, L = 358 mm, R = 22.5 mm, n = 2.35, f = 0.01 Hz
    "movie2": lambda: _cfg("movie2", 0.358, 0.0225, 2.35, frequency=0.01),
    # SI Movie 3: wrapping coil, L = 400 mm, R = 30 mm, n = 2, f = 0.006 Hz
    "movie3": lambda: _cfg("movie3", 0.400, 0.030, 2.0, frequency=0.006),
    # SI Movie 5: folding coil, L = 358 mm, R = 22.5 mm, n = 2.35, f = 0.02 Hz
    "movie5": lambda: _cfg("movie5", 0.358, 0.0225, 2.35, frequency=0.02),
    # SI Movie 6: folding normal form, L = 359 mm, R = 12.5 mm, n = 2.5, f = 0.10 Hz
    "movie6": lambda: _cfg("movie6", 0.359, 0.0125, 2.5, frequency=0.10),
    # SI Movie 7: critical dynamics, L = 300 mm, R = 15 mm, n = 3, f = 0.10 Hz
    "movie7": lambda: _cfg("movie7", 0.300, 0.015, 3.0, frequency=0.10),
}


def get_case(name: str) -> Config:
    if name not in CASES:
        raise UserInputError(f"unknown case {name!r}; available: {', '.join(CASES)}")
    return CASES[name]()
