"""Cell-body shapes: capped cylinder (the paper's), sphere and spheroid (body.shape)."""

import dataclasses
import math

import numpy as np
import pytest

from conftest import make_config
from flagwrap.body.cell_body import CappedCylinder
from flagwrap.body.multiblob import (BLOB_INSET, cell_body_blobs, nearest_spacing,
                                     resistance_matrix, spheroid_ring_blobs)
from flagwrap.errors import UserInputError
from test_multiblob import prolate_drag


def exact_spheroid_distance(p, a, c):
    """Distance from p to the spheroid rho^2/a^2 + (z - c)^2/c^2 = 1 by a fine meridian scan
    (independent of the kernel's first-order formula)."""
    rho, w = math.hypot(p[0], p[1]), p[2] - c
    th = np.linspace(0.0, math.pi, 200001)
    d = np.hypot(rho - a * np.sin(th), w + c * np.cos(th)).min()
    inside = (rho / a) ** 2 + (w / c) ** 2 < 1.0
    return -d if inside else d


def test_sphere_distance_is_exact_and_spheroid_first_order():
    rng = np.random.default_rng(0)
    sph = CappedCylinder(0.2, 0.2, cutoff=0.01, strength=0.0, shape="sphere")
    p = rng.standard_normal((50, 3)) * 0.3 + [0, 0, 0.2]
    assert np.allclose(sph.distance(p), np.linalg.norm(p - [0, 0, 0.2], axis=1) - 0.2, atol=1e-14)
    # 3:1 spheroid (a = 0.1, c = 0.3): beside the surface the kernel's distance is the true one
    # to O(d^2 / a) (the level set's curvature); at |d| <= 0.02 a that is < 1e-3 a x O(1)
    a, c = 0.1, 0.3
    body = CappedCylinder(a, 2 * c - a, cutoff=0.01, strength=0.0, shape="spheroid")
    for _ in range(30):
        th, ph = rng.uniform(0, math.pi), rng.uniform(0, 2 * math.pi)
        n = np.array([math.sin(th) * math.cos(ph) / a, math.sin(th) * math.sin(ph) / a,
                      -math.cos(th) / c])
        n /= np.linalg.norm(n)
        on = np.array([a * math.sin(th) * math.cos(ph), a * math.sin(th) * math.sin(ph),
                       c - c * math.cos(th)])
        for d in (-0.002, 0.001, 0.002):
            q = on + d * n
            got = body.distance(q[None])[0]
            assert abs(got - exact_spheroid_distance(q, a, c)) < 2.0 * d * d / a + 1e-9


def test_spheroid_contact_force_is_the_gradient_of_its_energy():
    a, c = 0.1, 0.3
    body = CappedCylinder(a, 2 * c - a, cutoff=0.02, strength=1.0, first_bead=0, shape="spheroid")
    rng = np.random.default_rng(1)
    th = rng.uniform(0.2, 2.9, 12)
    ph = rng.uniform(0, 2 * math.pi, 12)
    x = np.column_stack([1.01 * a * np.sin(th) * np.cos(ph), 1.01 * a * np.sin(th) * np.sin(ph),
                         c - 1.005 * c * np.cos(th)])
    g = np.zeros_like(x)
    body.energy_grad(x, g, np.empty(len(x)))
    assert np.abs(g).max() > 0  # some beads are in range
    h = 1e-7
    for i in range(len(x)):
        for m in range(3):
            xp, xm = x.copy(), x.copy()
            xp[i, m] += h
            xm[i, m] -= h
            Ep = body.energy_grad(xp, np.zeros_like(x), np.empty(len(x)))
            Em = body.energy_grad(xm, np.zeros_like(x), np.empty(len(x)))
            assert (Ep - Em) / (2 * h) == pytest.approx(g[i, m], rel=1e-5, abs=1e-6 * np.abs(g).max())


def test_ring_spheroid_blobs_converge_to_the_exact_prolate_drag():
    # a 2:1 spheroid of ring blobs inset by BLOB_INSET a_b against the exact drag of the body
    # itself: the error falls about as the spacing (measured, axial / across: 9.9e-3 / 8.1e-3
    # at 228 blobs, 4.3e-3 / 3.2e-3 at 514, 1.9e-3 / 1.3e-3 at 1054), so it must shrink with
    # refinement and stay below 0.06 x spacing / semi-minor axis
    fa, ft = prolate_drag(1.0, 0.5)
    errs = []
    for sp in (0.15, 0.1):
        ab = 0.5 * sp
        d = BLOB_INSET * ab
        b = spheroid_ring_blobs(0.5 - d, 1.0 - d, sp) - np.array([0, 0, 1.0 - d])
        R = resistance_matrix(b, ab)
        errs.append((abs(R[2, 2] / fa - 1), abs(R[0, 0] / ft - 1)))
        assert max(errs[-1]) < 0.06 * sp / 0.5
    assert errs[1][0] < errs[0][0] / 1.5 and errs[1][1] < errs[0][1] / 1.5


@pytest.mark.parametrize("shape", ["sphere", "spheroid"])
def test_shapes_build_blobs_contact_and_drawings(shape, tmp_path):
    from flagwrap.plotting.render import body_surface

    cfg = make_config()
    cfg = cfg.replace(body=dataclasses.replace(cfg.body, surface="no-slip", shape=shape))
    blobs, r = cell_body_blobs(cfg)
    assert nearest_spacing(blobs) < 3 * r[0]
    L, R = cfg.filament.length, cfg.body.resolved_radius(cfg.filament.helix_radius)
    H = cfg.body.resolved_length(cfg.filament.helix_radius)
    top = (R + H) / L
    assert blobs[:, 2].min() == pytest.approx(BLOB_INSET * r[0])
    assert blobs[:, 2].max() == pytest.approx(top - BLOB_INSET * r[0])
    v, f = body_surface(R, H, shape=shape)
    # a closed mesh: its volume (divergence theorem) is the spheroid's 4/3 pi a^2 c to 1 %
    tri = v[f]
    vol = np.einsum("ij,ij->i", tri[:, 0], np.cross(tri[:, 1], tri[:, 2])).sum() / 6
    assert vol == pytest.approx(4 / 3 * math.pi * R**2 * 0.5 * (R + H), rel=0.01)


def test_sphere_refuses_a_cylinder_length_and_unknown_shapes():
    cfg = make_config()
    with pytest.raises(UserInputError, match="cylinder_length does not apply"):
        cfg.replace(body=dataclasses.replace(cfg.body, shape="sphere", cylinder_length=0.1))
    with pytest.raises(UserInputError, match="body.shape must be one of"):
        cfg.replace(body=dataclasses.replace(cfg.body, shape="cube"))


def test_free_swimmer_on_a_spheroid_runs():
    from conftest import paper_filament
    from flagwrap.simulation import simulate

    cfg = make_config(protocol=(("ccw", 0.05),), filament=paper_filament(n_beads=21))
    cfg = cfg.replace(body=dataclasses.replace(cfg.body, surface="no-slip", motion="free",
                                               shape="spheroid", blob_spacing=0.025))
    tr = simulate(cfg)
    assert tr.ok, tr.message
    assert np.asarray(tr.body)[-1, 12] > 0  # counter-rotates
