"""Steadily whirling states: fixed points of the turning-frame equations, by Newton.

A helix driven at constant speed settles, below its threshold, into a shape that turns rigidly
with the motor. In the frame turning with the motor (:mod:`flagwrap.system.rotating`) that
shape is a fixed point ``f(z) = 0``. The motor angle is not an unknown there: the clamp
stands still.

Newton's method on ``f`` has one difficulty, the stiff bonds. A linear step in the positions
turns a bond by an angle ``d`` and lengthens it by ``~ b d^2 / 2``. Against the stretching
stiffness, ~1e3 times the bending one, that second-order strain is a large spurious force,
and plain Newton from the rest shape diverges above M ~ 30 (Fig. 4(a) helix). :func:`retract`
therefore maps each step back onto bond lengths that change only to first order: each new
bond vector is rescaled to ``|e| + t . de``, and the chain is rebuilt from the clamp. Newton
keeps its quadratic convergence, because the map differs from the linear step only at second
order. With this, Newton converges from the rest shape up to M ~ 100 and along a continuation
in ``M`` beyond.

The residual reaches a floor set by rounding. The stretching force ``k_s (l - l0)`` carries an
absolute error ``~ k_s eps |x|``, about 6e-9 in core units at the paper's ``k_s``, and the
mobility turns it into a velocity error ``~ 3e-8 / M``. Convergence is therefore judged by the
Newton step, with the residual reported beside it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np


@dataclass
class SteadyState:
    """A fixed point of the turning-frame equations at one ``machin``.

    Attributes
    ----------
    z : the unknowns (turning frame; positions of the free beads, twist angles of free bonds)
    base : reference frames of ``z`` (the chart of its Jacobian)
    machin : Machin number ``M``
    residual : max-norm of ``dz/dt`` at ``z`` [L omega, rad omega]
    step : max-norm of the last Newton step
    iterations : Newton iterations taken
    converged : the step fell below the tolerance
    info : the system's :class:`~flagwrap.system.rod_system.ForceInfo` at ``z``
    """

    z: np.ndarray
    base: object
    machin: float
    residual: float
    step: float
    iterations: int
    converged: bool
    info: object = field(default=None, repr=False)


def retract(frame, z: np.ndarray, dz: np.ndarray) -> np.ndarray:
    """``z + dz`` with each bond's length changed only to first order in ``dz`` (see the
    module docstring); the twist angles move linearly."""
    s = frame.system
    x, _, _ = s.unpack(frame.full(z))
    k = s.nc - 1  # the last prescribed bead: the chain is rebuilt from it
    xn = x.copy()
    xn[s.nc:] += dz[: frame.n3].reshape(-1, 3)
    e_old = x[k + 1:] - x[k:-1]
    e_new = xn[k + 1:] - xn[k:-1]
    lo = np.linalg.norm(e_old, axis=1)
    l1 = lo + np.einsum("ij,ij->i", e_old, e_new - e_old) / lo
    # a step of a bond's size is far outside the linear regime: keep the length positive
    # (Newton's max_step rejects such steps; a predictor may still make one)
    l1 = np.clip(l1, 0.5 * lo, 1.5 * lo)
    e_new *= (l1 / np.linalg.norm(e_new, axis=1))[:, None]
    out = z + dz
    out[: frame.n3] = (x[k] + np.cumsum(e_new, axis=0)).ravel()
    return out


class NewtonFailure(RuntimeError):
    """Newton did not converge; ``state`` holds the last iterate."""

    def __init__(self, message, state):
        super().__init__(message)
        self.state = state


def newton(frame, machin: float, z0: np.ndarray, base0, step_tol: float = 1e-10,
           max_iter: int = 12, max_step: float = 0.05) -> SteadyState:
    """The fixed point of ``frame`` at ``machin`` near ``z0`` (Newton with :func:`retract`).

    Converged when the largest position change of a step is below ``step_tol`` [L] and the
    largest twist change below ``10 step_tol`` (the integrators' weighting). A step moving a
    bead by more than ``max_step`` [L] means the start was outside Newton's basin: it raises
    :class:`NewtonFailure` (as does ``max_iter``), for the caller to take a smaller
    continuation step.
    """
    z = np.array(z0, float)
    base = base0
    n3 = frame.n3
    step = math.inf
    converged = False
    for it in range(1, max_iter + 1):
        f, info = frame.velocity(z, base, machin)
        base = info.frames  # the chart at z itself (a change of chart moves nothing)
        if not np.all(np.isfinite(f)):
            break
        J = frame.jacobian(z, base, machin, info)
        try:
            dz = np.linalg.solve(J, -f)
        except np.linalg.LinAlgError:
            break
        sx = float(np.max(np.abs(dz[:n3]))) if n3 else 0.0
        st = float(np.max(np.abs(dz[n3:]))) if dz.size > n3 else 0.0
        step = max(sx, st / 10.0)
        if not math.isfinite(step) or sx > max_step:
            break
        z = retract(frame, z, dz)
        if step < step_tol:
            converged = True
            break
    f, info = frame.velocity(z, base, machin)
    state = SteadyState(z, info.frames, float(machin), float(np.max(np.abs(f))), step,
                        it, converged, info)
    if converged:
        return state
    raise NewtonFailure(f"Newton did not converge at M = {machin:.6g} (last step {step:.2e} L "
                        f"after {it} iterations)", state)


def initial_guess(frame):
    """The rest shape in the turning frame: ``(z, base)`` (or the frame's own
    ``initial_state``)."""
    own = getattr(frame, "initial_state", None)  # a frame with its own start (the polymorph's)
    if own is not None:
        return own()
    s = frame.system
    return s.initial_y()[:frame.n].copy(), s.frames0.copy()


def extrapolate(frame, a: SteadyState, b: SteadyState, machin: float) -> np.ndarray:
    """Secant predictor in ``log M`` from two states on the branch."""
    r = math.log(machin / b.machin) / math.log(b.machin / a.machin)
    return retract(frame, b.z, r * (b.z - a.z))


class BranchLost(NewtonFailure):
    """The continuation could not step beyond ``state``; ``m_failed``: the last M tried;
    ``states``: the targets :func:`branch` reached before (empty from :func:`march`)."""

    def __init__(self, message, state, m_failed):
        super().__init__(message, state)
        self.m_failed = m_failed
        self.states = {}


def march(frame, cur: SteadyState, m_stop: float, factor: float = 1.25, prev=None):
    """Continue the branch from ``cur`` (``prev``: the state before it, for the secant
    predictor) up to ``m_stop``, yielding each new steady state. Steps are at most ``factor``
    in M. A step where Newton fails is retried with its factor square-rooted, and the factor
    grows back (squared, up to ``factor``) after a step of at most 5 iterations. Raises
    :class:`BranchLost` once the factor would fall below 1.001."""
    f = factor
    while cur.machin < m_stop * (1 - 1e-12):
        m_next = min(cur.machin * f, m_stop)
        guess = extrapolate(frame, prev, cur, m_next) if prev is not None else cur.z
        try:
            nxt = newton(frame, m_next, guess, cur.base)
        except NewtonFailure:
            f = math.sqrt(f)
            if f < 1.001:
                raise BranchLost(f"the steady branch could not be continued beyond M = "
                                 f"{cur.machin:.6g}", cur, m_next) from None
            continue
        prev, cur = cur, nxt
        yield nxt
        f = min(factor, f * f) if nxt.iterations <= 5 else f


def start_state(frame, machin: float, halvings: int = 8) -> SteadyState:
    """The first steady state of a branch: Newton from the rest shape at ``machin``, halving
    ``machin`` up to ``halvings`` times where it fails. Where it still fails and the system
    has gravity, the gravity is switched on in steps (a homotopy: 1/8, 2/8, ... of it, a step
    halved where Newton fails). A buoyant helix sags or lifts far from its rest shape, by an
    amount that does not shrink with M. Raises :class:`NewtonFailure`."""
    z, base = initial_guess(frame)
    m = float(machin)
    last = None
    for _ in range(halvings + 1):
        try:
            return newton(frame, m, z, base)
        except NewtonFailure as exc:
            last = exc
            m /= 2.0
    g = frame.system.gravity
    if not np.any(g):
        raise last
    g0 = g.copy()
    m = float(machin)
    try:
        done, step = 0.0, 0.125
        state = None
        while done < 1.0:
            nxt = min(1.0, done + step)
            g[:] = g0 * nxt
            try:
                state = newton(frame, m, z if state is None else state.z,
                               base if state is None else state.base)
            except NewtonFailure:
                step /= 2.0
                if step < 1e-3:
                    raise
                continue
            done = nxt
            step = min(0.25, 2.0 * step)
        return state
    finally:
        g[:] = g0


def branch(frame, machins, m_start: float = 10.0, factor: float = 1.25) -> dict:
    """Steady states at each of ``machins``, by continuation (:func:`march`) from the rest
    shape at ``m_start``. Returns ``{M: SteadyState}``. Where the branch is lost it raises
    :class:`BranchLost` and keeps what converged: the exception's ``states`` holds the
    targets reached before (``{M: SteadyState}``) and its ``state`` the last state."""
    targets = sorted(float(m) for m in machins)
    cur = start_state(frame, min(float(m_start), targets[0]))
    prev = None
    out = {}
    try:
        for target in targets:
            for nxt in march(frame, cur, target, factor, prev):
                prev, cur = cur, nxt
            out[target] = cur
    except BranchLost as exc:
        exc.states = out
        raise
    return out
