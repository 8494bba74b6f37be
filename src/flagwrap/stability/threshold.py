"""The critical Machin number from linear stability: where the steady whirling state of one
motor direction first becomes unstable.

The steady state is followed in ``M`` from a small value, where it is the rest shape barely
bent, by Newton continuation (:mod:`flagwrap.stability.steady`: secant predictor in ``log M``,
the step halved where Newton fails). At every point the leading eigenvalue of the
turning-frame Jacobian is computed (:mod:`flagwrap.stability.spectrum`). Once its real part
changes sign, the interval is bisected in ``log M`` to ``rtol``, and ``M_c`` is the root of
the real part's linear interpolation across the last interval.

The crossing is a **Hopf** bifurcation in the turning frame when the eigenvalue crossing zero
is a complex pair. Its imaginary part ``Omega`` is the frequency at which the critical mode
oscillates in that frame, in units of the motor speed; a mode with azimuthal wavenumber ``m``
appears in the lab at ``m omega +- Omega``. The crossing is **steady** (a real eigenvalue) when
the pair is real. That means a pitchfork or a fold of the branch, with a new steadily turning
shape. If the branch cannot be continued (Newton fails at every step down to a factor
1.001), the result says where it ended: that is a fold of the branch, or a turn too sharp to
follow.

This is not the time-domain criterion of :mod:`flagwrap.analysis.critical` (the free end
rising 0.15 L within ``K`` CW turns after ``K'`` CCW turns). That one needs a finite
perturbation and a finite time. docs/stability.md compares the two.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from flagwrap.errors import UserInputError
from flagwrap.stability.spectrum import spectrum
from flagwrap.stability.steady import BranchLost, NewtonFailure, extrapolate, march, newton, start_state

DIRECTIONS = {"ccw": 1.0, "cw": -1.0}


@dataclass
class BranchPoint:
    """One steady state on the branch: ``M``, its two leading eigenvalues (units of omega),
    the free end's axial position ``tip_z`` [L] (rest: ``tip_z0``), the Newton residual."""

    machin: float
    leading: complex
    second: complex
    tip_z: float
    residual: float
    iterations: int
    real_leading: float = math.nan  # the largest real eigenvalue (a fold's signature)

    def as_dict(self) -> dict:
        return {"machin": self.machin, "leading_re": self.leading.real,
                "leading_im": abs(self.leading.imag), "second_re": self.second.real,
                "second_im": abs(self.second.imag), "tip_z": self.tip_z,
                "residual": self.residual, "iterations": self.iterations,
                "real_leading": self.real_leading}


@dataclass
class StabilityResult:
    """The outcome of :func:`find_critical` (core units unless named SI)."""

    direction: str
    converged: bool
    message: str
    machin_c: float = math.nan
    bracket: tuple = (math.nan, math.nan)
    crossing: str = ""  # "hopf", "steady" (a real eigenvalue crosses) or "fold"
    eigenvalue: complex = complex(math.nan, math.nan)  # at the upper end of the bracket
    mode_frequency: float = math.nan  # |Im| of the critical pair / omega (turning frame)
    omega_c: float = math.nan  # SI [rad/s]
    frequency_c: float = math.nan  # SI [Hz]
    tip_z0: float = math.nan
    branch: list = field(default_factory=list)
    state: object = field(default=None, repr=False)  # steady state at the top of the bracket
    frame: object = field(default=None, repr=False)  # the RotatingFrame it was computed in
    wall_time: float = 0.0
    motor: dict | None = None  # a torque motor's verdict (motor_verdict), else None
    #: d Re(lambda) / d eps at M_c, eps = M/M_c - 1 (units of omega): how fast the critical
    #: mode grows just above the threshold (a crossing by an eigenvalue; nan at a fold)
    growth_slope: float = math.nan

    def summary(self) -> dict:
        return {
            "direction": self.direction, "converged": self.converged, "message": self.message,
            "machin_c": self.machin_c, "bracket": list(self.bracket), "crossing": self.crossing,
            "eigenvalue_re": self.eigenvalue.real, "eigenvalue_im": abs(self.eigenvalue.imag),
            "mode_frequency": self.mode_frequency, "omega_c": self.omega_c,
            "frequency_c": self.frequency_c,
            "mode_frequency_si": self.mode_frequency * self.omega_c,
            "tip_z0": self.tip_z0, "wall_time": self.wall_time,
            "branch": [p.as_dict() for p in self.branch], "motor": self.motor,
            "growth_slope": self.growth_slope,
        }


