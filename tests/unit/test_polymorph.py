"""The polymorph order parameter (flagwrap.elasticity.polymorph) against independent answers:
a numerically minimised discrete domain wall against the analytic tanh wall, the energy
gradients against finite differences, a quasi-static torque sweep against the analytic
spinodal and Maxwell torques, and the one-state limit against the fixed rest shape."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.optimize import brentq, minimize, minimize_scalar

from flagwrap.elasticity import polymorph as pm
from flagwrap.errors import UserInputError

MODEL = pm.PolymorphModel(barrier=2.0, stiffness=0.3, delta_twist=1.5, maxwell_torque=0.4)


def _minimise(fun_grad, x0):
    r = minimize(fun_grad, x0, jac=True, method="L-BFGS-B",
                 options=dict(gtol=1e-12, ftol=1e-15, maxiter=20000))
    return r


def static_wall(model, b, n):
    """The discrete energy (P3) at zero tilt minimised on ``n`` vertices ``b`` apart with the
    end vertices held in the two wells (-1 and +1); the interior starts as a step."""
    s = np.arange(n) * b
    ends = np.array([-1.0, 1.0])
    x0 = np.sign(s[1:-1] - s[-1] / 2)  # symmetric: 0 on the middle vertex of an odd chain

    def fg(x):
        p = np.concatenate([ends[:1], x, ends[1:]])
        return (pm.total_energy(p, model, model.maxwell_torque, b, b),
                pm.total_energy_grad(p, model, model.maxwell_torque, b, b)[1:-1])

    r = _minimise(fg, x0)
    assert r.success, r.message
    return s, np.concatenate([ends[:1], r.x, ends[1:]]), r.fun


def _fit_wall(s, phi):
    from scipy.optimize import curve_fit
    popt, _ = curve_fit(lambda s, s0, w: np.tanh((s - s0) / w), s, phi, p0=[s[-1] / 2, 1.0])
    return popt


# --- (a) the static domain wall -------------------------------------------------------
def test_discrete_wall_matches_tanh_profile_width_and_energy():
    """b/w = 0.1 on a chain 16 w long (ends at +-8 w: finite-length error ~ 2 e^-16).
    Central differences make every error second order, c (b/w)^2 with c ~ 0.03-0.1
    (measured: energy 0.033, width 0.092, profile 0.056): bounds at 1.5-3x those."""
    w = MODEL.wall_width
    b = 0.1 * w
    s, phi, energy = static_wall(MODEL, b, 161)
    s0, w_fit = _fit_wall(s, phi)
    eps = (b / w) ** 2
    assert abs(s0 - s[-1] / 2) < 1e-6 * b  # by symmetry, centred
    assert abs(w_fit / w - 1) < 0.15 * eps
    assert np.max(np.abs(phi - pm.wall_profile(s, s0, w))) < 0.1 * eps
    assert abs(energy / MODEL.wall_energy - 1) < 0.1 * eps


def test_discrete_wall_energy_converges_at_second_order():
    """Halving b/w cuts the energy error 4x (second order), from below (the lattice
    underestimates the gradient energy of a smooth profile): 3 < ratio < 5."""
    w = MODEL.wall_width
    errs = []
    for ratio, n in ((0.2, 81), (0.1, 161)):
        _, _, energy = static_wall(MODEL, ratio * w, n)
        errs.append(energy / MODEL.wall_energy - 1)
    assert errs[0] < 0 and errs[1] < 0
    assert 3.0 < errs[0] / errs[1] < 5.0


# --- (b) gradients against finite differences -----------------------------------------
@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(2, 40),
       torque=st.floats(-5, 5), nonuniform=st.booleans())
def test_energy_gradients_match_finite_differences(seed, n, torque, nonuniform):
    """Central differences with step 1e-6 have error ~ h^2 |E'''| ~ 1e-12 x O(10^2):
    agreement to 1e-6 relative to the gradient's scale."""
    rng = np.random.default_rng(seed)
    phi = rng.uniform(-1.5, 1.5, n)
    vor = rng.uniform(0.01, 0.1, n) if nonuniform else 0.05
    lengths = rng.uniform(0.01, 0.1, n - 1) if nonuniform else 0.05
    g = pm.total_energy_grad(phi, MODEL, torque, vor, lengths)
    h = 1e-6
    fd = np.empty(n)
    for i in range(n):
        e = np.zeros(n)
        e[i] = h
        fd[i] = (pm.total_energy(phi + e, MODEL, torque, vor, lengths)
                 - pm.total_energy(phi - e, MODEL, torque, vor, lengths)) / (2 * h)
    scale = 1.0 + np.max(np.abs(g))
    np.testing.assert_allclose(g, fd, atol=1e-6 * scale)
    # the two parts separately (each is used on its own when wired)
    gl = pm.local_energy_grad(phi, MODEL, torque, vor)
    gg = pm.gradient_energy_grad(phi, MODEL.stiffness, lengths)
    np.testing.assert_allclose(gl + gg, g, rtol=0, atol=1e-14 * scale)


@settings(max_examples=20, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(2, 30))
def test_hessian_bands_match_finite_differences_of_the_gradient(seed, n):
    rng = np.random.default_rng(seed)
    phi = rng.uniform(-1.5, 1.5, n)
    vor, lengths = rng.uniform(0.01, 0.1, n), rng.uniform(0.01, 0.1, n - 1)
    main, off = pm.total_energy_hessian_bands(phi, MODEL, vor, lengths)
    hess = np.diag(main) + np.diag(off, 1) + np.diag(off, -1)
    h = 1e-6
    fd = np.array([(pm.total_energy_grad(phi + h * e, MODEL, 0.3, vor, lengths)
                    - pm.total_energy_grad(phi - h * e, MODEL, 0.3, vor, lengths)) / (2 * h)
                   for e in np.eye(n)])
    np.testing.assert_allclose(hess, fd, atol=1e-6 * (1 + np.max(np.abs(hess))))


@settings(max_examples=20, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(1, 12))
def test_elastic_phi_gradient_matches_finite_differences(seed, n):
    rng = np.random.default_rng(seed)
    ka, kb = rng.normal(size=(n, 2)), rng.normal(size=(n, 2))
    ma, mb = rng.normal(size=n), rng.normal(size=n)
    kappa, m = rng.normal(size=(n, 2)), rng.normal(size=n)
    cb, ct = rng.uniform(0.5, 2, n), rng.uniform(0.5, 2, n)
    phi = rng.uniform(-1.2, 1.2, n)

    def energy(p):
        kbar = pm.interpolate_rest(ka, kb, p)
        mbar = pm.interpolate_rest(ma, mb, p)
        return np.sum(0.5 * cb * np.sum((kappa - kbar) ** 2, axis=1) + 0.5 * ct * (m - mbar) ** 2)

    g = pm.elastic_phi_gradient(kappa, m, ka, kb, ma, mb, phi, cb, ct)
    h = 1e-6
    fd = np.array([(energy(phi + h * e) - energy(phi - h * e)) / (2 * h) for e in np.eye(n)])
    np.testing.assert_allclose(g, fd, atol=1e-7 * (1 + np.max(np.abs(g))))


def test_twist_moment_enters_as_the_tilt():
    """At a fixed twist moment N = ctwist (m - mbar), the rod's twist term pushes phi with
    -N dmbar/dphi = -N Delta_m / 2 per vertex: (P2)'s tilt times the vertex length when
    Delta_m = Delta l. Straight rest (no bending), 5 vertices."""
    n, l, N = 5, 0.1, 0.7
    model = pm.PolymorphModel(1.0, 0.01, delta_twist=2.0, maxwell_torque=0.0)
    ma, mb = np.zeros(n), np.full(n, model.delta_twist * l)
    phi = np.linspace(-0.9, 0.9, n)
    ct = np.full(n, 0.8 / l)
    m = pm.interpolate_rest(ma, mb, phi) + N / ct
    z = np.zeros((n, 2))
    g = pm.elastic_phi_gradient(z, m, z, z, ma, mb, phi, np.ones(n), ct)
    tilt_grad = -model.tilt(N) * l  # d/dphi of -h phi v_i
    np.testing.assert_allclose(g, tilt_grad, rtol=1e-13)


# --- (c) quasi-static loading: spinodals, hysteresis, Maxwell --------------------------
def _hessian(phi, model, b):
    main, off = pm.total_energy_hessian_bands(phi, model, b, b)
    return np.diag(main) + np.diag(off, 1) + np.diag(off, -1)


def _sweep(model, torques, phi0, b):
    """Quasi-static: at each torque a trust-region Newton descent from the previous state,
    its step capped at 0.05 (L2 over the chain) so that it follows the downhill path and
    cannot leap over a small barrier into the other well, as a line search can."""
    phi, means = phi0.copy(), []
    for N in torques:
        r = minimize(lambda x: pm.total_energy(x, model, N, b, b), phi, method="trust-exact",
                     jac=lambda x: pm.total_energy_grad(x, model, N, b, b),
                     hess=lambda x: _hessian(x, model, b),
                     options=dict(gtol=1e-10, initial_trust_radius=0.01, max_trust_radius=0.05))
        # status 2 ("failure to predict improvement") is the energy's rounding floor
        assert r.success or np.max(np.abs(r.jac)) < 1e-8, r.message
        phi = r.x
        means.append(phi.mean())
    return np.array(means)


@pytest.mark.parametrize("delta", [1.5, -0.8])
def test_quasistatic_sweep_switches_at_the_spinodal_torques(delta):
    """Torque stepped up then down by 0.01 H on a 30-vertex chain with free ends, minimised
    from the previous state (a small random ripple on the start): the state stays in its
    well until the well vanishes (P6), so each switch falls in the step that crosses
    N_M +- H. Tolerance: one step."""
    model = pm.PolymorphModel(2.0, 0.3, delta, maxwell_torque=0.4)
    H = model.spinodal_half_width
    step = 0.01 * H
    # offset by half a step: no torque lies on a threshold (there the well is an inflection)
    up = model.maxwell_torque + np.arange(-1.5 * H + step / 2, 1.5 * H, step)
    n, b = 30, 0.05
    start = -1.0 if delta > 0 else 1.0  # the well that rising torque destabilises
    phi0 = start + 0.01 * np.random.default_rng(7).normal(size=n)
    m_up = _sweep(model, up, phi0, b)
    i = int(np.argmax(np.sign(m_up) != np.sign(start)))
    assert i > 0 and np.sign(m_up[-1]) != np.sign(start), "no switch on the way up"
    assert up[i - 1] < max(model.switch_torques) < up[i]  # rising N meets the upper one
    down = up[::-1]
    m_down = _sweep(model, down, np.full(n, -start), b)
    j = int(np.argmax(np.sign(m_down) == np.sign(start)))
    assert j > 0 and np.sign(m_down[-1]) == np.sign(start), "no switch on the way down"
    assert down[j - 1] > min(model.switch_torques) > down[j]
    # the loop is open between the thresholds: two states at N_M
    k = int(np.argmin(np.abs(up - model.maxwell_torque)))
    assert np.sign(m_up[k]) != np.sign(m_down[len(up) - 1 - k])
    # and A -> B is the threshold the model names first
    fwd, back = model.switch_torques
    assert (fwd > back) == (delta > 0)
    assert fwd - back == pytest.approx(2 * math.copysign(H, delta), rel=1e-14)


def test_maxwell_torque_is_where_the_wells_have_equal_energy():
    """The two local minima of the uniform energy density found numerically (bounded scalar
    minimisation in each half), their difference zeroed by root finding in N: N_M (P7)."""
    def well_gap(N):
        f = lambda p: MODEL.barrier * pm.double_well(p) - MODEL.tilt(N) * p  # noqa: E731
        lo = minimize_scalar(f, bounds=(-2, 0), method="bounded", options=dict(xatol=1e-12)).fun
        hi = minimize_scalar(f, bounds=(0, 2), method="bounded", options=dict(xatol=1e-12)).fun
        return hi - lo

    H = MODEL.spinodal_half_width
    n_eq = brentq(well_gap, MODEL.maxwell_torque - 0.9 * H, MODEL.maxwell_torque + 0.7 * H,
                  xtol=1e-12)
    assert n_eq == pytest.approx(MODEL.maxwell_torque, abs=1e-8)
    # B (phi = +1) is favoured above N_M when Delta > 0
    assert well_gap(MODEL.maxwell_torque + 0.1 * H) < 0


def test_from_thresholds_reproduces_the_loop_and_the_wall():
    model = pm.PolymorphModel.from_thresholds(-1.1, 0.4, delta_twist=-4.6, wall_width=0.3)
    assert model.switch_torques == pytest.approx((-1.1, 0.4), rel=1e-14)
    assert model.maxwell_torque == pytest.approx(-0.35)
    assert model.wall_width == pytest.approx(0.3, rel=1e-14)
    with pytest.raises(UserInputError, match="torque_forward"):
        pm.PolymorphModel.from_thresholds(-1.1, 0.4, delta_twist=4.6, wall_width=0.3)


def test_wall_narrower_than_a_bond_is_refused():
    assert pm.check_wall_resolution(0.3, 0.1) == 0.3
    with pytest.raises(UserInputError, match=r"polymorph.wall_width must be >= the bead spacing"):
        pm.check_wall_resolution(0.05, 0.1)


# --- (d) the one-state limit -----------------------------------------------------------
def test_one_state_filament_keeps_its_rest_shape_exactly():
    """A = B: every phi gives the rod's own rest curvature and twist bit for bit, no force on
    phi from the elastic energy, and no tilt (the load cannot switch it)."""
    from flagwrap.elasticity.rod import initial_frames, rest_state
    t = np.linspace(0, 4 * np.pi, 25)
    x = np.stack([0.1 * np.cos(t), -0.1 * np.sin(t), 0.05 * t], axis=1)
    frames = initial_frames(x)
    rest = rest_state(x, frames, np.zeros(len(x) - 1))
    rng = np.random.default_rng(3)
    phi = rng.uniform(-3, 3, len(x))
    kbar = pm.interpolate_rest(rest.kbar, rest.kbar, phi)
    mbar = pm.interpolate_rest(rest.mbar, rest.mbar, phi)
    assert np.array_equal(kbar, rest.kbar) and np.array_equal(mbar, rest.mbar)
    g = pm.elastic_phi_gradient(rng.normal(size=rest.kbar.shape), rng.normal(size=len(x)),
                                rest.kbar, rest.kbar, rest.mbar, rest.mbar, phi,
                                rest.cbend, rest.ctwist)
    assert np.all(g == 0.0)
    one = pm.PolymorphModel(1.0, 0.1, delta_twist=0.0)
    assert one.tilt(123.0) == 0.0 and one.spinodal_half_width == math.inf


def test_helix_curvature_torsion_of_a_known_helix():
    """R = 1, P = 2 pi: kappa = tau = 1/2; left-handed flips the torsion's sign only."""
    assert pm.helix_curvature_torsion(1.0, 2 * math.pi, "right") == pytest.approx((0.5, 0.5))
    assert pm.helix_curvature_torsion(1.0, 2 * math.pi, "left") == pytest.approx((0.5, -0.5))
    with pytest.raises(UserInputError, match="handedness"):
        pm.helix_curvature_torsion(1.0, 1.0, "up")


# --- the polymorph library -------------------------------------------------------------
try:  # noqa: E402
    import tomllib
except ImportError:  # pragma: no cover - Python 3.10
    import tomli as tomllib

from flagwrap.elasticity import polymorph_library as pl  # noqa: E402


def _packaged_doc():
    from importlib import resources
    return tomllib.loads(resources.files("flagwrap").joinpath("data/polymorphs.toml")
                         .read_text(encoding="utf-8"))


def test_packaged_library_loads_with_a_source_for_every_number():
    lib = pl.default_library()
    normal = lib.polymorph("ecoli_normal")
    assert (normal.radius_um.value, normal.pitch_um.value, normal.handedness.value) == (0.2, 2.3, "left")
    semi = lib.polymorph("ecoli_semicoiled")
    assert semi.handedness.value == "right" and semi.pitch_um.value == pytest.approx(2.3 / 2)
    t = lib.transition("salmonella_normal_semicoiled")
    assert (t.torque_forward_pn_um.value, t.torque_back_pn_um.value) == (-1.1, 0.4)
    assert "Hotani" in t.torque_forward_pn_um.source and t.wall_width_um.value is None
    assert lib.bending_stiffness_pn_um2.value == 3.5
    for p in lib.polymorphs:
        for f in (p.radius_um, p.pitch_um, p.handedness):
            assert f.source.strip() and (f.value is None) == (f.status == "gap")
    # the gaps are flagged, and refuse to be used silently
    coiled = lib.polymorph("ecoli_coiled")
    assert not coiled.known
    with pytest.raises(UserInputError, match="ecoli_coiled.*radius_um is a gap"):
        coiled.curvature_torsion_per_um()
    k, tau = normal.curvature_torsion_per_um()
    assert tau < 0 < k  # left-handed


def test_hotani_loop_gives_a_model_with_the_stated_thresholds():
    """Hotani's two torques as the model's spinodals (P6), with the E. coli normal and
    semicoiled torsions as Delta (a cross-organism stand-in, flagged in the docs)."""
    lib = pl.default_library()
    t = lib.transition("salmonella_normal_semicoiled")
    _, tau_a = lib.polymorph("ecoli_normal").curvature_torsion_per_um()
    _, tau_b = lib.polymorph("ecoli_semicoiled").curvature_torsion_per_um()
    # forward (A -> B) needs the negative torque, so Delta < 0 as the model requires
    model = pm.PolymorphModel.from_thresholds(t.torque_forward_pn_um.value,
                                              t.torque_back_pn_um.value, tau_a - tau_b,
                                              wall_width=0.5)
    assert model.switch_torques == pytest.approx((-1.1, 0.4))
    assert model.maxwell_torque == pytest.approx(-0.35)


def _edited(path, value, doc=None):
    doc = doc or _packaged_doc()
    node = doc
    for k in path[:-1]:
        node = node[k]
    if value is None:
        del node[path[-1]]
    else:
        node[path[-1]] = value
    return doc


@pytest.mark.parametrize("path,value,message", [
    (("transition", 0, "to"), "salmonella_curly",
     r"^<toml>: transition 'salmonella_normal_semicoiled': to = 'salmonella_curly' is not a "
     r"polymorph of the library; allowed: ecoli_normal, "),
    (("polymorph", 0, "radius_um"), None,
     r"^<toml>: polymorph 'ecoli_normal': radius_um is missing; give a value in \(0, 1e\+06\) um"),
    (("polymorph", 1, "pitch_um"), None, r"^<toml>: polymorph 'ecoli_semicoiled': pitch_um is missing"),
    (("transition", 0, "torque_forward_pn_um", "value"), 1.1,
     r"^<toml>: transition 'salmonella_normal_semicoiled': torque_forward_pn_um must be in "
     r"\(-1e\+06, 0\) pN um \(negative"),
    (("transition", 0, "torque_back_pn_um", "value"), -0.4,
     r"torque_back_pn_um must be in \(0, 1e\+06\) pN um \(positive"),
    (("polymorph", 0, "pitch_um", "source"), None, r"ecoli_normal': pitch_um needs a non-empty 'source'"),
    (("polymorph", 0, "handedness", "value"), "up", r"handedness must be 'left' or 'right'"),
    (("polymorph", 3, "radius_um", "value"), 0.3, r"ecoli_coiled': radius_um has status 'gap' but a value"),
])
def test_bad_library_entries_are_one_line_naming_the_key(path, value, message):
    with pytest.raises(UserInputError, match=message) as exc:
        pl.parse_library(_edited(path, value))
    assert "\n" not in str(exc.value)


def test_unknown_polymorph_name_and_unresolved_wall_are_refused():
    lib = pl.default_library()
    with pytest.raises(UserInputError, match=r"^unknown polymorph 'curly2'; allowed: ecoli_normal"):
        lib.polymorph("curly2")
    t = lib.transition("salmonella_normal_semicoiled")
    with pytest.raises(UserInputError, match=r"wall_width_um is a gap in the library"):
        t.wall_width(bead_spacing_um=0.1)
    assert t.wall_width(0.1, wall_width_um=0.5) == 0.5
    with pytest.raises(UserInputError, match=r"^transition 'salmonella_normal_semicoiled': "
                                             r"wall_width_um must be >= the bead spacing 0.1 "):
        t.wall_width(0.1, wall_width_um=0.05)


def test_library_file_errors_are_one_line(tmp_path):
    with pytest.raises(UserInputError, match="polymorph library not found"):
        pl.load_library_file(tmp_path / "nope.toml")
    bad = tmp_path / "bad.toml"
    bad.write_text("[[polymorph]\n")
    with pytest.raises(UserInputError, match="invalid TOML"):
        pl.load_library_file(bad)
