"""The time loop: one small object that steps, records, guards and reports progress.

``simulate(config)`` -> :class:`Trajectory` (core units inside, SI on output via
:mod:`flagwrap.io.runfile`). The loop walks through the motor protocol phase by phase (so the
right-hand side is smooth inside every step), clips steps to land on output times, and stops
with a message, keeping everything computed so far, when a guard trips:

* a non-finite state or a step size below ``numerics.dt_min``;
* a bead inside the cell body;
* a bond strain above ``max_strain`` (the springs are meant to be virtually inextensible);
* non-finite generalized forces.

The message names the time, the bead (or bond) and the quantity; the trajectory ends with the
last frame that passed the guards.

Checkpoints (:mod:`flagwrap.io.checkpoint`): with ``checkpoint_path`` set, the complete loop
state is written atomically every ``checkpoint_every_steps`` accepted steps and/or every
``checkpoint_every_seconds`` of wall time; ``run(resume=path)`` continues from one and
reproduces the uninterrupted run bit for bit (the state includes the step-size controller's
``h`` and the reference frames the forces were computed against).
"""

from __future__ import annotations

import math
import signal
import threading
import time as _time
import warnings
from dataclasses import dataclass, field

import numpy as np

from flagwrap.integrators import make_integrator
from flagwrap.system.rod_system import RodSystem

TWO_PI = 2.0 * math.pi
# the per-frame records of a Trajectory, in the order Simulation._record computes them
_RECORDS = ("t", "x", "theta", "m1", "phi", "omega", "motor_torque", "elastic_energy",
            "contact_energy", "min_distance", "max_strain", "interaction_energy", "hook_angle",
            "hook_torque", "hook_twist_torque")


@dataclass
class Trajectory:
    """Recorded run in core units (length L, time 1/omega, torque A/L)."""

    config: object
    t: list = field(default_factory=list)
    x: list = field(default_factory=list)
    theta: list = field(default_factory=list)
    m1: list = field(default_factory=list)
    phi: list = field(default_factory=list)
    omega: list = field(default_factory=list)
    motor_torque: list = field(default_factory=list)
    elastic_energy: list = field(default_factory=list)
    contact_energy: list = field(default_factory=list)
    min_distance: list = field(default_factory=list)
    max_strain: list = field(default_factory=list)
    interaction_energy: list = field(default_factory=list)
    hook_angle: list = field(default_factory=list)
    hook_torque: list = field(default_factory=list)
    hook_twist_torque: list = field(default_factory=list)
    #: a free body's [X (3), q (4), U (3), Omega (3)] per frame (lab frame, core units);
    #: empty for a fixed body
    body: list = field(default_factory=list)
    #: several flagella: each motor's torque [A/L] then its rate [omega] per frame, (2 n,);
    #: empty for one
    motors: list = field(default_factory=list)
    #: a polymorphic filament's order parameter per bead per frame (docs/polymorph.md);
    #: empty without one
    order: list = field(default_factory=list)
    #: each filament's (first bead, bead count) in ``x``: the system's parts
    filaments: list = field(default_factory=list)
    status: str = "running"
    message: str = ""
    n_steps: int = 0
    n_rejected: int = 0
    wall_time: float = 0.0
    #: the state and its reference frames where the loop stopped (not stored in run files:
    #: a continuation, e.g. a steady-state search from a run's end, starts from them)
    final_frames: object = None
    final_y: object = None

    @property
    def ok(self) -> bool:
        return self.status == "completed"

    def filament_slices(self) -> list:
        """Each filament's beads in ``x`` (one slice for one filament, or before any frame)."""
        if self.filaments:
            return [slice(a, a + n) for a, n in self.filaments]
        return [slice(0, len(self.x[0]) if self.x else 0)]

    def arrays(self) -> dict:
        out = {k: np.asarray(getattr(self, k)) for k in _RECORDS}
        if self.body:
            out["body"] = np.asarray(self.body)
        if self.motors:
            out["motors"] = np.asarray(self.motors)
        if self.order:
            out["order"] = np.asarray(self.order)
        return out