def _point(frame, state):
    sp = spectrum(frame, state)
    second = sp.values[1]
    if sp.values[0].imag != 0.0 and len(sp.values) > 2:  # skip the conjugate partner
        second = sp.values[2]
    real = sp.values[sp.values.imag == 0.0]
    return BranchPoint(state.machin, sp.leading, complex(second), float(state.info.x[-1, 2]),
                       state.residual, state.iterations,
                       float(real[0].real) if real.size else math.nan)


def find_critical(frame, m_start: float = 10.0, m_max: float = 1e4, factor: float = 1.25,
                  rtol: float = 1e-3, on_point=None, omega_si: float | None = None,
                  machin_si: float | None = None) -> StabilityResult:
    """Continue the steady state of ``frame`` (a :class:`~flagwrap.system.rotating.RotatingFrame`)
    from ``m_start`` up to ``m_max``; return the first loss of stability.

    ``on_point(BranchPoint)`` is called for every state computed (a progress display).
    ``omega_si`` / ``machin_si``: the config's motor speed [rad/s] and its ``M``, to report
    ``omega_c = omega_si M_c / machin_si``.
    """
    import time

    t0 = time.perf_counter()
    direction = "ccw" if frame.omega > 0 else "cw"
    res = StabilityResult(direction, False, "", frame=frame)
    res.tip_z0 = float(frame.system.x0[-1, 2])

    def done():
        if res.converged and omega_si is not None and machin_si:
            res.omega_c = abs(omega_si) * res.machin_c / machin_si
            res.frequency_c = res.omega_c / (2 * math.pi)
        res.wall_time = time.perf_counter() - t0
        return res

    def record(state):
        p = _point(frame, state)
        res.branch.append(p)
        if on_point is not None:
            on_point(p)
        return p

    # the first state: Newton from the rest shape, at a smaller M or by switching gravity on
    # in steps if it must
    try:
        cur = start_state(frame, m_start, halvings=7)
    except NewtonFailure:
        res.message = (f"no steady state found from the rest shape at M = {m_start:g} down to "
                       f"{m_start / 2**7:g} (Newton did not converge"
                       + (", also with gravity switched on in steps" if frame.system.gravity.any()
                          else "") + ")")
        return done()
    p = record(cur)
    if p.leading.real >= 0.0:
        res.message = (f"the steady state is already unstable at M = {cur.machin:.4g} (leading "
                       f"eigenvalue {p.leading.real:+.3g} {abs(p.leading.imag):+.3g}i): "
                       f"lower --m-start")
        return done()
    prev_p = None
    try:
        for nxt in march(frame, cur, m_max, factor):
            pn = record(nxt)
            if pn.leading.real >= 0.0:
                _refine(frame, res, cur, p, nxt, pn, rtol, record)
                return done()
            cur, prev_p, p = nxt, p, pn
    except BranchLost as lost:
        if _fold(res, prev_p, p, cur, lost.m_failed):
            return done()
        res.message = (f"the steady branch could not be continued beyond M = {cur.machin:.6g} "
                       f"(a sharp turn, or a fold without a real eigenvalue going to zero), "
                       f"stable up to there")
        res.bracket = (cur.machin, math.nan)
        return done()
    res.message = f"stable up to M = {m_max:g} (no crossing in the range scanned: raise --m-max)"
    res.bracket = (cur.machin, math.nan)
    return done()


