"""Steady branches other than the whirl, and the bifurcation diagram of one helix.

Below the whirl's Hopf (:mod:`.threshold`) the helix is not always back on the whirl: the
motor reversal can throw it into a *far* state, a folded shape resting against the body
that turns rigidly with the motor. In the turning frame that shape is a fixed point of the
same equations as the whirl, on a branch of its own. The far branch exists only above a
saddle-node (fold) ``M_f``: below it every run returns to the whirl. Between ``M_f`` and the
Hopf both states are stable and which one a run ends in depends on how hard it was kicked
(docs/stability.md, "Two thresholds").

The far branch is found and followed in three steps:

1. **A far state** from the time domain: the motor reversal at ``m_far`` (by default 1.07
   ``M_Hopf``, where the Fig. 4(a) helix's reversal lands in the far state), from the steady
   whirl of the other direction (what a long first phase of the paper's protocol ends on),
   run ``settle`` turns in the turning frame, then Newton from the end state
   (:func:`far_state_from_reversal`); or a run file's last frame (:func:`far_state_from_run`).
2. **Down and up in M by relaxation** (:func:`relax`): at each new ``M`` the previous far
   state is run for ``settle`` turns in the time domain and polished by Newton. The far
   state's contact set with the body changes along the branch; the contact law's stiffness
   falls to zero over the last 2e-5 L before its cut-off, so the branch is only piecewise
   smooth there and an arclength continuation stalls at such grazing points, while the
   stable state itself, which the relaxation follows, carries on. The branch is "lost" when
   the relaxed state has jumped away (by more than ``jump`` L) from the previous one.
3. **The fold** (:func:`arclength`): pseudo-arclength continuation (Keller 1977; Allgower &
   Georg, *Introduction to Numerical Continuation Methods*, 1990, ch. 2) from the last far
   state above the loss, in ``(z, log M)``, through the turning point, where one real
   eigenvalue of the Jacobian crosses zero and the branch turns back as the unstable
   (saddle) branch. ``M_f`` is the vertex of a parabola through the points around the turn;
   the eigenvalue's sign is checked on both sides.

Beside it the whirl's branch (stable below the Hopf, unstable above) and the Hopf cycle's
extent from the time domain (a kicked whirl run on until its oscillation saturates) make the
diagram: the free end's axial position against ``M``.
"""

from __future__ import annotations

import dataclasses
import math
import time
from dataclasses import dataclass, field

import numpy as np

from flagwrap.errors import UserInputError
from flagwrap.stability.steady import NewtonFailure, SteadyState, march, newton, retract


# --------------------------------------------------------------------------------------------
# pseudo-arclength continuation


@dataclass
class ArcPoint:
    """A point of a continued branch: its steady state, the tangent's ``d log M / ds`` there,
    the leading eigenvalue (largest real part) and the largest real eigenvalue
    (``leading_real``; ``nan`` if none is real), the free end's axial position ``tip_z`` [L]."""

    state: SteadyState = field(repr=False)
    machin: float
    dp_ds: float
    leading: complex
    leading_real: float
    tip_z: float


@dataclass
class Arc:
    """A continued branch; ``fold`` the index of the first point past a turn in ``M``
    (``None`` if none), ``fold_machin`` the turn's ``M``."""

    points: list
    fold: int | None = None
    fold_machin: float = math.nan
    message: str = ""


def _f_p(frame, z, base, p, h: float = 1e-6) -> np.ndarray:
    """``dF/d log M`` by central differences."""
    fp, _ = frame.velocity(z, base, math.exp(p + h))
    fm, _ = frame.velocity(z, base, math.exp(p - h))
    return (fp - fm) / (2.0 * h)


def _bordered(J, Fp, row) -> np.ndarray:
    n = J.shape[0]
    A = np.empty((n + 1, n + 1))
    A[:n, :n] = J
    A[:n, n] = Fp
    A[n] = row
    return A


