"""The body-shape extension test (issue 28): shapes defined in this file, with no edit of
src/, build contact, blobs, anchors and drawings through :mod:`flagwrap.body.shapes`' small
interface and run in the simulator.

* ``UnitTestSphere``: the sphere again, written here from its own formulas, so the generic
  contact path (``ShapeContact``: no fused kernel) is checked against the built-in sphere's
  kernel, and a run pressed against the body reaches the built-in run's equilibrium.
* ``Peanut``: two overlapping spheres on the axis, a shape flagwrap does not have, as a free
  no-slip swimming cell: force- and torque-free, it swims, and it is drawn.
"""

import dataclasses
import math

import numpy as np
import pytest

from conftest import make_config, paper_filament
from flagwrap.body.shapes import BodyShape, register_shape
from flagwrap.errors import UserInputError
from flagwrap.system.rod_system import RodSystem


def fibonacci_sphere(radius: float, spacing: float) -> np.ndarray:
    """About ``spacing``-apart points on a sphere of ``radius`` (golden-angle spiral)."""
    n = max(12, int(round(4 * math.pi * radius**2 / (0.866 * spacing**2))))
    k = np.arange(n) + 0.5
    z = 1 - 2 * k / n
    r = np.sqrt(1 - z * z)
    phi = math.pi * (3 - math.sqrt(5)) * k
    return radius * np.column_stack([r * np.cos(phi), r * np.sin(phi), z])


def uv_sphere(radius, centre, n_around, n_profile):
    t = np.linspace(0, math.pi, n_profile + 1)[1:-1]
    p = 2 * math.pi * np.arange(n_around) / n_around
    v = [[0, 0, -radius]] + [[radius * math.sin(a) * math.cos(b), radius * math.sin(a) * math.sin(b),
                              -radius * math.cos(a)] for a in t for b in p] + [[0, 0, radius]]
    v = np.array(v) + centre
    tris = []
    ring = lambda j: 1 + j * n_around + np.arange(n_around)  # noqa: E731
    k1 = (np.arange(n_around) + 1) % n_around
    tris.append(np.column_stack([np.zeros(n_around, int), ring(0)[k1], ring(0)]))
    for j in range(len(t) - 1):
        lo, hi = ring(j), ring(j + 1)
        tris.append(np.column_stack([lo, lo[k1], hi[k1]]))
        tris.append(np.column_stack([lo, hi[k1], hi]))
    top = len(v) - 1
    tris.append(np.column_stack([ring(len(t) - 1), ring(len(t) - 1)[k1],
                                 np.full(n_around, top)]))
    return v, np.concatenate(tris)


class UnitTestSphere(BodyShape):
    """A sphere of ``radius`` with its lowest point at the origin; ``length`` unused."""

    name = "unit-test-sphere"
    axisymmetric = True

    def __init__(self, radius, length):
        super().__init__(radius, radius)
        self.centre = np.array([0.0, 0.0, radius])

    def signed_distance(self, x):
        r = x - self.centre
        n = np.linalg.norm(r, axis=1)
        return n - self.radius, r / n[:, None]

    def blob_shell(self, spacing, blob_radius):
        return fibonacci_sphere(self.radius - 0.33 * blob_radius, spacing) + self.centre

    def surface_mesh(self, n_around=48, n_profile=18):
        return uv_sphere(self.radius, self.centre, n_around, n_profile)

    def pole_cap(self, polar, azimuth):
        n = np.array([math.sin(polar) * math.cos(azimuth), math.sin(polar) * math.sin(azimuth),
                      -math.cos(polar)])
        return self.centre + self.radius * n, n


