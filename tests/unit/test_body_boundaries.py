"""A fixed boundary seen from a moving body (flagwrap.body.boundaries) and the free cell that
swims against it (flagwrap.system.swimmer): the tube's screening against Haberman & Sayre and
the joint blob solve, its covariance under the pose, and the boundary's push taken as an
external load (the fluid takes it; the body does not carry it back)."""

import math

import numpy as np
import pytest
import tomllib
from conftest import NO_SLIP_BODY, tiny_toml

from flagwrap.body.boundaries import TubeFromBody, WallFromBody
from flagwrap.body.multiblob import effective_radii, geometric_matrix, icosphere
from flagwrap.confinement.tube import BLOB_RADIUS_RATIO, Tube, rigid_body_drag
from flagwrap.geometry.frames import quaternion_matrix
from flagwrap.hydrodynamics.polydisperse import PolydisperseRPY
from flagwrap.hydrodynamics.wall import PlaneWall
from flagwrap.io.config import config_from_dict
from flagwrap.theory.wall_drag import haberman_sayre

#: the tiny cell (body radius 0.058 m, filament out to 0.06 m from the axis) in a tube of
#: radius 0.07 m about the motor axis
TUBE = "[[tube]]\nradius = 0.07\nlength = 0.7\ncenter = [0.0, 0.0, -0.1]\nblob_spacing = 0.035\n"
#: a plane beside it, tilted (not square to the axis)
WALL = "[[wall]]\npoint = [0.0715, 0.0, 0.0]\nnormal = [-1.0, 0.0, 0.02]\n"


def _sphere(lam):
    u = icosphere(2)
    from scipy.spatial import cKDTree

    d, _ = cKDTree(u).query(u, k=2)
    ab = 0.5 * lam * d[:, 1].mean()  # half the spacing, as the cell body's blobs
    return lam * u, ab


def _mobility(view, blobs, radii):
    """The rigid body's 6 x 6 mobility ``(K^T M~^-1 K)^-1`` with the boundary's Delta."""
    M = PolydisperseRPY(radii).matrix(blobs) + view.correction_matrix(blobs, radii, blobs,
                                                                      radii)
    K = geometric_matrix(blobs)
    return np.linalg.inv(K.T @ np.linalg.solve(M, K))


@pytest.mark.parametrize("lam", [0.1, 0.3, 0.5])
def test_sphere_in_a_tube_seen_from_itself_is_the_joint_solve_and_haberman_sayre(lam):
    """A blob sphere on the axis of a closed blob tube (R_t = 1, blobs 0.2 apart): its
    mobility from the tube's Schur complement, seen from the sphere at a turned and shifted
    pose, against (a) the joint blob solve of the held sphere (rigid_body_drag: the same
    equations solved at once, to 1e-8) and (b) Haberman & Sayre's factor, 1 % (this tube's
    measured accuracy: docs/confinement.md, within 0.4 % for a/R_t <= 0.5)."""
    t = Tube(1.0, 4.0, closed=True)
    h = 0.2
    tb = t.blob_shell(h, BLOB_RADIUS_RATIO * h)
    sb, ab = _sphere(lam)
    radii = np.full(len(sb), ab)
    a = effective_radii(sb, ab)[0]
    tube = TubeFromBody(t, tb, BLOB_RADIUS_RATIO * h)
    # the sphere's own frame turned about a tilted axis (its blobs move with it): the lab
    # geometry is the same, so its translational drag along the tube's axis is too
    q = np.array([0.9, 0.2, -0.3, 0.25])
    R = quaternion_matrix(q / np.linalg.norm(q))
    N = _mobility(tube.at(np.zeros(3), R), sb @ R.T @ R, radii)  # body coords = sb
    zeta = np.linalg.inv(N)[:3, :3]  # translation drag, body axes
    drag_lab = R @ zeta @ R.T
    F = rigid_body_drag(tb, BLOB_RADIUS_RATIO * h, sb @ R.T, ab, (0.0, 0.0, 1.0))
    # rigid_body_drag holds the sphere from turning: the same as inverting the full N only
    # without translation-rotation coupling, which a sphere on the axis has not
    assert np.abs(N[:3, 3:]).max() < 1e-6 * np.abs(N[:3, :3]).max()
    assert drag_lab[2, 2] == pytest.approx(-F[2], rel=1e-8)
    assert drag_lab[2, 2] / (6 * math.pi * a) == pytest.approx(haberman_sayre(a), rel=0.01)


def _random_pose(rng):
    q = rng.standard_normal(4)
    return 0.1 * rng.standard_normal(3), quaternion_matrix(q / np.linalg.norm(q))