def _tangent(frame, state, prev) -> np.ndarray:
    """The unit null vector of ``[J, F_p]`` at ``state``, oriented along ``prev``."""
    p = math.log(state.machin)
    J = frame.jacobian(state.z, state.base, state.machin, state.info)
    n = J.shape[0]
    rhs = np.zeros(n + 1)
    rhs[n] = 1.0
    t = np.linalg.solve(_bordered(J, _f_p(frame, state.z, state.base, p), prev), rhs)
    return t / np.linalg.norm(t)


def _eigen(frame, state):
    from flagwrap.stability.spectrum import spectrum

    w = spectrum(frame, state).values
    real = w[np.abs(w.imag) <= 1e-9 * np.maximum(1.0, np.abs(w.real))].real
    return complex(w[0]), float(real.max()) if real.size else math.nan


def arc_point(frame, state, dp_ds: float = math.nan) -> ArcPoint:
    lead, lead_real = _eigen(frame, state)
    return ArcPoint(state, state.machin, float(dp_ds), lead, lead_real,
                    float(state.info.x[-1, 2]))


def _correct(frame, z0, base, p0, tau, step_tol=1e-10, max_iter=10, max_step=0.05):
    """Newton on the bordered system ``F(z, p) = 0, tau . ((z, p) - (z0, p0)) = 0``."""
    n3 = frame.n3
    z, p = np.array(z0, float), float(p0)
    for it in range(1, max_iter + 1):
        f, info = frame.velocity(z, base, math.exp(p))
        base = info.frames
        if not np.all(np.isfinite(f)):
            break
        J = frame.jacobian(z, base, math.exp(p), info)
        n = J.shape[0]
        r = np.concatenate([-f, [-(tau[:n] @ (z - z0) + tau[n] * (p - p0))]])
        try:
            d = np.linalg.solve(_bordered(J, _f_p(frame, z, base, p), tau), r)
        except np.linalg.LinAlgError:
            break
        sx = float(np.max(np.abs(d[:n3])))
        step = max(sx, float(np.max(np.abs(d[n3:n]))) / 10.0 if n > n3 else 0.0, abs(d[n]))
        if not math.isfinite(step) or sx > max_step:
            break
        z = retract(frame, z, d[:n])
        p += d[n]
        if step < step_tol:
            f, info = frame.velocity(z, base, math.exp(p))
            return SteadyState(z, info.frames, math.exp(p), float(np.max(np.abs(f))), step,
                               it, True, info)
    raise NewtonFailure(f"the arclength corrector did not converge near M = {math.exp(p0):.6g}",
                        None)


def arclength(frame, start: SteadyState, direction: int = -1, ds: float = 0.01,
              ds_max: float = 0.1, ds_min: float = 1e-5, m_min: float = 1e-3,
              m_max: float = 1e8, max_points: int = 60, past_fold: int = 4,
              on_point=None) -> Arc:
    """Follow the branch through ``start`` (a converged :class:`SteadyState`), first towards
    decreasing ``M`` (``direction = -1``) or increasing (``+1``), by pseudo-arclength steps
    ``ds`` in the Euclidean norm of ``(z, log M)`` (halved where the corrector fails, grown
    1.5x after an easy step, within ``[ds_min, ds_max]``). Stops ``past_fold`` points after
    the first turn in ``M``, when ``M`` leaves ``[m_min, m_max]``, after ``max_points``, or
    when the step falls below ``ds_min`` (``message`` says which)."""
    n = start.z.size
    seed = np.zeros(n + 1)
    seed[n] = float(direction)
    tau = _tangent(frame, start, seed)
    cur = start
    arc = Arc([arc_point(frame, cur, tau[n])], message="max_points reached")
    while len(arc.points) < max_points:
        p = math.log(cur.machin)
        try:
            nxt = _correct(frame, retract(frame, cur.z, ds * tau[:n]), cur.base, p + ds * tau[n],
                           tau)
        except NewtonFailure:
            ds /= 2.0
            if ds < ds_min:
                arc.message = f"step below {ds_min:g} at M = {cur.machin:.6g}"
                break
            continue
        new_tau = _tangent(frame, nxt, tau)
        pt = arc_point(frame, nxt, new_tau[n])
        arc.points.append(pt)
        if on_point is not None:
            on_point(pt)
        if arc.fold is None and np.sign(new_tau[n]) != np.sign(tau[n]):
            arc.fold = len(arc.points) - 1
            arc.fold_machin = _fold_machin(arc.points, arc.fold)
        tau, cur = new_tau, nxt
        if nxt.iterations <= 4:
            ds = min(ds_max, 1.5 * ds)
        if arc.fold is not None and len(arc.points) - 1 - arc.fold >= past_fold:
            arc.message = "past the fold"
            break
        if not m_min <= nxt.machin <= m_max:
            arc.message = f"M = {nxt.machin:.6g} left [{m_min:g}, {m_max:g}]"
            break
    return arc


