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


def tiny_toml(ccw=0.2, cw=0.2, n_beads=21, machin=100):
    """A 21-bead Fig. 4(a)-like case that runs in well under a second (loose tol 1e-3)."""
    return f"""
name = "tiny"
[filament]
length = 0.4
helix_radius = 0.03
turns = 2
cross_section_radius = 0.0015
youngs_modulus = 1.5e6
n_beads = {n_beads}
[motor]
machin = {machin}
protocol = [{{direction = "ccw", turns = {ccw}}}, {{direction = "cw", turns = {cw}}}]
[numerics]
save_every = 0.05
tol = 1e-3
"""


NO_SLIP_BODY = "[body]\nsurface = 'no-slip'\nblob_spacing = 0.025\n"


def system_kinds(polar_deg=30) -> dict:
    """``{name: (numerics lines, tables)}``: every kind of system a feature must run on, as
    TOML added to :func:`tiny_toml`'s ``[numerics]`` and appended to it (the two flagella sit
    ``polar_deg`` from the pole, on opposite sides)."""
    free = NO_SLIP_BODY + "motion = 'free'\n"
    return {
        "lab": ("", ""),
        "turning frame": ("frame = 'rotating'\n", ""),
        "krylov": ("linear_solver = 'krylov'\n", ""),
        "fixed no-slip body": ("", NO_SLIP_BODY),
        "free cell": ("", free),
        "free cell, turning frame": ("frame = 'rotating'\n", free),
        "two flagella on a free cell": ("", free + "".join(
            f"[[flagellum]]\npolar_deg = {polar_deg}\nazimuth_deg = {az}\n" for az in (0, 180))),
    }


@pytest.fixture(scope="session")
def tiny_run(tmp_path_factory):
    """Run file of :func:`tiny_toml` (read-only for the tests that share it)."""
    from flagwrap.io.config import config_from_dict, tomllib
    from flagwrap.io.runfile import write_run
    from flagwrap.simulation import simulate

    path = tmp_path_factory.mktemp("tiny") / "tiny.nc"
    write_run(simulate(config_from_dict(tomllib.loads(tiny_toml()))), path)
    return path


def fd_gradient(energy, x, theta, h=1e-6):
    """Central differences of ``energy(x, theta)`` over every coordinate of ``x`` (N, 3) and
    ``theta`` (N-1,): the oracle of the gradient tests (error O(h^2) + rounding/h)."""
    gx = np.zeros_like(x)
    for i in range(len(x)):
        for k in range(3):
            xp, xm = x.copy(), x.copy()
            xp[i, k] += h
            xm[i, k] -= h
            gx[i, k] = (energy(xp, theta) - energy(xm, theta)) / (2 * h)
    gt = np.zeros_like(theta)
    for j in range(len(theta)):
        tp, tm = theta.copy(), theta.copy()
        tp[j] += h
        tm[j] -= h
        gt[j] = (energy(x, tp) - energy(x, tm)) / (2 * h)
    return gx, gt


def fluid_force_and_torque(s, y):
    """What a free cell ``s`` (a swimmer system) at ``y`` exerts on the fluid, in total:
    ``(force, torque, force scale, torque scale)``: blob forces + bead forces + bond torques,
    the scales the sums of their magnitudes (a force- and torque-free cell: the totals are
    round-off of those)."""
    info = s.forces(y, s.frames0)
    _, _, lam = s.body_velocity(y, info.G)
    x, _, _ = s.unpack(y)
    xf = x[s.free_beads]
    F = info.G[s.sl_x].reshape(-1, 3)
    tau = info.G[s.sl_th]
    bf = s.bond_first[s.free_bonds]
    t = (x[bf + 1] - x[bf]) / np.linalg.norm(x[bf + 1] - x[bf], axis=1)[:, None]
    L = lam.reshape(-1, 3)
    force = F.sum(axis=0) + L.sum(axis=0)
    torque = np.cross(xf, F).sum(axis=0) + tau @ t + np.cross(s.blobs, L).sum(axis=0)
    return force, torque, np.abs(F).sum(), np.abs(np.cross(xf, F)).sum() + np.abs(tau).sum()


def fd_frame_jacobian(fr, z, frames, omega):
    """Central differences of a turning frame's velocity ``fr.velocity(z, frames, omega)``,
    column by column (steps 1e-6 for positions, 1e-5 for angles)."""
    f0 = fr.velocity(z, frames, omega)[0]
    J = np.empty((len(f0), fr.n))
    for k in range(fr.n):
        h = 1e-6 if k < fr.n3 else 1e-5
        zp, zm = z.copy(), z.copy()
        zp[k] += h
        zm[k] -= h
        J[:, k] = (fr.velocity(zp, frames, omega)[0] - fr.velocity(zm, frames, omega)[0]) / (2 * h)
    return J