class Peanut(BodyShape):
    """Two spheres of ``radius`` on the axis, centres ``length`` apart (``length < 2 radius``),
    the lower one's lowest point at the origin: the union's signed distance is the nearer
    sphere's (exact outside)."""

    name = "unit-test-peanut"
    axisymmetric = True

    def __init__(self, radius, length):
        super().__init__(radius, length)
        if not 0 < length < 2 * radius:
            raise UserInputError(f"peanut: length must be in (0, 2 radius), got {length:g}")
        self.centres = np.array([[0.0, 0.0, radius], [0.0, 0.0, radius + length]])
        self.centre = self.centres[0]  # the pole cap's

    def signed_distance(self, x):
        r = x[:, None, :] - self.centres[None]
        n = np.linalg.norm(r, axis=2)
        k = np.argmin(n, axis=1)
        i = np.arange(len(x))
        return n[i, k] - self.radius, r[i, k] / n[i, k][:, None]

    def blob_shell(self, spacing, blob_radius):
        rs = self.radius - 0.33 * blob_radius
        out = []
        for j, c in enumerate(self.centres):
            p = fibonacci_sphere(rs, spacing) + c
            other = self.centres[1 - j]
            out.append(p[np.linalg.norm(p - other, axis=1) > rs])
        return np.concatenate(out)

    def surface_mesh(self, n_around=48, n_profile=18):
        v0, f0 = uv_sphere(self.radius, self.centres[0], n_around, n_profile)
        v1, f1 = uv_sphere(self.radius, self.centres[1], n_around, n_profile)
        return np.concatenate([v0, v1]), np.concatenate([f0, f1 + len(v0)])

    pole_cap = UnitTestSphere.pole_cap  # the lower sphere's


register_shape(UnitTestSphere.name, UnitTestSphere)
register_shape(Peanut.name, Peanut)


def _cfg(shape, **body):
    cfg = make_config(machin=283.0, protocol=(("stop", 5.0),), hi=False,
                      filament=paper_filament(n_beads=21))
    return cfg.replace(body=dataclasses.replace(cfg.body, shape=shape, **body))


def test_the_generic_contact_is_the_sphere_kernel_and_its_hessian_the_gradients_change():
    from flagwrap.body.cell_body import ShapeContact

    ref = RodSystem(_cfg("sphere")).body
    mine = RodSystem(_cfg(UnitTestSphere.name)).body
    assert ref.fused and not mine.fused
    rng = np.random.default_rng(4)
    c, R = np.array([0.0, 0.0, ref.radius]), ref.radius
    u = rng.standard_normal((40, 3))
    u /= np.linalg.norm(u, axis=1)[:, None]
    x = c + u * (R + rng.uniform(0.1, 1.0, (40, 1)) * ref.cutoff)  # all within range
    ga, gb = np.zeros_like(x), np.zeros_like(x)
    da, db = np.empty(len(x)), np.empty(len(x))
    Ea, Eb = ref.energy_grad(x, ga, da), mine.energy_grad(x, gb, db)
    assert Ea > 0
    # the same law on the same distances: round-off of the two distance formulas
    assert Eb == pytest.approx(Ea, rel=1e-10)
    np.testing.assert_allclose(gb, ga, rtol=1e-9, atol=1e-12 * np.abs(ga).max())
    np.testing.assert_allclose(db, da, atol=1e-14)
    # the interaction's Hessian against central differences of its own gradient
    sc = ShapeContact(mine, np.ones(len(x), bool))
    r, cc, v = sc.hessian_coo(x, None)
    H = np.zeros((x.size, x.size))
    np.add.at(H, (r, cc), v)
    h = 1e-9
    for k in range(x.size):
        xp, xm = x.copy().ravel(), x.copy().ravel()
        xp[k] += h
        xm[k] -= h
        gp, gm = np.zeros_like(x), np.zeros_like(x)
        sc.energy_grad(xp.reshape(-1, 3), None, gp, None)
        sc.energy_grad(xm.reshape(-1, 3), None, gm, None)
        np.testing.assert_allclose(H[:, k], (gp - gm).ravel() / (2 * h), rtol=1e-4,
                                   atol=1e-5 * np.abs(H).max())