def _fold_machin(points, k) -> float:
    """``M`` at the turn: the vertex of the parabola ``log M (s)`` through the three points
    around the sign change of ``dp/ds`` (arclength between points from their states)."""
    i = max(1, min(k, len(points) - 2))
    trio = points[i - 1:i + 2]
    s = [0.0]
    for a, b in zip(trio[:-1], trio[1:]):
        s.append(s[-1] + math.hypot(float(np.linalg.norm(b.state.z - a.state.z)),
                                    math.log(b.machin / a.machin)))
    c = np.polyfit(s, [math.log(q.machin) for q in trio], 2)
    if c[0] == 0.0:
        return float(trio[1].machin)
    return float(math.exp(np.polyval(c, -c[1] / (2.0 * c[0]))))


# --------------------------------------------------------------------------------------------
# the time domain in the turning frame


def frame_config(config, machin: float, protocol):
    """``config`` at ``machin``, stepped in the turning frame with ``protocol`` (phases)."""
    # the reference speed given as M (a config that gives it as a frequency in Hz gives it up)
    return config.replace(
        motor=dataclasses.replace(config.motor, machin=float(machin), frequency=None,
                                  protocol=tuple(protocol)),
        numerics=dataclasses.replace(config.numerics, frame="rotating"))


def _run(config, y0=None, base=None):
    from flagwrap.simulation import Simulation, make_system

    return Simulation(config, system=make_system(config)).run(y0=y0, base=base)


def distance(frame, a, b) -> float:
    """Largest bead distance between two states' unknowns ``z`` [L]."""
    d = (np.asarray(a)[:frame.n3] - np.asarray(b)[:frame.n3]).reshape(-1, 3)
    return float(np.max(np.linalg.norm(d, axis=1))) if d.size else 0.0


def relax(config, frame, z, base, machin: float, turns: float, direction: str) -> SteadyState:
    """The steady state a run of ``turns`` motor turns at ``machin`` reaches from ``(z,
    base)`` (turning frame), polished by Newton. Raises :class:`NewtonFailure` when the run's
    end is not near a fixed point (still moving: an oscillation, or a run that failed)."""
    from flagwrap.params import Phase

    cfg = frame_config(config, machin, (Phase(direction, turns),))
    tr = _run(cfg, frame.full(z), base)
    if not tr.ok:
        raise NewtonFailure(f"the relaxation run at M = {machin:.6g} stopped: {tr.message}", None)
    return newton(frame, machin, frame.reduce(tr.final_y), tr.final_frames)


# --------------------------------------------------------------------------------------------
# the diagram


@dataclass
class Cycle:
    """The whirl kicked along its critical mode at ``machin`` and run ``turns`` turns: the
    free end's axial range over the last ``window`` turns and the mean largest bead distance
    from the (unstable) whirl there; ``far`` when the run left for the far state."""

    machin: float
    tip_min: float
    tip_max: float
    amplitude: float
    far: bool
    turns: float


