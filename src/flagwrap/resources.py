"""What a run will cost in memory and disk, checked before any work starts.

A config can be valid physics and still ask for more than the machine has: a protocol of
``1e9`` turns saved every ``0.05`` turns, or ``n_beads = 200000`` with dense linear algebra.
:func:`estimate` prices a :class:`~flagwrap.params.Config`; :func:`check_memory` and
:func:`check_disk` turn an over-budget estimate into one :class:`UserInputError` naming the
inputs to change (``motor.protocol`` turns, ``numerics.save_every``, ``filament.n_beads``).

Estimates (bytes, float64):

* recorded output: ``n_saves = total_turns / save_every + 2`` frames of
  ``8 n_f (3 N + 3 (N-1) + (N-1) + 8)`` bytes for ``n_f`` flagella of ``N`` beads (positions,
  directors, twist angles, scalars); held
  about three times over while a run file is built (lists, stacked arrays, the SI dataset);
* dense linear algebra (long-range hydrodynamics, ``ny = 3 N_free + N_bonds + n_f <= 4000``
  over all flagella,
  the crossover of :mod:`flagwrap.integrators.linear`): about five ``ny x ny`` matrices
  (mobility, Jacobian, their product, ``W``, its LU factors);
* on disk: the run file (one copy of the output) plus a checkpoint of the same size, each
  briefly twice while written atomically (temporary file, then rename).

The memory limit is ``FLAGWRAP_MAX_MEMORY`` (bytes, or with a K/M/G/T suffix) if set, else
half the memory available now (``MemAvailable`` of ``/proc/meminfo``, or ``os.sysconf``).
"""

from __future__ import annotations

import math
import os

import numpy as np
import shutil
from dataclasses import dataclass
from pathlib import Path

from flagwrap.errors import UserInputError

#: fraction of the available memory a single run may plan to use
MEMORY_FRACTION = 0.5
_SUFFIX = {"": 1, "K": 2**10, "M": 2**20, "G": 2**30, "T": 2**40}


@dataclass(frozen=True)
class Estimate:
    """Planned cost of one run (bytes)."""

    total_turns: float
    n_saves: float
    frame_bytes: int
    output_memory: float
    linalg_memory: float
    file_bytes: float
    unknowns: int  # ny: per flagellum 3 (N - 2) bead coordinates + (N - 2) twists + its motor angle
    blobs: int = 0  # a no-slip body's blobs (estimated from its surface and spacing)
    blob_memory: float = 0.0

    @property
    def memory(self) -> float:
        return self.output_memory + self.linalg_memory + self.blob_memory


def total_turns(config) -> float:
    """Duration of the motor protocol in reference turns ``T`` (a phase lasts ``turns / speed``)."""
    return float(sum(p.turns / (p.speed if p.direction != "stop" else 1.0)
                     for p in config.motor.protocol))


def _dense_solver(linear_solver: str, ny: int) -> bool:
    """Whether the stage solver assembles a dense ``W`` (``make_w``'s choice with HI on)."""
    from flagwrap.integrators.linear import AUTO_CROSSOVER_NY

    return linear_solver == "dense" or (linear_solver == "auto" and ny <= AUTO_CROSSOVER_NY)


def estimate(config) -> Estimate:
    fil, num = config.filament, config.numerics
    n_f = max(1, len(config.flagella))  # every flagellum a copy of the filament
    N = int(fil.n_beads)
    turns = total_turns(config)
    n_saves = turns / num.save_every + 2.0
    frame = 8 * n_f * (3 * N + 3 * (N - 1) + (N - 1) + 8)
    from flagwrap.joints.clamp import AxialClamp
    from flagwrap.system.layout import DofLayout

    # free coordinates (Estimate.unknowns): the layout RodSystem builds, n_f (4 N - 7) + n_f
    # - 1 with clamps (each filament's free beads and bonds, one motor angle each)
    ny = DofLayout.clamped_filament(n_f * (N - AxialClamp.n_beads),
                                    n_f * (N - 1 - AxialClamp.n_edges), n_motors=n_f).size
    dense = num.hydrodynamics and _dense_solver(num.linear_solver, ny)
    linalg = 5.0 * 8.0 * ny * ny if dense else 200.0 * 8.0 * ny
    blobs, blob_mem = _blob_cost(config, ny)
    return Estimate(turns, n_saves, frame, 3.0 * n_saves * frame, linalg, n_saves * frame, ny,
                    blobs, blob_mem)