class Simulation:
    """Owns the loop for one :class:`RodSystem` and one integrator."""

    def __init__(self, config, system: RodSystem | None = None, integrator=None,
                 max_strain: float = 0.05, checkpoint_path=None, checkpoint_every_steps: int = 0,
                 checkpoint_every_seconds: float = 0.0):
        if system is not None and system.config != config:
            raise ValueError("Simulation: system was built from a different config")
        if system is None:
            from flagwrap.resources import check_memory

            check_memory(config)  # before building anything N^2-sized
        self.config = config
        self.checkpoint_path = checkpoint_path
        self.checkpoint_every_steps = int(checkpoint_every_steps or 0)
        self.checkpoint_every_seconds = float(checkpoint_every_seconds or 0.0)
        self._config_toml = None
        self.system = system or make_system(config)
        num = config.numerics
        self.integrator = integrator or make_integrator(num.integrator, num.tol, num.linear_solver)
        self.h0 = num.dt * TWO_PI
        self.h_min = num.dt_min * TWO_PI
        self.save_dt = num.save_every * TWO_PI
        self.max_steps = num.max_steps
        self.max_strain_limit = max_strain
        self.max_wall = float(num.max_wall_time)

    def _record(self, traj, t, y, info, omega):
        s = self.system
        info_in = info
        info = s.record_view(y, info)  # the lab frame (a turning-frame system rotates it back)
        m1 = np.empty((len(info.theta), 3))
        m2 = np.empty((len(info.theta), 3))
        from flagwrap.elasticity._kernels import material_frames

        material_frames(info.frames.t, info.frames.d1, info.theta, m1, m2)
        # everything computed before anything is appended: an interrupt in between must not
        # leave the records with different lengths
        phi = y[s.i_phi]
        hook = s.joint_observables(info, m1, m2)
        # a torque motor's own rate (several: the first motor's)
        rate = float(np.ravel(s.motor_rate(y, info_in, omega))[0])
        row = (t, info.x.copy(), info.theta.copy(), m1, phi, rate,
               s.motor_torque(info_in, phi, omega, y), info.elastic_energy, info.contact_energy,
               float(np.min(info.distance[s.free_beads])) if s.nb else np.inf,
               self._strain(info), info.interaction_energy) + hook
        body = getattr(s, "body_record", None)  # a moving body's pose and velocities
        body = None if body is None else body(y, info_in)
        order = getattr(s, "order_record", None)  # a polymorphic filament's phi per bead
        order = None if order is None else order(y)
        motors = None
        if s.n_filaments > 1:  # every motor's torque and rate
            motors = np.concatenate([s.motor_torques(info_in, phi, omega, y),
                                     np.broadcast_to(s.motor_rate(y, info_in, omega),
                                                     (s.n_filaments,))])
        for name, value in zip(_RECORDS, row):
            getattr(traj, name).append(value)
        if body is not None:
            traj.body.append(body)
        if motors is not None:
            traj.motors.append(motors)
        if order is not None:
            traj.order.append(order)

    def _strain(self, info) -> float:
        ln = self.system.bond_lengths(info.x)
        return float(np.max(np.abs(ln / self.system.l0 - 1.0)))

    def _guard(self, info) -> str:
        s = self.system
        if not np.all(np.isfinite(info.G)):
            k = int(np.flatnonzero(~np.isfinite(info.G))[0])
            block, i = s.layout.locate(k)
            if block == "x":
                where = f"bead {s.free_bead_ids[i // 3]} (force component {'xyz'[i % 3]})"
            elif block == "theta":
                where = f"bond {s.free_bond_ids[i]} (twist torque)"
            else:
                where = f"unknown {k} ({block})"
            return f"non-finite generalized force {info.G[k]} on {where}"
        if s.nb and np.min(info.distance[s.free_beads]) <= 0.0:
            i = int(s.free_bead_ids[np.argmin(info.distance[s.free_beads])])
            return f"bead {i} entered the cell body (distance {info.distance[i]:.3g} L)"
        strain = np.abs(s.bond_lengths(info.x) / s.l0 - 1.0)
        if strain.max() > self.max_strain_limit:
            j = int(np.argmax(strain))
            i = int(s.bond_first[j])
            return (f"bond {j} (beads {i}-{i + 1}) strain {strain[j]:.3g} exceeds the limit "
                    f"{self.max_strain_limit:g} (stretching springs no longer inextensible)")
        return ""

    def _fastest(self, y, info) -> str:
        """``"; fastest bead i (|dx/dt| = v L omega)"`` at the last good state (diagnostics)."""
        s = self.system
        try:
            v = s.apply_mobility(y, info.G)[s.sl_x].reshape(-1, 3)
            sp = np.linalg.norm(v, axis=1)
            i = int(np.nanargmax(sp))
            return f"; fastest bead {s.free_bead_ids[i]} (|dx/dt| = {sp[i]:.3g} L omega)"
        except (ValueError, FloatingPointError):
            return ""

    def _start_contact_hint(self, info) -> str:
        """Why a run that stops at once may have done so: free beads next to the clamp that
        start inside the body's contact range (a fine chain: the repulsion throws them off)."""
        s = self.system
        cutoff = getattr(s.body, "cutoff", None)
        if cutoff is None or not s.nb:
            return ""
        # the beads next to each clamp: as far along the chain as the contact range reaches
        near = np.concatenate([np.arange(p.bead0 + p.nc, min(p.bead0 + p.N, p.bead0 + p.nc + int(
            np.ceil(cutoff / s.bond)) + 1)) for p in s.parts])
        d = info.distance[near]
        inside = np.flatnonzero(d < cutoff)
        if not inside.size:
            return ""
        i = int(near[inside[np.argmin(d[inside])]])
        L = self.config.filament.length
        return (f"; bead {i} starts {info.distance[i] * L * 1e3:.3g} mm from the cell body, inside "
                f"its contact range a (1 + contact.range) = {cutoff * L * 1e3:.3g} mm: with "
                f"filament.n_beads = {self.config.filament.n_beads} (bond {s.bond * L * 1e3:.3g} mm) "
                "beads next to the clamp start in contact; use fewer beads or a smaller "
                "contact.range")

    def _checkpoint_toml(self) -> str:
        if self._config_toml is None:
            from flagwrap.io.config import config_to_toml

            self._config_toml = config_to_toml(self.config)
        return self._config_toml

    def _write_checkpoint(self, traj, t, t_end, y, base_in, h, next_save, wall_time):
        from flagwrap.io.checkpoint import Checkpoint, write_checkpoint

        write_checkpoint(Checkpoint(
            t=t, t_end=t_end, h=h, next_save=next_save, n_steps=traj.n_steps,
            n_rejected=traj.n_rejected, wall_time=wall_time, y=y, base_t=base_in.t,
            base_d1=base_in.d1, base_rt=base_in.rt, records=traj.arrays(),
            config_toml=self._checkpoint_toml(), solver_memory=self.system.solver_memory()),
            self.checkpoint_path)

    def run(self, t_end: float | None = None, progress: bool = False, y0=None,
            base=None, t0: float = 0.0, resume=None, budget_used=(0, 0.0),
            stop=None) -> Trajectory:
        """Integrate from ``t0`` to ``t_end`` (default: the end of the motor protocol; beyond
        it the motor keeps its last speed).

        ``resume``: a checkpoint path (or :class:`~flagwrap.io.checkpoint.Checkpoint`) to
        continue from instead of ``y0/base/t0``; it must come from the same config and version.
        ``budget_used``: (steps, wall seconds) already spent on this run by earlier calls
        that this one continues (a run split into chunks), counted against
        ``numerics.max_steps`` / ``max_wall_time``; these budgets are per invocation
        otherwise, so a run stopped by one can be resumed.
        ``stop``: a terminating event, called with the trajectory after every recorded frame;
        a non-empty string it returns ends the run there as "completed" with that message
        (e.g. :class:`flagwrap.analysis.critical.BuckledStop`).
        """
        s = self.system
        sched = s.schedule
        traj = Trajectory(self.config, filaments=[(p.bead0, p.N) for p in s.parts])
        wall0 = 0.0
        if resume is not None:
            from flagwrap.io.checkpoint import Checkpoint, check_compatible, read_checkpoint

            ck = resume if isinstance(resume, Checkpoint) else read_checkpoint(resume)
            check_compatible(ck, self.config, resume if not isinstance(resume, Checkpoint) else "checkpoint")
            if t_end is not None and t_end != ck.t_end:
                from flagwrap.errors import UserInputError

                raise UserInputError(f"checkpoint runs to t={ck.t_end}, not the requested t_end={t_end}")
            t_end, t, h, next_save = ck.t_end, ck.t, ck.h, ck.next_save
            for k, v in ck.records.items():
                getattr(traj, k).extend(list(v))
            traj.n_steps, traj.n_rejected, wall0 = ck.n_steps, ck.n_rejected, ck.wall_time
            y = ck.y.copy()
            base_in = ck.base()
            s.restore_solver_memory(ck.solver_memory)
            info = s.forces(y, base_in)
            t0 = t
        else:
            t_end = sched.t_end if t_end is None else t_end
            if y0 is None:  # a new run: nothing of an earlier one's stage solver carries over
                s.restore_solver_memory(np.zeros(0))
            y = s.initial_y() if y0 is None else np.array(y0, float)
            base_in = (s.frames0.copy() if base is None else base)
            info = s.forces(y, base_in)
            if y0 is not None:  # the config's checks saw its own start, not this one
                from flagwrap.system.parts import check_start_state

                check_start_state(self.config, s, y, info)
            t = t0
            h = self.h0
            self._record(traj, t, y, info, sched(t))
            next_save = t + self.save_dt
        base = info.frames
        info_start, t_start = info, t
        fresh = resume is None and y0 is None  # the configured initial state
        n_steps0 = traj.n_steps  # the budgets count this invocation (plus budget_used)
        steps_left = self.max_steps - int(budget_used[0])
        wall_left = self.max_wall - float(budget_used[1])
        ck_steps, ck_secs = self.checkpoint_every_steps, self.checkpoint_every_seconds
        ck_on = self.checkpoint_path is not None and (ck_steps > 0 or ck_secs > 0)
        bar = None
        if progress:
            from tqdm.auto import tqdm

            # the whole run's turns, a resumed run starting where it stopped
            bar = tqdm(total=round(t_end / TWO_PI, 3), initial=round(t0 / TWO_PI, 3), unit="turn",
                       desc=self.config.name,
                       bar_format="{l_bar}{bar}| {n:.2f}/{total:.2f} turns [{elapsed}<{remaining}]")
        start = _time.perf_counter()
        last_ck = start
        fixed = not self.integrator.adaptive
        eps = 1e-12 * max(1.0, t_end)
        interrupted = _deferred_sigint()

        def keep_last_state():
            # (t, y, info) is consistent between steps: the run's last frame unless saved
            if traj.t[-1] < t - eps:
                self._record(traj, t, y, info, sched(t - eps))

        try:
            while t < t_end - eps:
                if interrupted():
                    keep_last_state()
                    raise KeyboardInterrupt
                k = sched.segment_index(t + eps)
                seg = sched.segments[k]
                omega = seg.omega
                # the last phase runs on to t_end (the schedule keeps its speed past its end)
                seg_end = seg.t1 if k < len(sched.segments) - 1 else max(seg.t1, t_end)
                stop_at = min(seg_end, t_end, next_save)
                h_try = min(h, stop_at - t)
                res = self.integrator.step(s, y, base, info, h_try, omega)
                if not res.accepted:
                    traj.n_rejected += 1
                    if fixed:
                        raise _Stop(f"t/T={t / TWO_PI:.6g}: {res.reason} with fixed dt={h_try / TWO_PI:.3g} T"
                                    f"{self._fastest(y, info)}")
                    h = res.h_next
                    if h < self.h_min:
                        raise _Stop(f"t/T={t / TWO_PI:.6g}: step size {h / TWO_PI:.3g} T fell below "
                                    f"dt_min={self.h_min / TWO_PI:.3g} T ({res.reason})"
                                    f"{self._fastest(y, info)}")
                    continue
                traj.n_steps += 1
                t_new = t + h_try
                msg = self._guard(res.info)
                if msg:  # (t, y) stays the last good state: every stored frame passed the guards
                    raise _Stop(f"t/T={t_new / TWO_PI:.6g}: {msg}")
                base_in = base
                y, info = res.y, res.info
                base = info.frames
                if not fixed:
                    # do not let a step clipped to an output time shrink the controller's step
                    h = res.h_next if h_try >= h * 0.999 else max(h, res.h_next)
                if bar is not None:
                    # set, not summed: summed rounded increments overshoot the total (tqdm's
                    # "clamping frac" warning and a negative remaining time at the end)
                    done = min(bar.total, round(t_new / TWO_PI, 3))
                    if done > bar.n:
                        bar.n = done
                        bar.update(0)
                t = t_new
                if t >= next_save - eps:
                    self._record(traj, t, y, info, omega)
                    next_save += self.save_dt
                    if stop is not None:
                        why = stop(traj)
                        if why:
                            traj.status, traj.message = "completed", why
                            break
                over = None
                if traj.n_steps - n_steps0 >= steps_left:
                    over = f"reached numerics.max_steps={self.max_steps}"
                elif self.max_wall and _time.perf_counter() - start > wall_left:
                    over = f"wall time above numerics.max_wall_time={self.max_wall:g} s"
                if ck_on:
                    now = _time.perf_counter()
                    if over or (ck_steps > 0 and traj.n_steps % ck_steps == 0) or \
                            (ck_secs > 0 and now - last_ck >= ck_secs):
                        # (at a budget stop too, so --resume goes on from exactly here)
                        try:
                            self._write_checkpoint(traj, t, t_end, y, base_in, h, next_save,
                                                   wall0 + now - start)
                        except OSError as exc:  # a full disk must not cost the computed run
                            warnings.warn(f"checkpoint not written to {self.checkpoint_path} "
                                          f"({exc}); the run goes on without checkpoints",
                                          RuntimeWarning, stacklevel=2)
                            ck_on = False
                        last_ck = _time.perf_counter()
                if over:
                    raise _Stop(f"t/T={t / TWO_PI:.6g}: {over}", budget=True)
            keep_last_state()
            traj.status = "completed"
        except _Stop as halt:
            keep_last_state()  # every path to here leaves (t, y, info) at the last good state
            traj.status = "failed"
            traj.message = str(halt)
            if fresh and not halt.budget and t < t_start + self.save_dt:
                # a fresh run that failed at once: say if it started in contact
                traj.message += self._start_contact_hint(info_start)
        except (KeyboardInterrupt, SystemError) as exc:
            if isinstance(exc, SystemError) and not _caused_by_interrupt(exc):
                raise
            # keep what was computed, but still stop the caller (a sweep, a notebook): the
            # exception carries the saved frames. A first Ctrl-C is deferred to the end of the
            # step (then the state is appended); a second one lands mid-step, where the state
            # may be half-updated, so it is not appended (at most save_every of motion lost)
            traj.status = "failed"
            traj.message = f"t/T={t / TWO_PI:.6g}: interrupted ({interrupted.why})"
            raise RunInterrupted(traj, interrupted.signame) from None  # (finally: wall time,
            # frames, progress bar)
        finally:
            interrupted.restore()
            if bar is not None:
                bar.close()
            traj.wall_time = wall0 + _time.perf_counter() - start
            traj.final_frames = base
            traj.final_y = y
        if interrupted():
            # the Ctrl-C came during the last step, or one a guard stopped: the run ended by
            # itself, but the caller asked to stop (a sweep must not go on to the next case)
            note = f"interrupted ({interrupted.why}) during the last step"
            traj.message = f"{traj.message}; {note}" if traj.message else note
            raise RunInterrupted(traj, interrupted.signame)
        return traj