def test_a_rod_pressed_on_a_sphere_defined_here_rests_where_the_builtin_one_does():
    # a tether pulls the free end into the body: the rod wraps onto the sphere and stops in
    # contact (a static balance of tether, elasticity and contact, whatever the steps);
    # the test's sphere (generic contact through the system's interactions) and the built-in
    # one (fused kernel) reach the same rest state, within the integrator's tolerance
    from test_extension import Tether

    from flagwrap.simulation import Simulation

    out = {}
    for shape in ("sphere", UnitTestSphere.name):
        cfg = _cfg(shape)
        s = RodSystem(cfg, interactions=[Tether(200.0, (0.1, 0.0, 0.1))])
        tr = Simulation(cfg, system=s).run()
        assert tr.ok, tr.message
        x = np.asarray(tr.x)[-1]
        assert 0 < s.body.distance(x[2:]).min() < s.body.cutoff  # in contact, outside
        out[shape] = x
    tol = _cfg("sphere").numerics.tol
    assert np.abs(out["sphere"] - out[UnitTestSphere.name]).max() < tol  # measured 8.6e-10


def test_a_free_cell_of_a_shape_defined_here_swims_force_and_torque_free(rng, tmp_path):
    from flagwrap.io.runfile import read_run, write_run
    from flagwrap.io.vtk import export_vtk
    from flagwrap.simulation import make_system, simulate

    cfg = make_config(protocol=(("ccw", 0.05),), filament=paper_filament(n_beads=21))
    R = cfg.body.resolved_radius(cfg.filament.helix_radius)
    cfg = cfg.replace(body=dataclasses.replace(
        cfg.body, surface="no-slip", motion="free", shape=Peanut.name,
        cylinder_length=1.2 * R, blob_spacing=0.025))
    s = make_system(cfg)
    assert not s.body.fused  # the generic contact path
    y = s.initial_y()
    y[s.sl_x] += 0.01 * s.bond * rng.standard_normal(s.sl_x.stop - s.sl_x.start)
    from conftest import fluid_force_and_torque

    force, torque, f_scale, t_scale = fluid_force_and_torque(s, y)
    assert np.abs(force).max() < 1e-10 * f_scale
    assert np.abs(torque).max() < 1e-10 * t_scale
    tr = simulate(cfg)
    assert tr.ok, tr.message
    assert np.asarray(tr.body)[-1, 12] > 0  # the body counter-rotates about its axis
    path = tmp_path / "peanut.nc"
    write_run(tr, path)
    pvd = export_vtk(read_run(path), tmp_path / "vtk")
    assert (tmp_path / "vtk").is_dir() and pvd.is_file()
    assert any(p.name.startswith("body_") for p in (tmp_path / "vtk").iterdir())


def test_a_shape_defined_here_places_flagella_and_refuses_anchors_off_it():
    base = make_config(filament=paper_filament(n_beads=21))
    R = base.body.resolved_radius(base.filament.helix_radius)
    cfg = base.replace(body=dataclasses.replace(base.body, shape=Peanut.name,
                                                cylinder_length=1.2 * R))
    from flagwrap.params import Flagellum
    from flagwrap.system.parts import check_flagella

    two = cfg.replace(flagella=(Flagellum(polar_deg=30, azimuth_deg=0),
                                Flagellum(polar_deg=30, azimuth_deg=180)))
    check_flagella(two)
    s = RodSystem(two)
    for p in s.parts:  # the anchors on the lower sphere, motor axes along its normal
        assert abs(s.body.distance(p.x0[:1])[0]) < 1e-12
    with pytest.raises(UserInputError, match=r"flagellum\[0\].anchor = .* from the body surface"):
        cfg.replace(flagella=(Flagellum(anchor=(0.01, 0.0, 0.0), axis=(0.0, 0.0, -1.0)),))


def test_the_registry_refuses_a_name_taken_and_unknown_names():
    from flagwrap.params import CellBody

    with pytest.raises(ValueError, match="already registered"):
        register_shape("sphere", UnitTestSphere)
    with pytest.raises(UserInputError, match="register_shape"):
        CellBody(shape="no-such-shape")
    assert CellBody(shape=Peanut.name).shape == Peanut.name