def _blob_cost(config, ny: int) -> tuple[int, float]:
    """The fixed blobs' count, a no-slip body's (its surface over a blob's share,
    ``spacing^2 sqrt(3)/2`` on a triangular lattice) and a ``[[tube]]``'s
    (:meth:`flagwrap.confinement.tube.Tube.estimated_blobs`), and the memory their solver
    needs: the direct solver's factor and inverse (two ``(3 n)^2`` matrices) and the beads x
    blobs block, or the Krylov solver's blocks and coarse space."""
    n = _body_blobs(config) + _tube_blobs(config)
    if n == 0:
        return 0, 0.0
    from flagwrap.body.solver import AUTO_DIRECT_MAX

    b = config.body
    direct = b.solver == "direct" or (b.solver == "auto" and n <= AUTO_DIRECT_MAX)
    if direct:  # the factor, and up to INVERSE_MAX blobs the inverse (DirectBlobSolver)
        from flagwrap.body.solver import DirectBlobSolver

        mats = 2.0 if n <= DirectBlobSolver.INVERSE_MAX else 1.0
        return n, mats * 8.0 * (3 * n) ** 2 + 8.0 * 3 * n * ny
    # Krylov (body.solver.KrylovBlobSolver): CG vectors, the overlapping blocks' factors
    # (about 2.5 x 64 blobs each, n / 64 of them) and the coarse space's A Z (9 n^2 / 64)
    return n, 200.0 * 8.0 * 3 * n + 8.0 * (3 * 160) ** 2 * n / 64 + 8.0 * 9 * n * n / 64


def _body_blobs(config) -> int:
    b = config.body
    if not b.no_slip:
        return 0
    from flagwrap.body.shapes import config_shape

    mesh = config_shape(config).surface_mesh(48, 18)
    if mesh is None:
        return 0
    v, f = mesh
    tri = v[f]
    area = 0.5 * float(np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]),
                                      axis=1).sum())
    sp = b.resolved_blob_spacing(config.filament.helix_radius) / config.filament.length
    return int(area / (sp * sp * math.sqrt(3.0) / 2.0)) + 1


def _tube_blobs(config) -> int:
    if not (config.tubes and config.numerics.hydrodynamics):
        return 0
    from flagwrap.confinement.tube import BLOB_RADIUS_RATIO
    from flagwrap.system.parts import config_tube

    h = config.tubes[0].resolved_blob_spacing / config.filament.length
    return config_tube(config).estimated_blobs(h, BLOB_RADIUS_RATIO * h)


def _parse_bytes(text: str) -> float:
    s = text.strip().upper().removesuffix("B").removesuffix("I")
    unit = s[-1] if s and s[-1] in "KMGT" else ""
    try:
        value = float(s[: len(s) - len(unit)])
    except ValueError:
        raise UserInputError(f"FLAGWRAP_MAX_MEMORY must be a size like 8G or 500M, got {text!r}") from None
    if not math.isfinite(value) or value <= 0:
        raise UserInputError(f"FLAGWRAP_MAX_MEMORY must be a positive size, got {text!r}")
    return value * _SUFFIX[unit]


def available_memory() -> float:
    """Bytes of memory available to a new allocation now (best effort)."""
    try:
        with open("/proc/meminfo") as fh:
            for line in fh:
                if line.startswith("MemAvailable:"):
                    return float(line.split()[1]) * 1024.0
    except OSError:
        pass
    try:
        pages = os.sysconf("SC_AVPHYS_PAGES")
    except (ValueError, OSError, AttributeError):
        pages = os.sysconf("SC_PHYS_PAGES")
    return float(pages) * os.sysconf("SC_PAGE_SIZE")


def memory_limit() -> tuple[float, str]:
    env = os.environ.get("FLAGWRAP_MAX_MEMORY")
    if env:
        return _parse_bytes(env), "FLAGWRAP_MAX_MEMORY"
    return MEMORY_FRACTION * available_memory(), f"{MEMORY_FRACTION:.0%} of the available memory"


def _gb(x: float) -> str:
    return f"{x / 2**30:.3g} GiB"


#: cost of one time step of the direct RPY sum per bead pair [s]: ROS34PW2 + GCR at N = 4000
#: took 0.55 s per step on one core of this machine class (docs/numerics.md, benchmarks/gpu.py)
DIRECT_STEP_SECONDS_PER_PAIR = 0.55 / 4000**2
#: a single step longer than this is refused unless FLAGWRAP_MAX_STEP_SECONDS says otherwise
MAX_STEP_SECONDS = 60.0


def step_seconds(config) -> float:
    """Estimated wall time of one time step [s]: the O(N^2) direct RPY products dominate with
    long-range hydrodynamics on the direct backend; 0 where the estimate does not apply
    (HI off, FMM or GPU backends, which scale ~N)."""
    num = config.numerics
    if not num.hydrodynamics or num.mobility_backend not in ("direct", "auto"):
        return 0.0
    n = float(config.filament.n_beads) * max(1, len(config.flagella))  # all the beads
    return DIRECT_STEP_SECONDS_PER_PAIR * n ** 2