def _caused_by_interrupt(exc) -> bool:
    """Whether ``exc`` wraps a KeyboardInterrupt: numba turns one raised while it loads or
    runs compiled code into ``SystemError`` (the chain keeps the original)."""
    seen = set()
    while exc is not None and id(exc) not in seen:
        if isinstance(exc, KeyboardInterrupt):
            return True
        seen.add(id(exc))
        exc = exc.__cause__ or exc.__context__
    return False


class _Stop(Exception):
    """A run ends early; ``budget``: by numerics.max_steps / max_wall_time (not a failure of
    the physics or the numerics)."""

    def __init__(self, message: str, budget: bool = False):
        super().__init__(message)
        self.budget = budget


class _deferred_sigint:
    """Turn the first SIGINT or SIGTERM during a run into a flag the time loop checks between
    steps (``signame`` says which came).

    Why: a KeyboardInterrupt raised inside a numba kernel (or while numba loads one from its
    cache) surfaces as a ``SystemError``, not a KeyboardInterrupt, so the run would die with a
    traceback instead of keeping its frames; SIGTERM (what ``timeout`` and batch schedulers
    send) would kill it without a word. The handler puts the previous ones back, so a second
    signal acts at once (a step can take seconds at large N). Installed only in the main
    thread (Python allows signal handlers nowhere else) and only over the default handlers
    (a test runner or a GUI that owns a signal keeps it); elsewhere the flag stays down.
    """

    SIGNALS = {"SIGINT": signal.default_int_handler, "SIGTERM": signal.SIG_DFL}

    def __init__(self):
        self.flag = False
        self.signame = ""
        self.previous = {}
        if threading.current_thread() is not threading.main_thread():
            return
        for name, default in self.SIGNALS.items():
            sig = getattr(signal, name)
            if signal.getsignal(sig) is not default:
                continue  # someone else owns it: leave it
            try:
                signal.signal(sig, self._handle)
            except ValueError:  # the main thread of a sub-interpreter may not set handlers
                continue
            self.previous[sig] = default

    def _handle(self, signum, frame):
        self.flag = True
        self.signame = signal.Signals(signum).name
        self.restore()

    def restore(self):
        for sig, handler in self.previous.items():
            signal.signal(sig, handler)
        self.previous = {}

    def __call__(self) -> bool:
        return self.flag

    @property
    def why(self) -> str:
        return "SIGTERM" if self.signame == "SIGTERM" else "SIGINT / Ctrl-C"