def _refine(frame, res, lo, plo, hi, phi, rtol, record) -> None:
    while hi.machin / lo.machin - 1.0 > rtol:
        mid = math.sqrt(lo.machin * hi.machin)
        try:
            st = newton(frame, mid, extrapolate(frame, hi, lo, mid), lo.base)
        except NewtonFailure:
            try:
                st = newton(frame, mid, hi.z, hi.base)
            except NewtonFailure:
                break
        pm = record(st)
        if pm.leading.real >= 0.0:
            hi, phi = st, pm
        else:
            lo, plo = st, pm
    a, b = plo.leading.real, phi.leading.real
    # the root of the real part's linear interpolation in log M across the last interval
    w = a / (a - b) if b != a else 0.5
    res.machin_c = math.exp((1 - w) * math.log(lo.machin) + w * math.log(hi.machin))
    res.bracket = (lo.machin, hi.machin)
    res.eigenvalue = phi.leading
    if b != a:  # d Re / d ln M across the bracket, = d Re / d eps at M_c
        res.growth_slope = (b - a) / math.log(hi.machin / lo.machin)
    res.crossing = "steady" if phi.leading.imag == 0.0 else "hopf"
    res.mode_frequency = abs(phi.leading.imag)
    res.state = hi
    res.converged = True
    res.message = "converged"


def _fold(res, pa, pb, state, m_failed) -> bool:
    """A fold (saddle-node) of the branch: Newton fails just beyond ``pb`` while the leading
    eigenvalue is real, negative and shrinking towards zero. Near a fold it goes as
    ``sqrt(M_f - M)``, so ``lambda^2`` is linear in ``M``. Its zero from the last two points
    is ``M_f``, the threshold: beyond it this steady state does not exist. Fills ``res``;
    False when the last points do not look like a fold."""
    if pa is None:
        return False
    la, lb = pa.real_leading, pb.real_leading
    if not (la < lb < 0.0):
        return False
    slope = (lb**2 - la**2) / (pb.machin - pa.machin)  # < 0
    m_f = pb.machin - lb**2 / slope
    if not pb.machin <= m_f <= 1.1 * m_failed:
        return False
    res.machin_c = m_f
    res.bracket = (pb.machin, max(m_f, m_failed))
    res.crossing = "fold"
    res.eigenvalue = complex(lb, 0.0)
    res.mode_frequency = 0.0
    res.state = state
    res.converged = True
    res.message = (f"the steady branch folds: a real eigenvalue goes to zero "
                   f"({la:+.3g} at M = {pa.machin:.5g}, {lb:+.3g} at {pb.machin:.5g}) and Newton "
                   f"finds no steady state beyond; M_c = M_fold extrapolated by the square-root law")
    return True


#: the default top of the continuation, in units of the paper's scaling line 0.06 (R/L)^-3
M_MAX_LINES = 20.0


def resolve_m_max(config, m_start: float, m_max: float | None) -> float:
    """``m_max``, or :data:`M_MAX_LINES` x the config's scaling line; refused (one line) unless
    above ``m_start``."""
    from flagwrap.errors import UserInputError

    m = M_MAX_LINES * config.machin_critical_scaling if m_max is None else float(m_max)
    if not m > m_start:
        raise UserInputError(f"--m-max (m_max) must be above --m-start ({m_start:g}), got "
                             f"{m:g}" + ("" if m_max is not None else
                                         f" (the default, {M_MAX_LINES:g}x the scaling line)"))
    return m


def refuse_polymorph(config) -> None:
    """A one-line :class:`UserInputError` for a polymorphic filament linear stability does
    not take: several flagella (the turning frame needs one on the motor axis)."""
    if config.polymorph.enabled and len(config.flagella) > 1:
        raise UserInputError(
            "polymorph.enabled = true with several [[flagellum]] tables is not available to "
            "flagwrap stability (its turning frame needs one flagellum on the motor axis); "
            "run it in the time domain (flagwrap run)")


def refuse_tube(config) -> None:
    """A one-line :class:`UserInputError` for a ``[[tube]]`` the turning frame cannot hold:
    one not coaxial with the motor axis (no steady whirl to linearise), or around a free cell
    (it swims along the tube: no steady state). A coaxial tube around the rig or a held cell
    is linearised as a held body's blob shell is: its blobs held at one angle in the turning
    frame (:class:`~flagwrap.system.rotating.RotatingFrame`, ``blob_body``)."""
    if not config.tubes:
        return
    from flagwrap.system.parts import config_tube

    if config.body.free:
        raise UserInputError(
            "flagwrap stability: a free cell in a [[tube]] has no steady whirl (it swims "
            "along the tube); run it in the time domain (flagwrap run)")
    if not config_tube(config).about_z:
        raise UserInputError(
            "flagwrap stability: tube[0] must be coaxial with the motor axis (tube.axis along "
            "z, tube.center on it) for a steady whirl; run it in the time domain (flagwrap run)")