def check_time(config) -> float:
    """Raise :class:`UserInputError` if one step of ``config`` would take longer than the
    limit (``FLAGWRAP_MAX_STEP_SECONDS`` or :data:`MAX_STEP_SECONDS`); returns the estimate."""
    sec = step_seconds(config)
    env = os.environ.get("FLAGWRAP_MAX_STEP_SECONDS")
    try:
        limit = float(env) if env else MAX_STEP_SECONDS
    except ValueError:
        raise UserInputError(f"FLAGWRAP_MAX_STEP_SECONDS must be a number of seconds, got {env!r}") from None
    if sec <= limit:
        return sec
    if config.numerics.mobility_backend == "auto":
        from flagwrap.hydrodynamics.mobility import GPU_AUTO_MIN_BEADS, jax_gpu_available

        if config.filament.n_beads >= GPU_AUTO_MIN_BEADS and jax_gpu_available():
            return 0.0  # "auto" takes the GPU
    N = config.filament.n_beads
    raise UserInputError(
        f"filament.n_beads={N} with hydrodynamics on the direct RPY sum: one time step would take "
        f"about {sec:.3g} s ({N}^2 bead pairs; 0.55 s at 4000 beads on one core), a motor turn "
        f"~1000 steps; the limit is {limit:g} s per step ({'FLAGWRAP_MAX_STEP_SECONDS' if env else 'default'}). "
        "Use numerics.mobility_backend = \"fmm\" (pip install fmm3dpy) or \"jax\" on a GPU, reduce "
        "n_beads, or raise FLAGWRAP_MAX_STEP_SECONDS")


def check_memory(config, limit: float | None = None) -> Estimate:
    """Raise :class:`UserInputError` if ``config`` would need more memory than ``limit``
    (and, first, if one step would take longer than :func:`check_time` allows)."""
    check_time(config)
    est = estimate(config)
    why = "given limit"
    if limit is None:
        limit, why = memory_limit()
    if est.memory <= limit:
        return est
    num, N = config.numerics, config.filament.n_beads
    if est.blob_memory >= max(est.output_memory, est.linalg_memory) and _tube_blobs(config) > \
            _body_blobs(config):
        cause = (f"the tube: about {est.blobs:.3g} blobs with tube[0].blob_spacing = "
                 f"{config.tubes[0].resolved_blob_spacing:.3g} m need {_gb(est.blob_memory)} with "
                 f"body.solver = {config.body.solver!r}; increase tube[0].blob_spacing or use "
                 "body.solver = \"krylov\"")
    elif est.blob_memory >= max(est.output_memory, est.linalg_memory):
        b = config.body
        cause = (f"the no-slip body: about {est.blobs:.3g} blobs at body.blob_spacing = "
                 f"{b.resolved_blob_spacing(config.filament.helix_radius):.3g} m need "
                 f"{_gb(est.blob_memory)} with body.solver = {b.solver!r}; increase "
                 "body.blob_spacing (default R_cell / 3) or use body.solver = \"krylov\"")
    elif est.output_memory >= est.linalg_memory:
        cause = (f"the output: {est.n_saves:.4g} saved frames (motor.protocol turns "
                 f"{est.total_turns:.4g} / numerics.save_every {num.save_every:g}) of "
                 f"filament.n_beads={N} beads need {_gb(est.output_memory)}; shorten "
                 "motor.protocol turns, increase numerics.save_every or reduce filament.n_beads")
    else:
        cause = (f"dense linear algebra for filament.n_beads={N} ({est.unknowns} unknowns) needs "
                 f"{_gb(est.linalg_memory)}; reduce filament.n_beads, use numerics.linear_solver = "
                 "\"auto\" or \"krylov\" (matrix-free), or switch numerics.hydrodynamics off")
    raise UserInputError(f"run would need about {_gb(est.memory)} of memory, more than the limit "
                         f"{_gb(limit)} ({why}): {cause}")


def check_disk(config, output, checkpoint: bool = True, free: float | None = None) -> Estimate:
    """Raise :class:`UserInputError` if the run file (and checkpoint) would not fit on disk."""
    est = estimate(config)
    need = 2.0 * est.file_bytes * (2.0 if checkpoint else 1.0)
    if free is None:
        d = Path(output).resolve().parent
        while not d.exists() and d != d.parent:
            d = d.parent
        free = float(shutil.disk_usage(d).free)
    if need > free:
        num = config.numerics
        raise UserInputError(
            f"run file{' and checkpoint' if checkpoint else ''} for {output} would need about "
            f"{_gb(need)} of disk, more than the {_gb(free)} free: {est.n_saves:.4g} frames "
            f"(motor.protocol turns {est.total_turns:.4g} / numerics.save_every "
            f"{num.save_every:g}) of filament.n_beads={config.filament.n_beads} beads; "
            "increase numerics.save_every or shorten the protocol")
    return est
