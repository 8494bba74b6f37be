"""Johnson's slender-body theory (flagwrap.theory.slender_body) against exact Stokes results,
and the bead helix's propulsion matrix against it (docs/bacterium.md, "Rigid helix")."""

import math

import numpy as np
import pytest

from flagwrap.hydrodynamics.mobility import RPYMobility
from flagwrap.theory.slender_body import (
    bead_chain_centreline,
    bead_helix,
    blunt_profile,
    chain_effective_radii,
    compare_helix,
    helix_centreline,
    helix_pitch,
    johnson_resistance,
    normalised_deviation,
    points_centreline,
    prolate_spheroid_drag,
    propulsion_coefficients,
    spheroidal_profile,
    straight_centreline,
    straight_chain,
)


@pytest.mark.parametrize("aspect", [50, 100])
def test_spheroid_matches_exact_drag(aspect):
    # a straight prolate spheroid (semi-axes c = 1, r0 = 1/aspect) against the exact
    # Oberbeck / Chwang & Wu resistances. SBT drops terms O(eps^2 ln(1/eps)) relative,
    # eps = r0 / c: tolerance eps^2 ln(2 / eps) (1.8e-3 at 50, 5.3e-4 at 100). Measured
    # 3.8e-4 / 9.5e-5 (axial), 2e-5 / 4e-6 (transverse), 2e-5 / 5e-6 (rotation across),
    # 1.4e-3 / 4.3e-4 (spin, rotlet on)
    eps = 1.0 / aspect
    tol = eps**2 * math.log(2.0 / eps)
    ex = prolate_spheroid_drag(1.0, eps)
    R = johnson_resistance(straight_centreline(2.0), spheroidal_profile(eps, 2.0), n=24,
                           rotlet=True)
    assert R[2, 2] == pytest.approx(ex["axial"], rel=tol)
    assert R[0, 0] == pytest.approx(ex["transverse"], rel=tol)
    assert R[1, 1] == pytest.approx(ex["transverse"], rel=tol)
    assert R[3, 3] == pytest.approx(ex["rotation"], rel=tol)
    assert R[5, 5] == pytest.approx(ex["spin"], rel=tol)
    # and Johnson's closed form for the spheroid (uniform force density):
    # axial 4 pi L / (2 ln(L/r0) - 1), transverse 8 pi L / (2 ln(L/r0) + 1), L = 2c
    lg = 2 * math.log(2.0 / eps)
    assert R[2, 2] == pytest.approx(8 * math.pi / (lg - 1), rel=1e-10)
    assert R[0, 0] == pytest.approx(16 * math.pi / (lg + 1), rel=1e-10)
    # no translation-rotation coupling about the centre
    assert np.abs(R[:3, 3:]).max() < 1e-10 * R[0, 0]


def test_spheroid_error_falls_as_eps_squared():
    # the axial error quarters (times the log) when the aspect ratio doubles
    err = []
    for aspect in (50, 100):
        R = johnson_resistance(straight_centreline(2.0), spheroidal_profile(1 / aspect, 2.0),
                               n=16)
        err.append(R[2, 2] / prolate_spheroid_drag(1.0, 1 / aspect)["axial"] - 1)
    assert 3.0 < err[0] / err[1] < 5.0


def test_quadrature_converges():
    # the Nystrom solution of the Fig. 4(a) helix body converges spectrally: measured
    # max |R_n - R_96| / max|R_96| = 6e-4, 5e-6, 1e-8, 6e-10 at n = 12, 16, 24, 32
    L, Rh = 1.0, 0.075
    P = helix_pitch(L, Rh, 2.0)
    line = bead_chain_centreline(L, Rh, P, 61)
    prof, nprof = blunt_profile(0.0038, line.length), blunt_profile(0.0021, line.length)
    R24, R48 = (johnson_resistance(line, prof, n=n, normal_radius_profile=nprof)
                for n in (24, 48))
    assert np.abs(R24 - R48).max() < 1e-6 * np.abs(R48).max()
    # the discrete resistance matrix is symmetric and positive definite
    assert np.abs(R48 - R48.T).max() < 1e-10 * np.abs(R48).max()
    assert np.linalg.eigvalsh(0.5 * (R48 + R48.T)).min() > 0


def test_points_centreline_reproduces_the_helix():
    L, Rh = 1.0, 0.075
    P = helix_pitch(L, Rh, 2.0)
    exact = helix_centreline(L, Rh, P)
    pts = exact.position(np.linspace(0, L, 401))
    line = points_centreline(pts)
    assert line.length == pytest.approx(L, rel=1e-6)
    R0 = johnson_resistance(exact, spheroidal_profile(0.004, L), n=32)
    R1 = johnson_resistance(line, spheroidal_profile(0.004, line.length), n=32)
    assert np.abs(R1 - R0).max() < 1e-4 * np.abs(R0).max()