def make_frame(config, omega: float):
    """The turning frame of ``config``'s system at ``omega``: a free swimmer's
    (:class:`~flagwrap.system.swimmer.SwimmerFrame`) or the rig's
    (:class:`~flagwrap.system.rotating.RotatingFrame`; a fixed no-slip body's blob shell held
    at one angle, ``blob_body``); for a polymorphic filament either with its order
    parameters among the unknowns (:class:`~flagwrap.system.polymorph.PolymorphFrame`)."""
    refuse_polymorph(config)
    refuse_tube(config)
    if config.body.free:
        if config.walls:
            raise UserInputError(
                "flagwrap stability: a free cell beside a [[wall]] has no steady whirl (it moves "
                "against the wall); run it in the time domain (flagwrap run)")
        from flagwrap.system.swimmer import SwimmerFrame, make_swimmer

        if config.polymorph.enabled:
            from flagwrap.system.polymorph import PolymorphFrame, PolymorphSystem

            return PolymorphFrame(PolymorphSystem(make_swimmer(config)), omega)
        return SwimmerFrame(make_swimmer(config), omega)
    from flagwrap.system.rod_system import RodSystem
    from flagwrap.system.rotating import RotatingFrame

    if config.polymorph.enabled:  # the order parameters among the unknowns
        from flagwrap.system.polymorph import PolymorphFrame, PolymorphSystem

        return PolymorphFrame(PolymorphSystem(RodSystem(config)), omega,
                              blob_body=config.body.no_slip or bool(config.tubes))
    blobs = config.body.no_slip or bool(config.tubes)  # a held shell of blobs either way
    return RotatingFrame(RodSystem(config), omega, blob_body=blobs)


def check_continuation_options(m_start, m_max, rtol, factor, option=lambda name: name) -> None:
    """The ranges of the continuation's options (:func:`critical_from_config`), before any
    work: one-line :class:`~flagwrap.errors.UserInputError` s naming the option as
    ``option(name)`` (the CLI passes its flag names, the API keeps the keywords)."""
    from flagwrap.errors import UserInputError

    def number(name, v, lo, hi, lo_open=True):
        if v is None:
            return
        if (isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v)
                or (v <= lo if lo_open else v < lo) or v > hi):
            raise UserInputError(f"{option(name)} must be in {'(' if lo_open else '['}{lo:g}, "
                                 f"{hi:g}], got {v!r}")

    number("m_start", m_start, 0.0, 1e7)
    number("m_max", m_max, 0.0, 1e8)
    if m_max is not None and not m_max > m_start:
        raise UserInputError(f"{option('m_max')} must be above {option('m_start')} "
                             f"({m_start:g}), got {m_max:g}")
    number("rtol", rtol, 0.0, 0.5)
    number("factor", factor, 1.001, 4.0, lo_open=False)


def critical_from_config(config, direction: str = "cw", m_start: float = 10.0, m_max=None,
                         on_start=None, **kw) -> StabilityResult:
    """:func:`find_critical` for a config: its system, turning at the reference speed in
    ``direction`` ("cw" or "ccw"), from ``m_start`` to ``m_max`` (:func:`resolve_m_max`).
    Refuses a bad range or a system the turning frame does not fit before any work.

    A torque motor (``motor.kind`` "torque" or "torque-speed") is replaced by a speed motor
    at its reference frequency for the threshold, and the result gets ``res.motor``
    (:func:`motor_verdict`): whether that motor can drive the whirl past it. ``on_start(m_max)``
    is called once the system is built and accepted (a progress display's first line)."""
    drive = config.motor if config.motor.kind != "speed" else None
    config = speed_driven(config)
    m_max = resolve_m_max(config, m_start, m_max)
    frame = make_frame(config, DIRECTIONS[direction])
    if on_start is not None:  # the system is built and fits the turning frame
        on_start(m_max)
    res = find_critical(frame, m_start=m_start, m_max=m_max, omega_si=config.omega,
                        machin_si=config.machin, **kw)
    if drive is not None:
        res.motor = motor_verdict(drive, config, res)
    return res


