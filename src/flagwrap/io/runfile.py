"""Run files: one self-describing netCDF4/HDF5 file per run (xarray + h5netcdf).

Contents (SI units in each variable's ``units`` attribute):

=====================  =====================  ==============================================
variable               dims                   meaning
=====================  =====================  ==============================================
time                   (time)                 [s]
turns                  (time)                 t / T, T = 2 pi / omega (reference speed)
position               (time, bead, xyz)      bead centres [m]; body axis +z, clamp at origin
twist_angle            (time, bond)           material-frame angle theta [rad]
director               (time, bond, xyz)      material director m1 (unit)
motor_angle            (time)                 phi [rad], positive = CCW seen from the free end
omega                  (time)                 signed motor angular velocity [rad/s]
motor_torque           (time)                 N_m [N m] about the outward axis (CCW positive)
motor_torque_reduced   (time)                 N_m R / A
tip_position           (time, xyz)            free end r(L) [m]
elastic_energy         (time)                 [J]
contact_energy         (time)                 [J]
min_body_distance      (time)                 bead centre to body surface [m]
max_bond_strain        (time)                 max |l/l0 - 1|
interaction_energy     (time)                 energy of the interactions (self-contact) [J]
hook_angle             (time)                 angle between the motor's bond and the first
                                              bond of the filament proper [rad]
hook_torque            (time)                 bending torque at the joint's vertex [N m]
hook_twist_torque      (time)                 twist torque at the joint's vertex [N m]
body_position          (time, xyz)            a free body's reference point (the pole) [m]
body_orientation       (time, quat)           its unit quaternion (w, x, y, z), body -> lab
body_velocity          (time, xyz)            its velocity [m/s]
body_angular_velocity  (time, xyz)            its angular velocity [rad/s]
tip_position           (time, xyz)            (several flagella: flagellum 0's free end)
filament_first_bead    (filament)             several flagella: flagellum k's first bead
filament_n_beads       (filament)             its bead count
tip_positions          (time, filament, xyz)  each flagellum's free end [m]
motor_torques          (time, filament)       each motor's torque [N m] (sum: motor_torque)
motor_rates            (time, filament)       each motor's rate [rad/s]
polymorph_order        (time, bead)           a polymorphic filament's order parameter phi
                                              (-1: attribute polymorph_a, +1: polymorph_b)
=====================  =====================  ==============================================

The four ``body_*`` variables are written for a free body (``body.motion = "free"``) only;
a fixed body sits at the origin with the identity orientation. The ``filament`` variables
are written for several flagella (``[[flagellum]]`` tables) only: ``position`` then holds
them one after the other, ``omega`` and the ``hook_*`` records are flagellum 0's.

Global attributes: ``flagwrap_version``, ``format_version``, ``config_toml`` (the full input,
re-loadable), ``status`` ("completed" or "failed"), ``message``, ``machin`` (M), ``reynolds``,
``gravity_number`` (G = (rho_f - rho) g pi a^2 L^3 / A, > 0 buoyant), ``density_mismatch``
((rho - rho_f) / rho_f), ``omega_ratio_scaling`` (M / (0.06 (R/L)^-3)), scales, step counts and wall time. Files are
written to a temporary name, flushed, fsynced and renamed, so a crash never leaves a
half-written file under the final name.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from flagwrap import __version__
from flagwrap.errors import UserInputError

FORMAT_VERSION = 1


def trajectory_dataset(traj):
    import xarray as xr

    from flagwrap.io.config import config_to_toml

    cfg = traj.config
    sc = cfg.scales
    a = traj.arrays()
    L = sc.length
    t_si = a["t"] * sc.time
    x_si = a["x"] * L
    fil = cfg.filament
    torque_si = a["motor_torque"] * sc.torque
    ds = xr.Dataset(
        {
            "turns": ("time", a["t"] / (2 * np.pi), {"units": "1", "long_name": "t/T"}),
            "position": (("time", "bead", "xyz"), x_si, {"units": "m"}),
            "twist_angle": (("time", "bond"), a["theta"], {"units": "rad"}),
            "director": (("time", "bond", "xyz"), a["m1"], {"units": "1",
                                                            "long_name": "material director m1"}),
            "motor_angle": ("time", a["phi"], {"units": "rad"}),
            "omega": ("time", a["omega"] * sc.omega, {"units": "rad/s"}),
            "motor_torque": ("time", torque_si, {"units": "N m"}),
            "motor_torque_reduced": ("time", torque_si * fil.helix_radius / fil.bending_modulus,
                                     {"units": "1", "long_name": "N_m R / A"}),
            "tip_position": (("time", "xyz"), x_si[:, -1, :], {"units": "m"}),
            "elastic_energy": ("time", a["elastic_energy"] * sc.energy, {"units": "J"}),
            "contact_energy": ("time", a["contact_energy"] * sc.energy, {"units": "J"}),
            "min_body_distance": ("time", a["min_distance"] * L, {"units": "m"}),
            "max_bond_strain": ("time", a["max_strain"], {"units": "1"}),
            "interaction_energy": ("time", a["interaction_energy"] * sc.energy, {"units": "J"}),
            "hook_angle": ("time", a["hook_angle"], {"units": "rad"}),
            "hook_torque": ("time", a["hook_torque"] * sc.torque, {"units": "N m"}),
            "hook_twist_torque": ("time", a["hook_twist_torque"] * sc.torque, {"units": "N m"}),
        },
        coords={"time": ("time", t_si, {"units": "s"}), "xyz": ["x", "y", "z"]},
        attrs={
            "title": f"flagwrap run {cfg.name}",
            "flagwrap_version": __version__,
            "format_version": FORMAT_VERSION,
            "config_toml": config_to_toml(cfg),
            "status": traj.status,
            "message": traj.message,
            "machin": cfg.machin,
            "reynolds": cfg.reynolds,
            "gravity_number": cfg.gravity_number,
            "density_mismatch": cfg.density_mismatch,
            "omega_ratio_scaling": cfg.omega_ratio_scaling,
            "machin_critical_scaling": cfg.machin_critical_scaling,
            "omega": sc.omega,
            "period": sc.period,
            "length": L,
            "bending_modulus": fil.bending_modulus,
            "twist_modulus": fil.twist_modulus,
            "helix_radius": fil.helix_radius,
            "pitch": fil.pitch,
            "pitch_angle_deg": fil.pitch_angle_deg,
            "turns_of_helix": fil.turns,
            "n_steps": traj.n_steps,
            "n_rejected": traj.n_rejected,
            "wall_time_s": traj.wall_time,
            "integrator": cfg.numerics.integrator,
            "hydrodynamics": int(cfg.numerics.hydrodynamics),
            "joint": cfg.joint.kind,
            "conventions": "body axis +z, clamp at origin, filament hangs toward -z; "
                           "rotation sign: positive = CCW seen from the free end",
        },
    )
    # the system's filaments (a trajectory made without the loop: the config's tables)
    parts = traj.filaments or [(k * (x_si.shape[1] // max(1, len(cfg.flagella))),
                                x_si.shape[1] // max(1, len(cfg.flagella)))
                               for k in range(max(1, len(cfg.flagella)))]
    nf = len(parts)
    if nf > 1:  # several flagella: where each one's beads are
        first = np.array([a for a, _ in parts])
        n = np.array([m for _, m in parts])
        ds["filament_first_bead"] = ("filament", first, {"units": "1",
                                                         "long_name": "first bead of flagellum k"})
        ds["filament_n_beads"] = ("filament", n, {"units": "1"})
        ds["tip_positions"] = (("time", "filament", "xyz"), x_si[:, first + n - 1, :],
                               {"units": "m", "long_name": "free end of flagellum k"})
        ds["tip_position"] = (("time", "xyz"), x_si[:, first[0] + n[0] - 1, :],
                              {"units": "m", "long_name": "free end of flagellum 0"})
        ds.attrs["n_flagella"] = nf
        ds.attrs["conventions"] = (
            "body axis +z, the body's lowest point at the origin, each flagellum leaving the "
            "body along its motor axis from its anchor ([[flagellum]] tables); rotation sign: "
            "positive = CCW seen from the free end")
        if "motors" in a:  # each motor's torque and rate (core -> SI)
            m = a["motors"]
            ds["motor_torques"] = (("time", "filament"), m[:, :nf] * sc.torque,
                                   {"units": "N m", "long_name": "torque of flagellum k's motor"})
            ds["motor_rates"] = (("time", "filament"), m[:, nf:] * sc.omega,
                                 {"units": "rad/s", "long_name": "rate of flagellum k's motor"})
    if "order" in a:  # a polymorphic filament's order parameter (docs/polymorph.md)
        pm = cfg.polymorph
        ds["polymorph_order"] = (("time", "bead"), a["order"], {
            "units": "1", "long_name": f"polymorph order parameter: -1 {pm.polymorph_a}, "
                                       f"+1 {pm.polymorph_b}"})
        ds.attrs["polymorph_a"] = pm.polymorph_a
        ds.attrs["polymorph_b"] = pm.polymorph_b
    if "body" in a:  # a free body's pose and velocities (core -> SI)
        b = a["body"]
        ds["body_position"] = (("time", "xyz"), b[:, :3] * L, {"units": "m"})
        ds["body_orientation"] = (("time", "quat"), b[:, 3:7],
                                  {"units": "1", "long_name": "unit quaternion (w, x, y, z), body to lab"})
        ds["body_velocity"] = (("time", "xyz"), b[:, 7:10] * L * sc.omega, {"units": "m/s"})
        ds["body_angular_velocity"] = (("time", "xyz"), b[:, 10:13] * sc.omega, {"units": "rad/s"})
        ds.coords["quat"] = ["w", "x", "y", "z"]
    return ds


def write_dataset_atomic(ds, path) -> Path:
    """Write an xarray dataset to ``path`` atomically (see :mod:`flagwrap.io.atomic`)."""
    import dask

    from flagwrap.io.atomic import write_image

    def build(target):
        # xarray takes a write lock of the scheduler it sees; in a Dask worker process (a
        # sweep on a LocalCluster) that is a distributed Lock named after the in-memory
        # target, which the scheduler does not know, and every write failed ("Semaphore or
        # Lock `<_io.BytesIO ...>` not known"). One process writes one buffer here: a local
        # lock is the right one (another writer of the path is kept off by output_lock)
        with dask.config.set(scheduler="synchronous"):
            ds.to_netcdf(target, engine="h5netcdf", encoding=checksummed(ds))

    return write_image(path, build, size_hint=int(ds.nbytes))


def checksummed(ds) -> dict:
    """netCDF encoding that puts HDF5's Fletcher-32 checksum filter on every non-scalar
    variable (verified by HDF5 on every read: a corrupt chunk is a read error)."""
    return {k: {"fletcher32": True} for k, v in ds.variables.items()
            if v.ndim > 0 and v.size > 0 and v.dtype.kind in "biufc"}  # HDF5 filters need
    # fixed-size numbers (the string labels of the xyz axis are variable-length)


def write_run(traj, path) -> Path:
    """Write a trajectory atomically to ``path`` (netCDF4/HDF5)."""
    return write_dataset_atomic(trajectory_dataset(traj), path)


def read_run(path):
    """Open a run file; raise :class:`UserInputError` if it is not a readable flagwrap run."""
    import xarray as xr

    path = Path(path)
    if not path.is_file():
        raise UserInputError(f"run file not found: {path}")
    try:
        ds = xr.load_dataset(path, engine="h5netcdf", phony_dims="sort")
    except Exception as exc:  # truncated / not HDF5 / a checksum mismatch
        from flagwrap.io.atomic import read_error

        raise UserInputError(read_error(path, "run file", exc)) from None
    fv = ds.attrs.get("format_version")
    if fv is None or "config_toml" not in ds.attrs:
        raise UserInputError(f"{path} is not a flagwrap run file (no format_version/config)")
    if int(fv) > FORMAT_VERSION:
        raise UserInputError(
            f"{path} has format_version {fv}, newer than this flagwrap ({__version__}) reads "
            f"({FORMAT_VERSION}); upgrade flagwrap"
        )
    return ds


def filament_slices(ds) -> list:
    """Each flagellum's beads in ``position``'s bead dimension (one slice for a run of one).
    A file without the offsets takes them from its config's ``[[flagellum]]`` tables (every
    flagellum a copy of one filament)."""
    if "filament_first_bead" not in ds.variables:
        nf = max(1, len(config_of(ds).flagella)) if "config_toml" in ds.attrs else 1
        n = ds.sizes["bead"] // nf
        return [slice(k * n, (k + 1) * n) for k in range(nf)]
    first = ds["filament_first_bead"].values
    n = ds["filament_n_beads"].values
    return [slice(int(f), int(f + m)) for f, m in zip(first, n)]


def config_of(ds):
    """The :class:`~flagwrap.params.Config` stored in a run dataset."""
    from flagwrap.io.config import config_from_dict, tomllib

    data = tomllib.loads(ds.attrs["config_toml"])
    num = data.get("numerics", {})
    if num.get("integrator") == "rosenbrock":  # ROS2's name in run files before 2026-11-25
        num["integrator"] = "ros2"
    return config_from_dict(data)