@pytest.mark.parametrize("aob", [0.225, 0.5])
def test_chain_effective_radii_long_straight_chain(aob):
    # the analytic bead-chain radii against a long straight chain (801 beads) with a uniform
    # force per length: the middle bead moves as Eq. (2) of a uniform body of length N b says,
    # along (2 L - 2) and across (L + 1). Error O(N^-2): measured < 2e-7
    N, b = 801, 1.0
    a = aob * b
    rp, rn = chain_effective_radii(a, b)
    x = straight_chain(N, b)
    Lb = N * b
    for d, pred in ((np.array([0.0, 0.0, 1.0]), 2 * math.log(Lb**2 / rp**2) - 2),
                    (np.array([1.0, 0.0, 0.0]), math.log(Lb**2 / rn**2) + 1)):
        u = RPYMobility(a).apply(x, np.tile(d * b, (N, 1)))[N // 2] @ d
        assert 8 * math.pi * u == pytest.approx(pred, rel=1e-6)
    # one radius along and another across, except near touching beads
    if aob == 0.225:
        assert rp / rn == pytest.approx(1.755, rel=1e-3)
    else:
        assert 1.0 < rp / rn < 1.1


def test_bead_helix_is_the_simulators():
    from flagwrap.geometry.helix import helix_positions

    L, Rh, N = 1.0, 0.075, 61
    P = helix_pitch(L, Rh, 2.0)
    beads, _ = bead_helix(L, Rh, P, N)
    bonds = np.linalg.norm(np.diff(beads, axis=0), axis=1)
    np.testing.assert_allclose(bonds, L / (N - 1), rtol=1e-12)
    # the simulator's helix after its clamp bond: N + 1 beads at the same chord L / (N - 1)
    ref = helix_positions(L * N / (N - 1), Rh, P, N + 1)[1:]
    d_ref = np.linalg.norm(ref[:, None] - ref[None], axis=-1)
    np.testing.assert_allclose(np.linalg.norm(beads[:, None] - beads[None], axis=-1), d_ref,
                               atol=1e-12)


# the bead helix against SBT -----------------------------------------------------------------
# Tolerance: the slender body (spheroidal ends) is calibrated on the straight chain's axial
# and transverse drags; its error on the chain is the end shape (the chain is blunt), which
# the straight chain's one uncalibrated entry, the rotation across (the most end-weighted
# rigid motion), measures: 5.97 % at a/b = 0.225 and 8.99 % at a/b = 0.5 -> 6 % and 9 %.
TOL = {0.225: 0.06, 0.5: 0.09}


@pytest.fixture(scope="module")
def fig4a():
    return compare_helix()  # R = 0.075 L, 2 turns, 61 beads, a = 0.225 b


def _check(c, model, tol):
    assert abs(c["straight_rotation_error"]) <= tol  # the error bound itself
    Rb, Rs = c["beads"], c[model]
    for vb, vs in zip(propulsion_coefficients(Rb), propulsion_coefficients(Rs)):
        assert vs == pytest.approx(vb, rel=tol)
    assert normalised_deviation(Rs, Rb).max() <= tol


def test_fig4a_helix_two_radii(fig4a):
    # A, B, D: measured +0.29 %, -1.38 %, +1.48 %; max normalised deviation of the 36
    # entries 5.0 % (T-Omega, rotation across the helix axis: end-weighted, like the bound)
    c = fig4a
    assert c["r_par"] / c["a"] == pytest.approx(1.0216, rel=1e-3)
    assert c["r_perp"] / c["a"] == pytest.approx(0.5708, rel=1e-3)
    _check(c, "two", TOL[0.225])


@pytest.mark.xfail(strict=True, reason="one radius cannot describe the simulator's chain "
                   "(b = 4.4 a): along and across it behaves as slender bodies of radii "
                   "1.02 a and 0.57 a, so B comes out +36 % and A +7 % (docs/bacterium.md)")
def test_fig4a_helix_one_radius(fig4a):
    _check(fig4a, "one", TOL[0.225])


def test_touching_beads_one_radius():
    # touching beads (a = b/2) are close to a slender body of one radius
    # (chain_effective_radii: ratio 1.07): the single axial-calibrated radius predicts A, B,
    # D to +1.7 %, +3.3 %, +3.4 %, all 36 entries to 6.2 % (normalised)
    c = compare_helix(bead_radius=0.5 / 60)
    _check(c, "one", TOL[0.5])
    _check(c, "two", TOL[0.5])


def test_handedness_flips_the_coupling():
    L, Rh = 1.0, 0.075
    P = helix_pitch(L, Rh, 2.0)
    Bs = []
    for h in ("left", "right"):
        line = bead_chain_centreline(L, Rh, P, 61, h)
        Bs.append(propulsion_coefficients(johnson_resistance(
            line, spheroidal_profile(0.004, line.length), n=24))[1])
    assert Bs[0] == pytest.approx(-Bs[1], rel=1e-10)
    # left-handed about z: B > 0, so a free one turning about +z swims to -z (U = -B Omega/A)
    assert Bs[0] > 0


@pytest.mark.slow
def test_discrepancy_shrinks_with_finer_chains():
    # at fixed a/b = 0.225, more beads on the same helix: measured |rel. error| of B
    # 3.2 %, 1.4 %, 0.62 %, 0.28 % and of D 2.4 %, 1.5 %, 1.0 %, 0.74 % at N = 31, 61, 121, 241
    errs = []
    for N in (31, 61, 121, 241):
        c = compare_helix(n_beads=N, bead_radius=0.225 / (N - 1))
        errs.append([abs(s / b - 1) for s, b in zip(propulsion_coefficients(c["two"]),
                                                    propulsion_coefficients(c["beads"]))])
    errs = np.array(errs)
    assert np.all(np.diff(errs, axis=0) < 0)


@pytest.mark.slow
def test_blunter_ends_shrink_the_discrepancy():
    # the residual is the end shape: blunter SBT ends (p = 2, 4, 8, 12) bring A, B, D and the
    # straight rotation closer to the blunt bead chain, monotonically
    errs = []
    for p in (2, 4, 8, 12):
        c = compare_helix(p=p)
        e = [abs(s / b - 1) for s, b in zip(propulsion_coefficients(c["two"]),
                                            propulsion_coefficients(c["beads"]))]
        errs.append(e + [abs(c["straight_rotation_error"])])
    assert np.all(np.diff(np.array(errs), axis=0) < 0)
