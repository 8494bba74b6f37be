"""Checkpoints: the complete state of the time loop in one small HDF5 file.

A checkpoint holds everything :meth:`flagwrap.simulation.Simulation.run` needs to continue as if
it had never stopped, so that a resumed run reproduces the uninterrupted one bit for bit (same
flagwrap version, backend and thread count):

=========================  ====================================================================
item                       meaning (core units: length L, time 1/omega)
=========================  ====================================================================
``y``                      state vector (free bead positions, free twist angles, motor angle)
``base_t/base_d1/base_rt`` reference frames the forces at ``y`` were computed against (the
                           previous step's frames: the forces and the next base follow exactly)
attrs ``t, h, next_save``  time, the step-size controller's next step, the next output time
attrs ``t_end``            end of the run
attrs ``n_steps, ...``     accepted / rejected step counters, wall time so far
``records/<name>``         the trajectory recorded so far (:meth:`Trajectory.arrays` names; a free
                           body's ``body`` record when the run has one)
``solver_memory``          what the stage solver carries from step to step (a no-slip body's
                           lagged screening: ``RodSystem.solver_memory``); empty for the rig
attrs ``config_toml``      the full input; resume refuses a different one
attrs ``flagwrap_version`` resume refuses a checkpoint from another version
=========================  ====================================================================

Plain arrays and scalars only (h5py): nothing is pickled or evaluated on reading. Files are
written to a temporary name in the same folder, fsynced and renamed, so a crash (even
``kill -9``) leaves either the previous checkpoint or the new one, never a torn file.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from flagwrap import __version__
from flagwrap.errors import UserInputError
from flagwrap.io.atomic import write_image

#: 2: the joint records (hook_angle, hook_torque, hook_twist_torque) and interaction_energy;
#: 3: solver_memory
CHECKPOINT_FORMAT = 3
_MAGIC = "flagwrap checkpoint"
#: the per-frame records of a trajectory (flagwrap.simulation._RECORDS, repeated here so that
#: reading a checkpoint does not import the simulator; tests/unit/test_checkpoint.py checks)
RECORD_NAMES = ("t", "x", "theta", "m1", "phi", "omega", "motor_torque", "elastic_energy",
                "contact_energy", "min_distance", "max_strain", "interaction_energy",
                "hook_angle", "hook_torque", "hook_twist_torque")
#: records only some runs have (a free body's pose and velocities; several flagella's motors;
#: a polymorphic filament's order parameters): stored when present
OPTIONAL_RECORD_NAMES = ("body", "motors", "order")
_SCALARS = {"t": float, "t_end": float, "h": float, "next_save": float, "n_steps": int,
            "n_rejected": int, "wall_time": float}


@dataclass
class Checkpoint:
    """Loop state of a run (see the module docstring for the meaning of each field)."""

    t: float
    t_end: float
    h: float
    next_save: float
    n_steps: int
    n_rejected: int
    wall_time: float
    y: np.ndarray
    base_t: np.ndarray
    base_d1: np.ndarray
    base_rt: np.ndarray
    records: dict
    config_toml: str
    solver_memory: np.ndarray = field(default_factory=lambda: np.zeros(0))
    flagwrap_version: str = __version__

    def base(self):
        from flagwrap.elasticity.rod import Frames

        return Frames(self.base_t.copy(), self.base_d1.copy(), self.base_rt.copy())


def _checked(group, name, data):
    """A float64 dataset with the Fletcher-32 filter (chunked; an empty one cannot be)."""
    a = np.asarray(data, dtype=np.float64)
    group.create_dataset(name, data=a, fletcher32=a.size > 0)


def write_checkpoint(ckpt: Checkpoint, path) -> Path:
    """Write ``ckpt`` to ``path`` atomically (temporary file, fsync, rename, fsync folder)."""
    import h5py

    def write(tmp):
        with h5py.File(tmp, "w") as f:
            f.attrs["format"] = _MAGIC
            f.attrs["checkpoint_format"] = CHECKPOINT_FORMAT
            f.attrs["flagwrap_version"] = ckpt.flagwrap_version
            f.attrs["config_toml"] = ckpt.config_toml
            for k, typ in _SCALARS.items():
                f.attrs[k] = np.float64(getattr(ckpt, k)) if typ is float else np.int64(getattr(ckpt, k))
            # every array carries HDF5's Fletcher-32 checksum, verified by h5py on read; the
            # scalars are also stored as one checksummed array and compared with the attributes
            _checked(f, "scalars", [float(getattr(ckpt, k)) for k in _SCALARS])
            for k in ("y", "base_t", "base_d1", "base_rt", "solver_memory"):
                _checked(f, k, getattr(ckpt, k))
            g = f.create_group("records")
            for k in RECORD_NAMES + tuple(k for k in OPTIONAL_RECORD_NAMES if k in ckpt.records):
                _checked(g, k, ckpt.records[k])

    size = sum(np.asarray(getattr(ckpt, k)).nbytes for k in ("y", "base_t", "base_d1", "base_rt"))
    size += sum(np.asarray(v).nbytes for v in ckpt.records.values())
    return write_image(path, write, size_hint=size, sync_dir=True)


def read_checkpoint(path) -> Checkpoint:
    """Read a checkpoint; anything unreadable, foreign or incomplete is a :class:`UserInputError`."""
    import h5py

    path = Path(path)
    if not path.is_file():
        raise UserInputError(f"no checkpoint at {path} (nothing to resume; run without --resume)")
    try:
        f = h5py.File(path, "r")
    except Exception as exc:  # truncated, not HDF5
        raise UserInputError(f"{path} is not a readable checkpoint (truncated or not HDF5): {exc}") from None
    with f:
        if f.attrs.get("format") != _MAGIC:
            raise UserInputError(f"{path} is not a flagwrap checkpoint")
        fmt = int(f.attrs.get("checkpoint_format", -1))
        if fmt != CHECKPOINT_FORMAT:
            raise UserInputError(f"{path} has checkpoint format {fmt}; this flagwrap ({__version__}) "
                                 f"reads format {CHECKPOINT_FORMAT}")
        try:
            kw = {k: typ(f.attrs[k]) for k, typ in _SCALARS.items()}
            kw["config_toml"] = str(f.attrs["config_toml"])
            kw["flagwrap_version"] = str(f.attrs["flagwrap_version"])
            for k in ("y", "base_t", "base_d1", "base_rt", "solver_memory"):
                kw[k] = np.array(f[k][()], dtype=np.float64)
            kw["records"] = {k: np.array(f["records"][k][()], dtype=np.float64)
                             for k in RECORD_NAMES + OPTIONAL_RECORD_NAMES
                             if k in RECORD_NAMES or k in f["records"]}
            if "scalars" in f and not np.array_equal(
                    f["scalars"][()], np.array([float(kw[k]) for k in _SCALARS])):
                raise ValueError("scalar attributes differ from their checksummed copy")
        except (KeyError, OSError, ValueError, TypeError) as exc:
            from flagwrap.io.atomic import read_error

            msg = read_error(path, "checkpoint", exc)
            if " is corrupt: " not in msg:
                msg = f"{path} is an incomplete or damaged checkpoint ({exc})"
            raise UserInputError(msg) from None
    ck = Checkpoint(**kw)
    n = len(ck.records["t"])
    if n == 0 or any(len(v) != n for v in ck.records.values()):
        raise UserInputError(f"{path} is a damaged checkpoint (records of unequal length)")
    if not (np.all(np.isfinite(ck.y)) and np.isfinite(ck.t) and np.isfinite(ck.h) and ck.h > 0):
        raise UserInputError(f"{path} is a damaged checkpoint (non-finite state)")
    return ck


_BUDGETS = ("max_wall_time", "max_steps")


def _without_budgets(toml_text: str) -> list[str]:
    """Config lines without ``numerics.max_wall_time`` / ``max_steps``: budgets of one
    invocation, which do not change the trajectory, so a run stopped by one resumes with a
    larger one (the keys exist in [numerics] only)."""
    return [ln for ln in toml_text.splitlines() if ln.split("=")[0].strip() not in _BUDGETS]


def check_compatible(ckpt: Checkpoint, config, path="checkpoint") -> None:
    """Refuse to resume a checkpoint written by another version or for another config."""
    from flagwrap.io.config import config_to_toml

    if ckpt.flagwrap_version != __version__:
        raise UserInputError(
            f"{path} was written by flagwrap {ckpt.flagwrap_version}, this is {__version__}: "
            "a resumed run would not reproduce the original; rerun from the start or resume "
            f"with flagwrap {ckpt.flagwrap_version}")
    old, now = (_without_budgets(ckpt.config_toml), _without_budgets(config_to_toml(config)))
    if old != now:
        import difflib

        diff = [ln for ln in difflib.unified_diff(old, now, lineterm="", n=0)
                if ln[:1] in "+-" and not ln.startswith(("+++", "---"))]
        raise UserInputError(f"{path} belongs to a different config (checkpoint vs now: "
                             f"{'; '.join(diff[:6])}); resume with the same config and options")
