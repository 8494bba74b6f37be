"""The bead chain matched to a slender tube (flagwrap.hydrodynamics.tube; docs/bacterium.md,
"The chain matched to a tube") against slender-body theory, and its mobility's invariants."""

import dataclasses
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from conftest import system_kinds
from flagwrap.body.multiblob import resistance_matrix
from flagwrap.errors import UserInputError
from flagwrap.hydrodynamics.mobility import RPYMobility
from flagwrap.hydrodynamics.tube import TUBE_MIN_BOND, TubeMobility, tube_chain
from flagwrap.theory.slender_body import (
    bead_helix,
    blunt_profile,
    chain_effective_radii,
    helix_centreline,
    johnson_resistance,
    propulsion_coefficients,
    sphere_and_helix_swimmer,
    straight_chain,
)


def tube_mobility(a, b, chains):
    tc = tube_chain(a, b)
    return TubeMobility(RPYMobility(tc.bead_radius), chains, tc.kappa), tc


@pytest.mark.parametrize("b_over_a", [2.6, 4.44, 6.5, 10.0, 20.0])
def test_matched_radii_are_the_tube_radius(b_over_a):
    # the two conditions that define the match (module docstring), to rounding
    tc = tube_chain(1.0, b_over_a)
    r_par, r_perp = chain_effective_radii(tc.bead_radius, b_over_a)
    assert r_perp == pytest.approx(1.0, rel=1e-12)
    assert r_par * math.exp(-tc.kappa * b_over_a / (3 * tc.bead_radius)) == pytest.approx(
        1.0, rel=1e-12)
    assert tc.kappa >= 0 and tc.bead_radius < b_over_a / 2