@pytest.mark.parametrize("kind", ["tube", "wall"])
def test_delta_seen_from_the_body_is_the_labs_turned(kind, rng):
    """``Delta`` at body-frame points, pose ``(X, R)``, is ``R^T Delta_lab R`` block by block
    of the same points in the lab (RPY and Blake are covariant): to 1e-12; symmetric; and
    the product is the matrix's."""
    if kind == "tube":
        t = Tube(1.0, 3.0, center=(0.1, -0.2, 0.3), axis=(0.2, 0.1, 1.0))
        b = TubeFromBody(t, t.blob_shell(0.3, 0.3), 0.3)
    else:
        b = WallFromBody(PlaneWall([0.0, 0.0, -1.0], [0.1, 0.2, 1.0]))
    X, R = _random_pose(rng)
    x = 0.4 * rng.standard_normal((12, 3))
    a = np.full(len(x), 0.05)
    D = b.at(X, R).correction_matrix(x, a)
    lab = b.at(np.zeros(3), np.eye(3)).correction_matrix(x @ R.T + X, a)
    Rb = np.kron(np.eye(len(x)), R)
    assert np.abs(D - Rb.T @ lab @ Rb).max() < 1e-12 * np.abs(D).max()
    assert np.abs(D - D.T).max() < 1e-12 * np.abs(D).max()
    F = rng.standard_normal((len(x), 3))
    v = b.at(X, R).correction_apply(x, a, x, a, F)
    assert np.abs(v.ravel() - D @ F.ravel()).max() < 1e-10 * np.abs(v).max()
    # a cross block between two sets is the square one's off-diagonal block
    C = b.at(X, R).correction_matrix(x[:5], a[:5], x[5:], a[5:])
    assert np.abs(C - D[:15, 15:]).max() < 1e-12 * np.abs(D).max()


def test_the_tubes_screening_leaves_the_mobility_positive_definite(rng):
    """``M + Delta`` of spheres inside the tube is the Schur complement of a positive
    definite joint matrix: symmetric positive definite, and below the free ``M`` (the wall
    only slows them)."""
    t = Tube(1.0, 3.0)
    b = TubeFromBody(t, t.blob_shell(0.25, 0.25), 0.25)
    x = np.column_stack([0.5 * rng.uniform(-1, 1, (20, 2)), rng.uniform(-1, 1, 20)])
    a = np.full(len(x), 0.03)
    D = b.at(np.zeros(3), np.eye(3)).correction_matrix(x, a)
    M = PolydisperseRPY(a).matrix(x)
    assert np.linalg.eigvalsh(M + D).min() > 0
    assert np.linalg.eigvalsh(D).max() < 1e-12 * np.abs(D).max()


def _cell(extra, frame="lab"):
    from flagwrap.simulation import make_system

    text = tiny_toml().replace("[numerics]\n", f"[numerics]\nframe = '{frame}'\n", 1)
    return make_system(config_from_dict(tomllib.loads(text + NO_SLIP_BODY + "motion = 'free'\n"
                                                      + extra)))


def _pressed(s, rng):
    """A state of the free cell shifted 0.018 L along x (its filament's far side within the
    contact range of the tube or the wall) and turned a little about the axis."""
    y = s.initial_y()
    y[s.sl_x] += 0.002 * s.bond * rng.standard_normal(s.sl_x.stop - s.sl_x.start)
    y[s.sl_X] = [0.018, 0.0, 0.0]
    c, sn = math.cos(0.05), math.sin(0.05)
    y[s.sl_q] = [c, 0.0, 0.0, sn]
    return y


@pytest.mark.parametrize("extra", [TUBE, WALL], ids=["tube", "tilted wall"])
def test_the_filaments_contact_is_placed_at_the_bodys_pose(extra, rng):
    """The beads meet the boundary where it is in the lab: their contact energy and forces
    at a shifted, turned pose are those of the lab boundary on the lab positions (the body
    frame's forces turned back), and some beads touch."""
    from flagwrap.interactions.wall import TubeContact, WallContact

    s = _cell(extra)
    y = _pressed(s, rng)
    info = s.forces(y, s.frames0.copy())
    X, R = s.pose(y)
    (it,) = s._bead_contacts
    lab = (TubeContact(s.tube, it.cutoff, it.strength, it.active, it.c2) if s.tube is not None
           else WallContact(s.wall, it.cutoff, it.strength, it.active, it.c2))
    g = np.zeros((s.N, 3))
    e = lab.energy_grad(info.x @ R.T + X, info.theta, g, np.zeros(len(info.theta)))
    assert e > 0 and it.energy == pytest.approx(e, rel=1e-12)
    s0 = _cell("")  # the same cell without a boundary: the difference is the contact
    G0 = s0.forces(y[:s0.ny] if len(y) == s0.ny else np.concatenate(
        [y[:s.n_in], y[s.n_in:]]), s0.frames0.copy()).G
    dF = (info.G - G0)[s.sl_x].reshape(-1, 3)
    assert np.abs(dF + g[s.free_beads] @ R).max() < 1e-10 * np.abs(g).max()