@dataclass
class Diagram:
    """The bifurcation diagram of one helix in one motor direction (core units; ``tip_z``:
    the free end's axial position [L], rest ``tip_z0``)."""

    direction: str
    hopf: object  # the whirl's StabilityResult (threshold.find_critical)
    whirl: list = field(default_factory=list)  # ArcPoint, the whirl up to m_hi
    far: list = field(default_factory=list)  # ArcPoint, the far branch by relaxation
    saddle: list = field(default_factory=list)  # ArcPoint, the arc from the last far state
    cycles: list = field(default_factory=list)  # Cycle
    machin_fold: float = math.nan
    fold_eigenvalues: tuple = (math.nan, math.nan)  # leading real eigenvalue before, after
    far_lost_below: float = math.nan  # the highest M where relaxation left the far branch
    far_source: str = ""
    message: str = ""
    wall_time: float = 0.0
    tip_z0: float = math.nan

    @property
    def machin_hopf(self) -> float:
        return self.hopf.machin_c if self.hopf is not None else math.nan

    @property
    def fold_found(self) -> bool:
        return math.isfinite(self.machin_fold)

    def torques(self) -> dict:
        """|motor torque| [A/L] (:func:`~flagwrap.stability.threshold.state_torque`) of the
        whirl at the top of its threshold's bracket (``"hopf"``) and of the lowest far state,
        the one nearest the fold (``"fold"``), where they exist."""
        from flagwrap.stability.threshold import state_torque

        out = {}
        if self.hopf is not None and self.hopf.state is not None:
            out["hopf"] = state_torque(self.hopf.frame, self.hopf.state)
        lowest = [p for p in self.far if p.state is not None]
        if lowest:
            out["fold"] = state_torque(self.hopf.frame,
                                       min(lowest, key=lambda p: p.machin).state)
        return out

    def summary(self) -> dict:
        def pts(ps):
            return [{"machin": p.machin, "tip_z": p.tip_z, "leading_re": p.leading.real,
                     "leading_im": abs(p.leading.imag), "leading_real": p.leading_real}
                    for p in ps]

        return {
            "found": True, "direction": self.direction, "machin_hopf": self.machin_hopf,
            "hopf_crossing": self.hopf.crossing if self.hopf is not None else "",
            "machin_fold": self.machin_fold, "fold_found": self.fold_found,
            "fold_eigenvalues": list(self.fold_eigenvalues),
            "far_lost_below": self.far_lost_below, "far_source": self.far_source,
            "message": self.message, "wall_time": self.wall_time, "tip_z0": self.tip_z0,
            "whirl": pts(self.whirl), "far": pts(self.far), "saddle": pts(self.saddle),
            "cycles": [dataclasses.asdict(c) for c in self.cycles],
        }


#: M / M_c at which the reversal is tried in turn when no ``m_far`` is given
FAR_LADDER = (1.07, 1.25, 1.5)


class FarStateNotFound(RuntimeError):
    """No far state where one was looked for; the message says what the run ended in."""


def far_state_from_reversal(config, frame, machin: float, direction: str, settle: float,
                            whirl: SteadyState | None, m_start: float = 10.0) -> SteadyState:
    """The far state the motor reversal throws the helix into at ``machin``: the steady
    whirl of the other direction (the end of a long first phase of the paper's protocol,
    found by Newton continuation), then ``settle`` turns in ``direction`` in the turning frame
    and Newton from the end state. Raises :class:`FarStateNotFound` when the end is not a
    fixed point, or is the whirl ``whirl``."""
    from flagwrap.params import Phase
    from flagwrap.stability.steady import branch
    from flagwrap.stability.threshold import DIRECTIONS, make_frame

    other = "ccw" if direction == "cw" else "cw"
    what = (f"the reversal from the steady {other.upper()} whirl at M = {machin:.5g} "
            f"({settle:g} {direction.upper()} turns in the turning frame)")
    back = make_frame(config, DIRECTIONS[other])
    try:
        first = branch(back, [machin], m_start=min(m_start, machin / 2))[machin]
    except NewtonFailure:
        raise FarStateNotFound(f"no steady {other.upper()} whirl at M = {machin:.5g} to reverse "
                               f"from (Newton continuation lost it)") from None
    # both frames are the lab's at phi = 0: the same unknowns
    tr = _run(frame_config(config, machin, (Phase(direction, settle),)),
              frame.full(first.z), first.base)
    if not tr.ok:
        raise FarStateNotFound(f"{what} stopped: {tr.message}")
    z = frame.reduce(tr.final_y)
    try:
        st = newton(frame, machin, z, tr.final_frames)
    except NewtonFailure as exc:
        f, _ = frame.velocity(z, tr.final_frames, machin)
        raise FarStateNotFound(f"{what} does not end at rest in the turning frame (|dz/dt| = "
                               f"{np.max(np.abs(f)):.2g} at its end; {exc})") from None
    if whirl is not None and distance(frame, st.z, whirl.z) < 0.05:
        raise FarStateNotFound(f"{what} ends on the whirl (within "
                               f"{distance(frame, st.z, whirl.z):.2g} L of it)")
    return st


