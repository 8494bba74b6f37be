"""Interactions in the system (flagwrap.interactions): self-contact's forces and Jacobian as
the system sees them, input checks, and the crossing count of the buckled Fig. 4(a) run."""

import dataclasses

import numpy as np
import pytest

from flagwrap.errors import UserInputError
from flagwrap.interactions.self_contact import SelfContact, count_crossings, max_self_range
from flagwrap.io.config import load_config
from flagwrap.system.rod_system import RodSystem
from flagwrap.params import Contact, Phase


def _hairpin_config(self_contact=True):
    cfg = load_config("examples/fig4a.toml")
    N = 21
    fil = dataclasses.replace(cfg.filament, n_beads=N, pitch_angle_deg=None, turns=None)
    return cfg.replace(filament=fil, body=dataclasses.replace(cfg.body, enabled=False),
                       contact=dataclasses.replace(cfg.contact, self_contact=self_contact),
                       numerics=dataclasses.replace(cfg.numerics, hydrodynamics=False))


def _hairpin(a, gap):
    """Down the axis, a bottom bond, back up ``gap`` away (the two arms inside the cut-off)."""
    down = np.column_stack([np.zeros(11), np.zeros(11), -np.linspace(0, 1, 11) * 0.5])
    up = np.column_stack([np.full(10, gap), np.zeros(10), -np.linspace(1, 0.1, 10) * 0.5])
    x = np.vstack([down, up])
    rng = np.random.default_rng(5)
    x[2:] += 0.1 * a * rng.standard_normal((len(x) - 2, 3))
    return x


def test_self_contact_enters_the_forces_and_the_jacobian():
    cfg = _hairpin_config()
    a = cfg.filament.cross_section_radius / cfg.filament.length
    x_rest = np.column_stack([np.zeros(21), np.zeros(21), -np.linspace(0, 1, 21)])
    on = RodSystem(cfg, x0=x_rest)
    off = RodSystem(_hairpin_config(False), x0=x_rest)
    x = _hairpin(a, 2.6 * a)
    y = on.pack(x, np.zeros(20), 0.0)
    base = on.frames0
    g_on, g_off = on.forces(y, base), off.forces(y, base)
    sc = on.interactions[0].contact
    grad = np.zeros_like(x)
    E, dmin = sc.energy_grad(x, grad)
    assert E > 0 and g_on.interaction_energy == pytest.approx(E)
    assert np.allclose(g_on.G[on.sl_x] - g_off.G[off.sl_x], -grad[2:].ravel(), rtol=0, atol=1e-12 * np.abs(grad).max())
    # the interaction's part of the Jacobian against central differences of its forces
    J = on.force_jacobian(y, base) - off.force_jacobian(y, base)
    h = 1e-7 * a
    num = np.zeros_like(J)
    for k in range(on.ny - 1):
        yp, ym = y.copy(), y.copy()
        yp[k] += h
        ym[k] -= h
        num[:, k] = ((on.forces(yp, base).G - off.forces(yp, base).G)
                     - (on.forces(ym, base).G - off.forces(ym, base).G)) / (2 * h)
    # the kernel's one-sided differences of the elastic terms cancel between on and off only
    # to their own rounding: compare at 1e-4 of the contact block's scale
    assert np.abs(J[:, :-1] - num[:, :-1]).max() <= 1e-4 * np.abs(num).max()


def test_self_range_that_touches_the_rest_shape_is_refused():
    cfg = load_config("examples/fig4a.toml")
    on = cfg.replace(contact=dataclasses.replace(cfg.contact, self_contact=True))
    rmax = max_self_range(on)
    assert 1.0 < rmax < np.inf  # the default range 1 fits; some larger range does not
    with pytest.raises(UserInputError, match=r"contact\.self_range"):
        cfg.replace(contact=Contact(self_contact=True, self_range=rmax * 1.01))
    cfg.replace(contact=Contact(self_contact=True, self_range=rmax * 0.99))


@pytest.mark.parametrize("kw, key", [(dict(self_range=1.0), "contact.self_range"),
                                     (dict(self_contact=True, self_range=-1.0), "contact.self_range"),
                                     (dict(self_contact=True, self_strength=0.0), "contact.self_strength"),
                                     (dict(self_contact="yes"), "contact.self_contact")])
def test_bad_self_contact_input_names_the_key(kw, key):
    with pytest.raises(UserInputError, match=key.replace(".", r"\.")):
        Contact(**kw)


def test_default_keys_are_unchanged_by_the_new_sections():
    cfg = load_config("examples/fig4a.toml")
    d = cfg.to_dict(for_hash=True)
    assert "joint" not in d and "self_contact" not in d["contact"]


@pytest.mark.slow
def test_self_contact_removes_the_crossing_of_the_buckled_fig4a_run():
    # studies/self_contact.py: M = 600, 10 CCW + 10 CW turns, 1 crossing without (segments 26
    # and 56 at t/T = 17.35), none with; the segments then stay >= 2a apart (surfaces apart)
    from flagwrap.simulation import simulate

    cfg = load_config("examples/fig4a.toml")
    cfg = cfg.replace(motor=dataclasses.replace(cfg.motor, machin=600.0,
                                                protocol=(Phase("ccw", 10.0), Phase("cw", 10.0))))
    fil = cfg.filament
    a, b = fil.cross_section_radius / fil.length, fil.bond_length / fil.length
    probe = SelfContact(a, b)
    counts, dmins = [], []
    for on in (False, True):
        c = cfg.replace(contact=dataclasses.replace(cfg.contact, self_contact=on))
        X = np.asarray(simulate(c).arrays()["x"])
        counts.append(count_crossings(X, exclude=probe.exclude))
        dmins.append(min(probe.energy_grad(x, np.zeros_like(x))[1] for x in X))
    assert counts[0] >= 1 and counts[1] == 0
    assert dmins[1] > 2 * a