@pytest.mark.parametrize("extra", [TUBE, WALL], ids=["tube", "tilted wall"])
def test_the_fluid_takes_the_boundarys_push(extra, rng):
    """Force and torque balance of the whole cell against the boundary: the force and
    torque its blobs and beads exert on the fluid are the boundary's push on the cell
    (:meth:`external_load`), which is minus the gradient of the total contact energy (beads
    and blobs) under a rigid motion of the cell (central differences, 1e-6); with a
    boundary out of reach, both vanish."""
    s = _cell(extra)
    y = _pressed(s, rng)
    base = s.frames0.copy()
    info = s.forces(y, base)
    _, _, lam = s.body_velocity(y, info.G)
    x, _, _ = s.unpack(y)
    F = info.G[s.sl_x].reshape(-1, 3)
    xf = x[s.free_beads]
    lam = lam.reshape(-1, 3)
    tau = info.G[s.sl_th]
    t = info.frames.t[s.free_bonds]
    on_fluid = np.concatenate([lam.sum(0) + F.sum(0), np.cross(s.blobs, lam).sum(0)
                               + np.cross(xf, F).sum(0) + tau @ t])
    ext = s.external_load(y)
    assert np.abs(ext[:3]).max() > 0
    assert np.abs(on_fluid - ext).max() < 1e-8 * np.abs(ext).max()

    # -dU/d(rigid translation along each body axis) of every contact energy
    def energy(dX):
        yy = y.copy()
        R = s.pose(y)[1]
        yy[s.sl_X] = y[s.sl_X] + R @ dX
        s._body_cache = (None, None)
        s.forces(yy, base)
        (it,) = s._bead_contacts
        view = s._view(yy)
        g, _ = view.gap_gradient(s.blobs)
        e, _, _ = s._boundary_contact.law(g - s.blob_radii)
        return it.energy + e.sum()

    h = 1e-7
    grad = [(energy(h * e) - energy(-h * e)) / (2 * h) for e in np.eye(3)]
    assert np.allclose(-np.array(grad), ext[:3], rtol=1e-5, atol=1e-6 * np.abs(ext[:3]).max())


def test_screened_blob_solve_away_from_its_reference_is_the_exact_one(rng):
    """The body's blob solve in a tube at a pose other than its factor's (conjugate gradients
    preconditioned by the reference factor) against the exact matrix of that pose solved
    densely: 1e-8 (CG stops at 1e-11 of the residual; the matrix's condition number ~1e3);
    at the reference pose it is the factor's own solve (1e-11: two dense solves' rounding); a solve that needs more than
    ``refresh_iterations`` rebuilds the factor at its pose."""
    t = Tube(1.0, 3.0)
    tube = TubeFromBody(t, t.blob_shell(0.25, 0.25), 0.25)
    sb, ab = _sphere(0.5)
    radii = np.full(len(sb), ab)
    K = geometric_matrix(sb)
    M0 = PolydisperseRPY(radii).matrix(sb)

    def exact(X, R):
        M = M0 + tube.at(X, R).correction_matrix(sb, radii, sb, radii)
        return np.linalg.solve(M, K)

    key0 = np.array([0, 0, 0, 1.0, 0, 0, 0])
    s0 = tube.blob_solver(tube.at(np.zeros(3), np.eye(3)), sb, radii, key0)
    X = np.array([0.01, -0.005, 0.02])
    q = np.array([1.0, 0.01, -0.01, 0.1]) / np.linalg.norm([1.0, 0.01, -0.01, 0.1])
    R = quaternion_matrix(q)
    ref0 = exact(np.zeros(3), np.eye(3))
    assert np.abs(s0.solve(K) - ref0).max() < 1e-11 * np.abs(ref0).max()
    assert tube.refreshed == 1
    s1 = tube.blob_solver(tube.at(X, R), sb, radii, np.concatenate([X, q]))
    before = tube.iterations
    x1 = s1.solve(K)
    assert tube.refreshed == 1 and tube.iterations > before  # iterated, no new factor
    ref = exact(X, R)
    assert np.abs(x1 - ref).max() < 1e-8 * np.abs(ref).max()
    tube.refresh_iterations = 1  # now too few: the factor moves here, the solve exact
    x2 = s1.solve(K)
    assert tube.refreshed == 2 and np.array_equal(tube.memory(), np.concatenate([X, q]))
    assert np.abs(x2 - ref).max() < 1e-11 * np.abs(ref).max()