def read_far_from(config, path) -> dict:
    """A run file's last frame as a far-state start: ``{"x", "theta", "phi", "machin"}``
    (lab frame). Refuses (:class:`UserInputError`, one line) a file without frames or a run
    of another helix or system than ``config`` (its filament, body, contact, clamp, joint,
    flagella or walls differ); the motor, fluid and numerics may differ."""
    from flagwrap.io.runfile import config_of, read_run

    ds = read_run(path)
    try:
        rcfg = config_of(ds)
        if not ds.sizes.get("time", 0):
            raise UserInputError(f"--far-from {path}: the run file holds no frames")
        out = {"x": np.asarray(ds["position"].values[-1], float) / rcfg.scales.length,
               "theta": np.asarray(ds["twist_angle"].values[-1], float),
               "phi": float(ds["motor_angle"].values[-1]), "machin": float(rcfg.machin)}
        if "polymorph_order" in ds.variables:
            out["order"] = np.asarray(ds["polymorph_order"].values[-1], float)
    finally:
        ds.close()
    parts = ("filament", "body", "contact", "clamp", "joint", "flagella", "walls", "polymorph")
    differ = [k for k in parts if getattr(rcfg, k) != getattr(config, k)]
    if differ:
        raise UserInputError(f"--far-from {path}: a run of another helix or system than "
                             f"{config.name!r} (its [{'], ['.join(differ)}] differ)")
    return out


def far_state_from_run(config, frame, path, last: dict, direction: str, settle: float,
                       m_range: tuple) -> SteadyState:
    """The far state near a run file's last frame (``last``: :func:`read_far_from`): its
    beads turned into the turning frame by its motor angle, relaxed ``settle`` turns at the
    run's ``M``, polished by Newton. Refuses a run at an ``M`` outside ``m_range``."""
    from flagwrap.system.rotating import rotation

    m = last["machin"]
    lo, hi = m_range
    if not lo <= m <= hi:
        raise UserInputError(f"--far-from {path}: its M = {m:.5g} lies outside the diagram's "
                             f"range [{lo:.5g}, {hi:.5g}] (--m-lo, --m-hi)")
    # the lab beads turned back by the motor angle (R^T x, row by row): the turning frame
    own = {"order": last["order"]} if "order" in last else {}  # a polymorphic filament's
    y = frame.system.pack(last["x"] @ rotation(frame.axis, last["phi"]), last["theta"], 0.0,
                          **own)
    try:
        return relax(config, frame, frame.reduce(y), None, m, settle, direction)
    except NewtonFailure as exc:
        raise FarStateNotFound(f"the last frame of {path} relaxed {settle:g} turns at M = "
                               f"{m:.5g} does not reach a steady state ({exc})") from None


def hopf_cycle(config, frame, whirl: SteadyState, mode: np.ndarray, direction: str,
               turns: float = 40.0, window: float = 10.0, kick: float = 0.03) -> Cycle:
    """The whirl at ``whirl.machin`` kicked by ``kick`` L along ``mode`` (a real vector over
    the unknowns, largest bead displacement 1) and run ``turns`` turns in the turning frame:
    the free end's range and the mean distance from the whirl over the last ``window``."""
    from flagwrap.params import Phase
    from flagwrap.system.rotating import rotation

    cfg = frame_config(config, whirl.machin, (Phase(direction, turns),))
    cfg = cfg.replace(numerics=dataclasses.replace(cfg.numerics, save_every=0.05))
    z0 = retract(frame, whirl.z, kick * mode)
    tr = _run(cfg, frame.full(z0), whirl.base)
    A = tr.arrays()
    t = A["t"]
    last = t >= t[-1] - 2 * math.pi * window
    xw, _, _ = frame.system.unpack(frame.full(whirl.z))
    tips, dist = [], []
    for k in np.flatnonzero(last):
        xr = A["x"][k] @ rotation(frame.axis, -A["phi"][k]).T
        tips.append(xr[-1, 2])
        dist.append(float(np.max(np.linalg.norm(xr - xw, axis=1))))
    amp = float(np.mean(dist))
    return Cycle(whirl.machin, float(min(tips)), float(max(tips)), amp, amp > 0.2,
                 float(t[-1] / (2 * math.pi)))