class RunInterrupted(KeyboardInterrupt):
    """Ctrl-C (SIGINT) or SIGTERM during :meth:`Simulation.run`; ``.trajectory`` holds the
    frames computed so far (status "failed", message naming the time and the signal), e.g.
    for ``write_run``; ``.signame`` which signal ("SIGINT", "SIGTERM"; "" for a
    KeyboardInterrupt raised otherwise)."""

    def __init__(self, trajectory, signame: str = ""):
        super().__init__(trajectory.message)
        self.trajectory = trajectory
        self.signame = signame


def make_system(config):
    """The config's system, a :class:`RodSystem`: transformed to the turning frame when
    ``numerics.frame = "rotating"`` (:class:`flagwrap.system.rotating.RotatingSystem`), or
    given a free body (``body.motion = "free"``: :class:`flagwrap.system.swimmer.
    SwimmerSystem`); either is a ``RodSystem`` over the same parts, not a wrapper. A
    ``[polymorph]`` adds its order block to whichever it is
    (:class:`flagwrap.system.polymorph.PolymorphSystem`)."""
    if config.body.free:
        from flagwrap.system.swimmer import make_swimmer

        system = make_swimmer(config)
        if config.numerics.frame == "rotating":
            from flagwrap.system.swimmer import SwimmerRotating

            system = SwimmerRotating(system)
    elif config.numerics.frame == "rotating":
        from flagwrap.system.rotating import RotatingSystem

        system = RotatingSystem(RodSystem(config))
    else:
        system = RodSystem(config)
    if config.polymorph.enabled:
        from flagwrap.system.polymorph import PolymorphSystem

        system = PolymorphSystem(system)
    return system


def simulate(config, progress: bool = False, resume=None, **kwargs) -> Trajectory:
    """Run ``config`` through its whole motor protocol; see :class:`Simulation`.

    ``resume``: checkpoint to continue from; ``kwargs`` go to :class:`Simulation` (e.g.
    ``checkpoint_path``, ``checkpoint_every_steps``, ``checkpoint_every_seconds``).
    """
    from threadpoolctl import threadpool_limits

    with threadpool_limits(limits=config.numerics.threads):
        return Simulation(config, **kwargs).run(progress=progress, resume=resume)
