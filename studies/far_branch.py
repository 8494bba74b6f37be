"""Exploratory (issue 29, first probe; not part of the package yet): the far state of the
Fig. 4(a) helix as a steady branch of the turning frame, followed by pseudo-arclength.

    python studies/far_branch.py [--machin 660] [--points 40]

Reproduces: a turning-frame run at M (5 CCW + 30 CW turns) ends in the far state; Newton
from it; then the branch continued towards lower M. Measured on 2026-12-03 (M = 660): the
end state is a fixed point (residual 8.9e-11 before Newton, 5.7e-11 after 1 iteration),
free end 4.1e-4 L above the clamp, linearly stable (leading eigenvalue -0.629, real); five
or six beads rest just inside the body's contact range (distance 7.483e-3 L against the
cut-off 7.5e-3). Followed down, the leading eigenvalue stays at -0.59..-0.63 to M = 628
(where the leading real pair turns complex, -0.62 +- 0.05i) and jumps to +0.34 (real)
between M = 622.8 and 620.6, where one bead leaves the contact range (6 -> 5), with dp/ds
still negative (no fold); the corrector then stalls at M = 618.8. The jump is the states'
own, not the Jacobian's: at M = 624.9, 622.8 and 620.6 the frame's Jacobian agrees with
central differences of the velocity to 1e-10 (relative), and so do their leading
eigenvalues. The contact law's stiffness falls to zero over the last ~2e-5 L before the
cut-off (U ~ (d_c - d)^3 there, with the WCA stiffness k ~ 1e8 in core units), so a bead
leaving the contact range takes a large stiffness away within a few steps in M: a grazing
event, not a smooth fold, near M ~ 621 (the whirl's Hopf: 616.7). Open: how this fits the
time-domain far states down to M = 480 (other contact sets?), and what the branch does
past the event (issue 29).

Steady branches other than the whirl, followed through their folds (issue 29).

The whirl's branch is continued in ``M`` by :func:`flagwrap.stability.steady.march`, which
steps ``M`` and cannot pass a fold (a saddle-node, where the branch turns back in ``M``). A
far state (the folded or wrapped shape a run ends in after the reversal) is a fixed point of
the same turning-frame equations, on a branch that exists only above some ``M_f``: below it
the far state is gone and every run returns to the whirl. :func:`arclength` follows such a
branch by pseudo-arclength continuation (Keller 1977; Allgower & Georg, *Introduction to
Numerical Continuation Methods*, ch. 2) in ``(z, p)``, ``p = log M``:

    F(z, p) = 0,        tau . ((z, p) - (z_pred, p_pred)) = 0,

the second row fixing the step along the branch's tangent ``tau``, the null vector of
``[dF/dz, dF/dp]`` (oriented as the previous one). Each corrector step solves the bordered
system ``[[J, F_p], [tau_z^T, tau_p]]``; ``J`` is the frame's Jacobian
(:meth:`~flagwrap.system.rotating.RotatingFrame.jacobian`), ``F_p`` by central differences
in ``p``; the positions are updated through :func:`~flagwrap.stability.steady.retract`
(bond lengths to first order), as in Newton. A fold is where ``dp/ds`` changes sign: there
one real eigenvalue of ``J`` crosses zero, which :func:`arclength` records at every point
(the leading real eigenvalue). ``fold_machin`` places the fold by a parabola through the
three points around the turn.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from flagwrap.stability.steady import NewtonFailure, SteadyState, retract  # noqa: E402


@dataclass
class BranchPoint:
    """A point of a continued branch: its steady state, the tangent's ``dp/ds`` there and the
    largest real part among the eigenvalues (``leading``) and among the real ones
    (``leading_real``; ``nan`` if none is real)."""

    state: SteadyState = field(repr=False)
    machin: float
    dp_ds: float
    leading: complex
    leading_real: float
    height: float


@dataclass
class Branch:
    points: list
    fold_machin: float | None = None
    message: str = ""

    def machins(self) -> np.ndarray:
        return np.array([p.machin for p in self.points])


def _residual(frame, z, base, p):
    f, info = frame.velocity(z, base, math.exp(p))
    return f, info


def _f_p(frame, z, base, p, h: float = 1e-6) -> np.ndarray:
    fp, _ = frame.velocity(z, base, math.exp(p + h))
    fm, _ = frame.velocity(z, base, math.exp(p - h))
    return (fp - fm) / (2.0 * h)


def _tangent(J, Fp, prev) -> np.ndarray:
    """The unit null vector of ``[J, Fp]`` oriented along ``prev`` (n + 1,)."""
    n = J.shape[0]
    A = np.zeros((n + 1, n + 1))
    A[:n, :n] = J
    A[:n, n] = Fp
    A[n] = prev
    rhs = np.zeros(n + 1)
    rhs[n] = 1.0
    t = np.linalg.solve(A, rhs)
    return t / np.linalg.norm(t)


def _height(frame, z) -> float:
    x, _, _ = frame.system.unpack(frame.full(z))
    return float(x[-1, 2] - x[0, 2])


def _point(frame, state, dp_ds) -> BranchPoint:
    from flagwrap.stability.spectrum import spectrum

    w = spectrum(frame, state).values
    real = w[np.abs(w.imag) < 1e-9 * np.maximum(1.0, np.abs(w.real))].real
    return BranchPoint(state, state.machin, float(dp_ds), complex(w[0]),
                       float(real.max()) if real.size else math.nan, _height(frame, state.z))


def _correct(frame, z0, base, p0, tau, step_tol=1e-10, max_iter=10, max_step=0.05):
    """Newton on the bordered system from the predictor ``(z0, p0)``."""
    n3 = frame.n3
    z, p = np.array(z0, float), float(p0)
    for it in range(1, max_iter + 1):
        f, info = _residual(frame, z, base, p)
        base = info.frames
        if not np.all(np.isfinite(f)):
            break
        J = frame.jacobian(z, base, math.exp(p), info)
        n = J.shape[0]
        A = np.zeros((n + 1, n + 1))
        A[:n, :n] = J
        A[:n, n] = _f_p(frame, z, base, p)
        A[n] = tau
        r = np.concatenate([-f, [-(tau[:n] @ (z - z0) + tau[n] * (p - p0))]])
        try:
            d = np.linalg.solve(A, r)
        except np.linalg.LinAlgError:
            break
        sx = float(np.max(np.abs(d[:n3])))
        step = max(sx, float(np.max(np.abs(d[n3:n]))) / 10.0 if n > n3 else 0.0, abs(d[n]))
        if not math.isfinite(step) or sx > max_step:
            break
        z = retract(frame, z, d[:n])
        p += d[n]
        if step < step_tol:
            f, info = _residual(frame, z, base, p)
            return SteadyState(z, info.frames, math.exp(p), float(np.max(np.abs(f))), step,
                               it, True, info)
    raise NewtonFailure(f"the arclength corrector did not converge near M = {math.exp(p0):.6g}",
                        None)


def arclength(frame, start: SteadyState, direction: int = -1, ds: float = 0.02,
              ds_max: float = 0.2, ds_min: float = 1e-4, m_min: float = 1.0,
              m_max: float = 1e5, max_points: int = 200, past_fold: int = 3) -> Branch:
    """Follow the branch through ``start`` (a converged :class:`SteadyState`), first towards
    decreasing ``M`` (``direction = -1``) or increasing (``+1``), by pseudo-arclength steps
    of ``ds`` (in the Euclidean norm of ``(z, log M)``; halved where the corrector fails,
    grown 1.5x after an easy step, within ``[ds_min, ds_max]``). Stops ``past_fold`` points
    after the first fold, when ``M`` leaves ``[m_min, m_max]``, after ``max_points``, or when
    the step falls below ``ds_min`` (``message`` says which)."""
    n = start.z.size
    seed = np.zeros(n + 1)
    seed[n] = float(direction)
    f, info = _residual(frame, start.z, start.base, math.log(start.machin))
    J = frame.jacobian(start.z, info.frames, start.machin, info)
    tau = _tangent(J, _f_p(frame, start.z, info.frames, math.log(start.machin)), seed)
    cur = start
    points = [_point(frame, cur, tau[n])]
    after, fold, message = None, None, "max_points reached"
    while len(points) < max_points:
        p = math.log(cur.machin)
        z_pred = retract(frame, cur.z, ds * tau[:n])
        p_pred = p + ds * tau[n]
        try:
            nxt = _correct(frame, z_pred, cur.base, p_pred, tau)
        except NewtonFailure:
            ds /= 2.0
            if ds < ds_min:
                message = f"step below ds_min = {ds_min:g} at M = {cur.machin:.6g}"
                break
            continue
        f, info = _residual(frame, nxt.z, nxt.base, math.log(nxt.machin))
        J = frame.jacobian(nxt.z, info.frames, nxt.machin, info)
        new_tau = _tangent(J, _f_p(frame, nxt.z, info.frames, math.log(nxt.machin)), tau)
        pt = _point(frame, nxt, new_tau[n])
        points.append(pt)
        if fold is None and np.sign(new_tau[n]) != np.sign(tau[n]):
            fold = len(points) - 1
        tau, cur = new_tau, nxt
        if nxt.iterations <= 4:
            ds = min(ds_max, 1.5 * ds)
        if fold is not None and len(points) - 1 - fold >= past_fold:
            message = "past the fold"
            break
        if not m_min <= nxt.machin <= m_max:
            message = f"M = {nxt.machin:.6g} left [{m_min:g}, {m_max:g}]"
            break
    return Branch(points, _fold_machin(points, fold), message)


def _fold_machin(points, k) -> float | None:
    """``M`` at the turn: the vertex of the parabola ``log M (s)`` through the three points
    around the sign change of ``dp/ds`` (arclength ``s`` between points from their states)."""
    if k is None:
        return None
    i = max(1, min(k, len(points) - 2))
    trio = points[i - 1:i + 2]
    s = [0.0]
    for a, b in zip(trio[:-1], trio[1:]):
        s.append(s[-1] + math.hypot(float(np.linalg.norm(b.state.z - a.state.z)),
                                    math.log(b.machin / a.machin)))
    c = np.polyfit(s, [math.log(q.machin) for q in trio], 2)
    if c[0] == 0.0:
        return float(trio[1].machin)
    s0 = -c[1] / (2.0 * c[0])
    return float(math.exp(np.polyval(c, s0)))


def far_state(machin: float = 660.0, ccw: float = 5.0, cw: float = 30.0, path="far.ckpt.h5"):
    """The end state of a turning-frame run of the Fig. 4(a) helix at ``machin`` (``ccw``
    then ``cw`` turns) and its Newton-converged steady state: ``(frame, state)``."""
    import dataclasses

    from flagwrap.cases import get_case
    from flagwrap.io.checkpoint import read_checkpoint
    from flagwrap.params import Phase
    from flagwrap.simulation import Simulation, make_system
    from flagwrap.stability.steady import newton
    from flagwrap.stability.threshold import make_frame

    cfg = get_case("fig4a")
    cfg = cfg.replace(motor=dataclasses.replace(cfg.motor, machin=machin,
                                                protocol=(Phase("ccw", ccw), Phase("cw", cw))),
                      numerics=dataclasses.replace(cfg.numerics, frame="rotating"))
    # the loop keeps its last (y, chart) in a checkpoint at a step-budget stop: run once to
    # count the steps, then again stopped by that budget at the end
    n = Simulation(cfg, system=make_system(cfg)).run().n_steps
    cfg = cfg.replace(numerics=dataclasses.replace(cfg.numerics, max_steps=n))
    Simulation(cfg, system=make_system(cfg), checkpoint_path=path,
               checkpoint_every_seconds=1e9).run()
    ck = read_checkpoint(path)
    frame = make_frame(get_case("fig4a"), -1.0)
    return frame, newton(frame, machin, ck.y[:-1].copy(), ck.base())


def main(argv=None) -> int:
    import argparse

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--machin", type=float, default=660.0)
    ap.add_argument("--points", type=int, default=40)
    args = ap.parse_args(argv)
    frame, st = far_state(args.machin)
    print(f"far state at M = {st.machin:g}: residual {st.residual:.2e}, "
          f"free end {_height(frame, st.z):+.4f} L")
    br = arclength(frame, st, -1, ds=0.05, ds_max=0.3, max_points=args.points)
    for p in br.points:
        print(f"M {p.machin:9.2f}  dp/ds {p.dp_ds:+.3f}  leading {p.leading:.4f}  "
              f"leading real {p.leading_real:+.4f}  free end {p.height:+.4f} L")
    print(br.message, "fold at M =", br.fold_machin)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