def onset_prefactor(growth_slope: float, seed: float = 1e-3, rise: float = 0.15) -> float:
    """``C`` of the waiting time ``t_c/T ~ C/eps`` just above the threshold, from the linear
    growth alone: the critical mode grows by ``exp(2 pi Re(lambda))`` a motor turn
    (``lambda`` in units of omega) and ``Re(lambda) ~ s eps`` (``s`` = ``growth_slope``), so a
    seed of amplitude ``seed`` reaches ``rise`` (both in L, the paper's rise criterion 0.15 L)
    after ``ln(rise/seed) / (2 pi s eps)`` turns. An upper bound on how fast the paper's
    criterion can fire: a supercritical Hopf cycle that saturates below ``rise`` never does."""
    if not (growth_slope > 0 and 0 < seed < rise):
        return math.nan
    return math.log(rise / seed) / (2 * math.pi * growth_slope)


def state_torque(frame, state) -> float:
    """|torque| the motor supplies to a steady state of ``frame`` (core units ``A/L``): the
    clamp's generalized force ``dE/dphi`` plus the clamped bond's rotational drag at the
    state's M (:meth:`~flagwrap.system.rod_system.RodSystem.motor_torque`)."""
    s = frame.system
    # the system's own torque balance; its drag term M zeta omega taken at the state's M
    return abs(s.motor_torque(state.info, 0.0, frame.omega * state.machin / s.machin))


def whirl_torque(res) -> float:
    """|torque| the motor supplies to the steady whirl at the top of ``res``'s bracket (core
    units ``A/L``; :func:`state_torque`)."""
    if res.state is None:
        return math.nan
    return state_torque(res.frame, res.state)


def speed_driven(config):
    """``config`` with a torque or torque-speed motor replaced by a speed motor at its
    reference frequency (a steady state is defined at a given speed); unchanged otherwise."""
    import dataclasses

    if config.motor.kind == "speed":
        return config
    return config.replace(motor=dataclasses.replace(config.motor, kind="speed",
                                                    stall_torque=None, zero_load_speed=None))


def motor_verdict(motor, config, res) -> dict:
    """Can the torque motor ``motor`` (a :class:`~flagwrap.params.Motor` of kind "torque" or
    "torque-speed") turn this filament past its threshold?

    The steady whirl at the threshold needs the torque ``T_c`` (:func:`whirl_torque`) at the
    rate ``f_c``, and its load grows with the rate. A motor whose torque at ``f_c`` exceeds
    ``T_c`` settles beyond ``f_c`` and buckles the filament; one below it settles short of it.
    A torque-speed line ``T_s (1 - f/f_0)`` gives ``T_s (1 - f_c/f_0)`` at ``f_c``, so it
    needs ``T_s > T_c / (1 - f_c / f_0)``; a constant torque needs ``T > T_c``. ``T_c`` is the
    same at every viscosity (it is ``A/L`` times a function of ``M``), so more viscous fluid
    lowers ``f_c`` and the stall torque needed, towards ``T_c``. SI: N m and Hz."""
    out = {"kind": motor.kind, "stall_torque": motor.stall_torque,
           "zero_load_speed": motor.zero_load_speed, "frequency_c": res.frequency_c}
    if not res.converged:
        return {**out, "buckles": None}
    fil = config.filament
    T_c = whirl_torque(res) * fil.bending_modulus / fil.length
    if motor.kind == "torque-speed":
        slack = 1.0 - res.frequency_c / motor.zero_load_speed
        available = motor.stall_torque * max(slack, 0.0)
        needed = T_c / slack if slack > 0 else math.inf
    else:
        available, needed = motor.stall_torque, T_c
    return {**out, "torque_c": T_c, "torque_available": available,
            "stall_torque_needed": needed, "buckles": bool(available > T_c)}