def check_diagram_options(m_far=None, m_lo=None, m_hi=None, settle=20.0, factor=1.06,
                          cycles=(), option=lambda name: name) -> None:
    """Ranges of :func:`bifurcation_diagram`'s options, before any work (one-line errors)."""

    def number(name, v, lo, hi):
        if v is None:
            return
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) \
                or not lo < v <= hi:
            raise UserInputError(f"{option(name)} must be in ({lo:g}, {hi:g}], got {v!r}")

    number("m_far", m_far, 0.0, 1e7)
    number("m_lo", m_lo, 0.0, 1e7)
    number("m_hi", m_hi, 0.0, 1e8)
    number("settle", settle, 1.0, 1000.0)
    number("factor", factor, 1.001, 2.0)
    for c in cycles:
        number("cycles", c, 1.0, 2.0)
    if m_lo is not None and m_hi is not None and not m_lo < m_hi:
        raise UserInputError(f"{option('m_lo')} must be below {option('m_hi')}, got {m_lo:g} "
                             f">= {m_hi:g}")


def bifurcation_diagram(config, direction: str = "cw", m_far: float | None = None,
                        m_lo: float | None = None, m_hi: float | None = None,
                        settle: float = 20.0, factor: float = 1.06, jump: float = 0.1,
                        cycles=(1.02, 1.05), far_from=None, m_start: float = 10.0,
                        on_progress=None) -> Diagram:
    """The whirl (Hopf), the far branch (fold) and the Hopf cycle of ``config``'s helix.

    ``m_far``: where the far state is looked for (default: 1.07, 1.25 and 1.5 ``M_Hopf`` in
    turn, :data:`FAR_LADDER`, until one reversal ends at rest away from the whirl); ``far_from``: a
    run file whose last frame starts it instead. The far branch is followed down to ``m_lo``
    (default 0.3 ``M_Hopf``) and up to ``m_hi`` (default 1.5 ``M_Hopf``) by steps of
    ``factor`` in ``M``, each a relaxation of ``settle`` turns; ``jump`` [L]: a relaxed state
    farther than this from the previous one has left the branch. The steps along the branch
    relax ``max(5, settle / 2)`` turns each (they start next to the new state). ``cycles``:
    ``M/M_Hopf`` of the time-domain Hopf cycles (empty: none). ``on_progress(str)``: a line
    per stage.
    Raises :class:`UserInputError` for a system the turning frame does not fit (before any
    work) and :class:`FarStateNotFound` when no far state is found (the diagram so far in
    its ``diagram`` attribute)."""
    from flagwrap.stability.spectrum import mode_vector, spectrum
    from flagwrap.stability.threshold import DIRECTIONS, critical_from_config, speed_driven

    check_diagram_options(m_far, m_lo, m_hi, settle, factor, cycles)
    if direction not in DIRECTIONS:
        raise UserInputError(f"direction must be 'cw' or 'ccw', got {direction!r}")
    if config.body.free:
        raise UserInputError("flagwrap stability --diagram: a free-swimming cell's far states "
                             "are not followed (only a held cell's or the rig's): set "
                             "body.motion = \"fixed\"")
    last = read_far_from(config, far_from) if far_from is not None else None
    if last is not None and ((m_lo is not None and last["machin"] < m_lo)
                             or (m_hi is not None and last["machin"] > m_hi)):
        raise UserInputError(f"--far-from {far_from}: its M = {last['machin']:.5g} lies outside "
                             f"the diagram's range [{m_lo or 0:.5g}, {m_hi or math.inf:.5g}] "
                             f"(--m-lo, --m-hi)")
    if config.body.no_slip:
        raise UserInputError("flagwrap stability --far: a no-slip body's far branch is not "
                             "followed (its blob shell cannot be stepped in the turning frame, "
                             "where the far state is relaxed): use body.surface = \"transparent\" for the "
                             "diagram, or --far-from a lab-frame run for the start only")
    t0 = time.perf_counter()
    say = on_progress or (lambda line: None)
    # a step along the branch starts next to the new state: half the search's turns do
    step_turns = max(5.0, settle / 2)
    config = speed_driven(config)
    m_guess = 30.0 * config.machin_critical_scaling if m_hi is None else m_hi
    hopf = critical_from_config(config, direction, m_start=min(m_start, m_guess / 2),
                                m_max=max(m_guess, 2 * m_start))
    frame = hopf.frame
    d = Diagram(direction, hopf, tip_z0=float(frame.system.x0[-1, 2]))
    if not hopf.converged:
        d.message = f"the whirl: {hopf.message}"
        d.wall_time = time.perf_counter() - t0
        raise _not_found(d, f"no threshold of the whirl found ({hopf.message})")
    mc = hopf.machin_c
    say(f"whirl: {hopf.crossing} at M = {mc:.5g} ({len(hopf.branch)} states, "
        f"{time.perf_counter() - t0:.1f} s)")
    m_lo = 0.3 * mc if m_lo is None else float(m_lo)
    m_hi = 1.5 * mc if m_hi is None else float(m_hi)
    # where the reversal is tried: the given M, or a ladder above the threshold (just above
    # it a slowly growing whirl, e.g. a Hopf at Omega ~ omega, may not leave within the
    # turns; higher up the kick is harder), within the diagram
    ladder = ([float(m_far)] if m_far is not None else
              [r * mc for r in FAR_LADDER if r * mc <= m_hi] or [m_hi])
    m_far = ladder[0]
    if not m_lo < m_far <= m_hi:
        raise UserInputError(f"the far state's M ({m_far:.5g}) must lie in the diagram's range "
                             f"({m_lo:.5g}, {m_hi:.5g}]")

    # the whirl from the top of the Hopf bracket up to m_hi (unstable there, for the diagram)
    d.whirl = [ArcPoint(None, p.machin, math.nan, p.leading, p.real_leading, p.tip_z)
               for p in hopf.branch]
    whirl_at = {}
    if hopf.state is not None and hopf.crossing != "fold":
        cur = hopf.state
        whirl_at[cur.machin] = cur
        try:
            for st in march(frame, cur, m_hi, factor=1.1):
                d.whirl.append(arc_point(frame, st))
                whirl_at[st.machin] = st
        except NewtonFailure:
            pass
    d.whirl.sort(key=lambda p: p.machin)

    def whirl_near(m):
        """The whirl at ``m`` (continued afresh below the Hopf bracket), None if lost."""
        from flagwrap.stability.steady import branch

        if m in whirl_at:
            return whirl_at[m]
        try:
            whirl_at[m] = branch(frame, [m], m_start=min(m_start, m / 2))[m]
        except NewtonFailure:
            return None
        return whirl_at[m]

    # 1. a far state
    if far_from is not None:
        start = far_state_from_run(config, frame, far_from, last, direction, settle,
                                   (m_lo, m_hi))
        d.far_source = f"the last frame of {far_from}"
    else:
        tried = []
        for m_far in ladder:
            try:
                start = far_state_from_reversal(config, frame, m_far, direction, settle,
                                                whirl_near(m_far), m_start)
                break
            except FarStateNotFound as exc:
                tried.append(str(exc))
                say(f"no far state: {exc}")
        else:
            d.wall_time = time.perf_counter() - t0
            raise _not_found(d, "; ".join(tried)) from None
        other = "CCW" if direction == "cw" else "CW"
        d.far_source = (f"the reversal from the steady {other} whirl at M = {m_far:.5g} "
                        f"({settle:g} {direction.upper()} turns)")
    d.far.append(arc_point(frame, start))
    say(f"far state at M = {start.machin:.5g} from {d.far_source}: free end "
        f"{start.info.x[-1, 2] - d.tip_z0:+.3f} L from rest, leading eigenvalue "
        f"{d.far[0].leading.real:+.3g} ({time.perf_counter() - t0:.1f} s)")

    # 2. down and up by relaxation
    def step_to(cur, m):
        """The stable far state at ``m`` relaxed from ``cur``, as an ArcPoint; raises
        NewtonFailure where the relaxation left the branch (it moved by more than ``jump``,
        or Newton polished it onto an unstable state: a short relaxation near a fold can end
        next to the saddle)."""
        nxt = relax(config, frame, cur.z, cur.base, m, step_turns, direction)
        if distance(frame, nxt.z, cur.z) > jump:
            raise NewtonFailure("jumped", nxt)
        pt = arc_point(frame, nxt)
        if not pt.leading.real < 0:
            raise NewtonFailure("unstable", nxt)
        return pt

    def follow(cur, step):
        out = []
        while True:
            m = cur.machin * step
            if (step < 1 and m < m_lo) or (step > 1 and m > m_hi):
                return out, None
            try:
                pt = step_to(cur, m)
            except NewtonFailure:
                return out, (cur, m)
            out.append(pt)
            cur = pt.state

    down, lost = follow(start, 1.0 / factor)
    d.far += down
    if lost is not None:
        # narrow the loss to a ratio 1.003 before the arclength: fewer arc steps, same fold
        good, m_bad = lost
        while good.machin / m_bad > 1.003:
            m = math.sqrt(good.machin * m_bad)
            try:
                pt = step_to(good, m)
                good = pt.state
                d.far.append(pt)
            except NewtonFailure:
                m_bad = m
        d.far_lost_below = m_bad
        say(f"far branch followed down to M = {good.machin:.5g}; lost at {m_bad:.5g} "
            f"({time.perf_counter() - t0:.1f} s)")
        arc = arclength(frame, good, -1, ds=0.005, ds_max=0.05, max_points=60,
                        m_min=m_lo, m_max=m_hi)
        d.saddle = arc.points[1:]
        if arc.fold is not None:
            d.machin_fold = arc.fold_machin
            before = arc.points[arc.fold - 1].leading_real
            after = arc.points[arc.fold].leading_real
            k = arc.fold
            # the first point on the far side with the crossing eigenvalue positive
            while k < len(arc.points) - 1 and not after > 0:
                k += 1
                after = arc.points[k].leading_real
            d.fold_eigenvalues = (before, after)
            say(f"fold at M_f = {d.machin_fold:.5g} (leading real eigenvalue {before:+.3g} "
                f"before, {after:+.3g} past it; {time.perf_counter() - t0:.1f} s)")
        else:
            d.message = (f"the far branch is lost below M = {good.machin:.5g} but the arclength "
                         f"continuation found no smooth turn ({arc.message}): a loss by a "
                         f"contact event, bracketed by relaxation [{m_bad:.5g}, "
                         f"{good.machin:.5g}]")
    else:
        d.message = f"the far branch persists down to M = {m_lo:.5g} (lower --m-lo)"
    up, lost_up = follow(start, factor)
    d.far += up
    if lost_up is not None:
        note = (f"the far branch is left above M = {lost_up[0].machin:.5g} (relaxation at "
                f"{lost_up[1]:.5g} moves away from it)")
        d.message = f"{d.message}; {note}" if d.message else note
    d.far.sort(key=lambda p: p.machin)

    # 3. the Hopf cycle from the time domain
    if hopf.crossing == "hopf" and hopf.state is not None:
        sp = spectrum(frame, hopf.state, vectors=True)
        mode = mode_vector(frame, sp.vectors[:, 0]).real
        for r in cycles:
            m = r * mc
            try:
                w = newton(frame, m, hopf.state.z, hopf.state.base)
            except NewtonFailure:
                continue
            c = hopf_cycle(config, frame, w, mode, direction)
            d.cycles.append(c)
            say(f"Hopf cycle at M = {m:.5g} ({r:g} M_Hopf): distance from the whirl "
                f"{c.amplitude:.3f} L{' (left for the far state)' if c.far else ''} "
                f"({time.perf_counter() - t0:.1f} s)")
    d.wall_time = time.perf_counter() - t0
    return d


def _not_found(diagram, message):
    exc = FarStateNotFound(message)
    exc.diagram = diagram
    return exc