@pytest.mark.parametrize("b_over_a", [2.6, 6.5, 20.0])
def test_straight_chain_middle_moves_as_the_tube_local_term(b_over_a):
    # Independent answer: slender-body theory's local term for a uniform straight tube of
    # radius a and length l = N b with a uniform force per length f (the non-local integral
    # vanishes on a straight line): 8 pi u = (2 Lg - 2) f along, (Lg + 1) f across,
    # Lg = ln(4 s (l - s) / a^2), at the middle s = l/2. The chain's neighbour sums approach
    # it as K^-2 (K = 400 beads a side): measured 4e-8 to 1e-7; tolerance 1e-6
    a, b, N = 1.0, b_over_a, 801
    mob, _ = tube_mobility(a, b, [(0, N)])
    x = straight_chain(N, b)
    Lg = 2 * math.log(N * b / a)
    for d, coef in ((2, 2 * Lg - 2), (0, Lg + 1)):
        F = np.zeros((N, 3))
        F[:, d] = 1.0
        u = mob.apply(x, F)[N // 2, d]
        assert u == pytest.approx(coef / b / (8 * math.pi), rel=1e-6)


def test_sphere_chain_is_not_the_tube():
    # the defect the tube model repairs: spheres of the filament's radius at b = 6.5 a drag
    # along the chain as a tube of radius 0.52 a and across as one of 0.16 a
    r_par, r_perp = chain_effective_radii(1.0, 6.5)
    assert r_par < 0.55 and r_perp < 0.2


# the bacterial helix of the issue: R 0.2, P 2.3, L 7 um, a 10 nm; 101 beads (b = 7 a, the
# bacterial examples' 6.5-7 a)
L_B, R_B, P_B, A_B = 7.0, 0.2, 2.3, 0.01


def _sbt_tube():
    # Johnson's slender body of the filament's length with a near-uniform radius a (blunt
    # profile p = 12: uniform but for rounded tips; p = 24 moves A, B, D by <= 0.7 %)
    return johnson_resistance(helix_centreline(L_B, R_B, P_B), blunt_profile(A_B, L_B, 12), n=96)


def _bead_helix_R(n_beads, model):
    b = L_B / (n_beads - 1)
    x, _ = bead_helix(L_B, R_B, P_B, n_beads)
    if model == "tube":
        mob, tc = tube_mobility(A_B, b, [(0, n_beads)])
        ah = tc.bead_radius
    else:
        mob, ah = RPYMobility(A_B), A_B
    return resistance_matrix(x, ah, mobility=mob.matrix(x)), x


@pytest.fixture(scope="module")
def sbt_tube():
    return _sbt_tube()


def test_helix_propulsion_matrix_against_slender_body_theory(sbt_tube):
    # A, B, D of the tube-matched bead helix at b = 7 a against slender-body theory of the
    # filament (length L); nothing fitted to the helix. Tolerance 3 % (the issue's): the
    # chain is b longer than the filament (+1/(N-1) = 1 %) and blunt-ended where the SBT
    # body is rounded (docs/bacterium.md: 1.5 % in D). Measured: +2.3 %, +1.3 %, +2.7 %
    Rb, _ = _bead_helix_R(101, "tube")
    for got, ref in zip(propulsion_coefficients(Rb), propulsion_coefficients(sbt_tube)):
        assert got == pytest.approx(ref, rel=0.03)


@pytest.mark.parametrize("n_beads", [51, 71, 101, 151, 201])
def test_helix_propulsion_at_any_bacterial_spacing(n_beads):
    # b = 14, 10, 7, 4.7, 3.5 a against the slender body the chain stands for, the helix
    # through its beads extended by half a bead step at each end (length N b: each bead one
    # step of the contour). Tolerance 3 %: the blunt-end residual (docs/bacterium.md)
    from flagwrap.theory.slender_body import bead_chain_centreline

    line = bead_chain_centreline(L_B, R_B, P_B, n_beads)
    ref = johnson_resistance(line, blunt_profile(A_B, line.length, 12), n=96)
    Rb, _ = _bead_helix_R(n_beads, "tube")
    for got, r in zip(propulsion_coefficients(Rb), propulsion_coefficients(ref)):
        assert got == pytest.approx(r, rel=0.03)


def test_sphere_helix_propels_weakly(sbt_tube):
    # the spheres of radius a at b = 7 a: B half the tube's (measured -50 %), D -28 %
    Rb, _ = _bead_helix_R(101, "spheres")
    A, B, D = propulsion_coefficients(Rb)
    A0, B0, D0 = propulsion_coefficients(sbt_tube)
    assert B / B0 < 0.6 and D / D0 < 0.8


def test_free_swimmer_against_slender_body_theory(sbt_tube):
    # a rigid helix on a free sphere (radius 0.5 um, helix from 0.1 um below its surface):
    # speed, body counter-rotation and motor torque of the tube-matched chain (101 beads)
    # against the same swimmer with slender-body theory's helix; the sphere exact in both,
    # the sphere-helix interaction left out of both. Tolerance 3 % (the issue's; the entries
    # differ by <= 2.7 %). Measured in docs/bacterium.md
    Rb, _ = _bead_helix_R(101, "tube")
    centre = (0.0, 0.0, 0.5 + 0.1 + L_B / 2)  # the helix is centred on the origin
    got = sphere_and_helix_swimmer(Rb, 0.5, centre)
    ref = sphere_and_helix_swimmer(sbt_tube, 0.5, centre)
    assert ref[0] != 0 and ref[1] != 0
    for g, r in zip(got, ref):
        assert g == pytest.approx(r, rel=0.03)
    # the spheres chain misses the speed by tens of per cent (the issue's -45 %)
    Rs, _ = _bead_helix_R(101, "spheres")
    assert sphere_and_helix_swimmer(Rs, 0.5, centre)[0] < 0.7 * ref[0]


@settings(max_examples=30, deadline=None)
@given(st.integers(3, 25), st.floats(2.6, 15.0), st.integers(0, 2**31 - 1))
def test_tube_mobility_is_spd_and_consistent(n, b_over_a, seed):
    # a random chain of n beads split in two chains: the matrix is symmetric positive
    # definite, apply is the matrix's product, the near-field self blocks are the matrix's
    # diagonal blocks, and M(R x) = R M(x) R^T
    rng = np.random.default_rng(seed)
    b = b_over_a
    steps = rng.normal(size=(n, 3))
    steps *= b / np.linalg.norm(steps, axis=1)[:, None]
    x = np.cumsum(steps, axis=0)
    x[:, 0] += np.arange(n) * 3.0 * b  # spread the random walk so that beads do not overlap
    chains = [(0, n // 2), (n // 2, n)]
    mob, _ = tube_mobility(1.0, b, chains)
    M = mob.matrix(x)
    assert np.allclose(M, M.T, atol=1e-14 * np.abs(M).max())
    assert np.linalg.eigvalsh(M).min() > 0
    F = rng.normal(size=(n, 3))
    assert np.allclose(mob.apply(x, F).ravel(), M @ F.ravel(), rtol=1e-12, atol=1e-14)
    blocks = mob.near_field_blocks(x, 2)
    for i in range(n):
        assert np.allclose(blocks[i, 2], M[3 * i:3 * i + 3, 3 * i:3 * i + 3], rtol=1e-12)
    q = rng.normal(size=4)
    q /= np.linalg.norm(q)
    w, u1, u2, u3 = q
    R = np.array([[1 - 2 * (u2**2 + u3**2), 2 * (u1 * u2 - w * u3), 2 * (u1 * u3 + w * u2)],
                  [2 * (u1 * u2 + w * u3), 1 - 2 * (u1**2 + u3**2), 2 * (u2 * u3 - w * u1)],
                  [2 * (u1 * u3 - w * u2), 2 * (u2 * u3 + w * u1), 1 - 2 * (u1**2 + u2**2)]])
    Rb = np.kron(np.eye(n), R)
    assert np.allclose(mob.matrix(x @ R.T), Rb @ M @ Rb.T, atol=1e-12 * np.abs(M).max())


def test_tube_bound_and_errors():
    assert TUBE_MIN_BOND == pytest.approx(2.5036, abs=1e-4)
    with pytest.raises(ValueError, match="below"):
        tube_chain(1.0, 2.4)


def _filament(**kw):
    from flagwrap.io.config import load_config

    fil = load_config("examples/s_putrefaciens.toml").filament
    return dataclasses.replace(fil, pitch=fil.pitch, pitch_angle_deg=None, turns=None, **kw)


def test_config_refusals():
    with pytest.raises(UserInputError, match="hydrodynamic_model must be one of"):
        _filament(hydrodynamic_model="cylinder")
    with pytest.raises(UserInputError, match="hydrodynamic_radius cannot be set"):
        _filament(hydrodynamic_model="tube", hydrodynamic_radius=2e-8)
    with pytest.raises(UserInputError, match=r"n_beads <= \d+"):
        _filament(hydrodynamic_model="tube", n_beads=400)  # b = 1.6 a
    fil = _filament(hydrodynamic_model="tube")
    tc = tube_chain(fil.cross_section_radius, fil.bond_length)
    assert fil.bead_radius == tc.bead_radius and fil.tube_kappa == tc.kappa
    assert fil.bead_spin_drag == pytest.approx(
        4 * math.pi * fil.cross_section_radius**2 * fil.bond_length)
    assert _filament(hydrodynamic_model="spheres").tube_kappa == 0.0


# ---- every kind of system takes the tube model ------------------------------------------------

def _tiny(extra_numerics="", tables=""):
    import tomllib

    from conftest import tiny_toml
    from flagwrap.io.config import config_from_dict

    text = tiny_toml(ccw=0.1, cw=0.05, machin=283).replace(
        "n_beads = 21\n", "n_beads = 21\nhydrodynamic_model = 'tube'\n").replace(
        "[numerics]\n", "[numerics]\n" + extra_numerics)
    return config_from_dict(tomllib.loads(text + tables))


KINDS = system_kinds()


@pytest.mark.parametrize("kind", list(KINDS))
def test_every_kind_of_system_runs_on_the_tube_mobility(kind):
    # the system's mobility carries the tube term on each filament's free beads, the spin drag
    # is the tube's, and a short run completes
    from flagwrap.simulation import make_system, simulate

    cfg = _tiny(*KINDS[kind])
    s = make_system(cfg)
    assert isinstance(s.mobility, TubeMobility)
    fil = cfg.filament
    assert s.mobility.kappa == fil.tube_kappa > 0
    nb = [p.nb for p in s.parts]
    assert s.mobility.chains.tolist() == [[sum(nb[:k]), sum(nb[:k + 1])] for k in range(len(nb))]
    L = fil.length
    assert s.rot_drag[1] == pytest.approx(4 * math.pi * fil.cross_section_radius**2
                                          * fil.bond_length / L**3)
    tr = simulate(cfg)
    assert tr.ok and tr.n_steps > 0


def test_turning_frame_jacobian_holds_the_tube_term():
    # the turning frame's J includes the mobility's derivative (dMob[G]), here with the
    # tangent-dependent tube term: against central differences of the velocity itself, as
    # tests/unit/test_rotating.py does for the spheres (same tolerance, same steps)
    from conftest import fd_frame_jacobian
    from flagwrap.system.rod_system import RodSystem
    from flagwrap.system.rotating import RotatingFrame

    s = RodSystem(_tiny())
    fr = RotatingFrame(s, -1.0)
    rng = np.random.default_rng(1)
    z = s.initial_y()[:-1].copy()
    z[: fr.n3] += 1e-4 * rng.standard_normal(fr.n3)
    z[fr.n3:] += 0.02 * rng.standard_normal(fr.n - fr.n3)
    f, info = fr.velocity(z, s.frames0, 400.0)
    J = fr.jacobian(z, info.frames, 400.0, info)
    Jb = fd_frame_jacobian(fr, z, info.frames, 400.0)
    assert np.max(np.abs(J - Jb)) < 1e-7 * np.max(np.abs(J))


def test_free_cell_on_the_tube_mobility_is_force_and_torque_free(rng):
    # the tube term is local to each bead: the blobs' constraint, and so the cell's force
    # and torque balance, are unchanged (round-off of the sums)
    from conftest import fluid_force_and_torque
    from flagwrap.simulation import make_system

    s = make_system(_tiny(*KINDS["two flagella on a free cell"]))
    y = s.initial_y()
    y[s.sl_x] += 0.01 * s.bond * rng.standard_normal(s.sl_x.stop - s.sl_x.start)
    force, torque, f_scale, t_scale = fluid_force_and_torque(s, y)
    assert np.abs(force).max() < 1e-10 * f_scale
    assert np.abs(torque).max() < 1e-10 * t_scale


def test_hydrodynamics_off_refuses_the_tube():
    with pytest.raises(UserInputError, match="needs numerics.hydrodynamics = true"):
        _tiny("hydrodynamics = false\n")


def test_sphere_radius_past_the_neighbour_is_refused(tmp_path, capsys):
    # bad input, by the CLI: one line naming the key, exit 2, before any work
    from conftest import tiny_toml
    from flagwrap.cli.main import main

    cfg = tmp_path / "fat.toml"
    cfg.write_text(tiny_toml().replace("n_beads = 21\n", "n_beads = 21\nhydrodynamic_radius = 0.025\n"))
    assert main(["run", str(cfg), "-o", str(tmp_path / "fat.nc")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "filament.hydrodynamic_radius" in err[0] and "bond" in err[0]
    assert not (tmp_path / "fat.nc").exists()


@pytest.mark.parametrize("model, noted", [("spheres", True), ("tube", False)])
def test_run_notes_a_free_swimmer_on_thin_sphere_beads(capsys, model, noted):
    from flagwrap.cli.run import _bead_model, _weak_chain_note
    from flagwrap.io.config import load_config

    cfg = load_config("examples/s_putrefaciens.toml")
    cfg = cfg.replace(filament=_filament(hydrodynamic_model=model))
    _weak_chain_note(cfg)
    err = capsys.readouterr().err
    assert ("hydrodynamic_model = 'tube'" in err) == noted
    assert ("a_h = 1.79 a" in _bead_model(cfg)) == (model == "tube")
