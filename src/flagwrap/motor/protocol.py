"""Motor protocols: piecewise-constant angular velocity against time.

Core units: time ``1/omega`` (reference speed), so a phase of ``n`` turns at ``speed`` s lasts
``2 pi n / s``. Sign convention: positive = counter-clockwise seen from the free end of the
filament = right-handed rotation about the outward filament axis ``-z``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

_SIGN = {"ccw": 1.0, "cw": -1.0, "stop": 0.0}


@dataclass(frozen=True)
class Segment:
    t0: float
    t1: float
    omega: float  # signed angular velocity (core units)
    label: str


class Schedule:
    """Callable ``omega(t)`` built from :class:`flagwrap.params.Phase` objects."""

    def __init__(self, phases):
        segs = []
        t = 0.0
        for p in phases:
            speed = p.speed if p.direction != "stop" else 1.0
            dur = 2.0 * math.pi * p.turns / speed
            segs.append(Segment(t, t + dur, _SIGN[p.direction] * (p.speed if p.direction != "stop" else 0.0), p.direction))
            t += dur
        self.segments = tuple(segs)
        self.t_end = t

    def __call__(self, t: float) -> float:
        for s in self.segments:
            if t < s.t1:
                return s.omega
        return self.segments[-1].omega

    def segment_index(self, t: float) -> int:
        for k, s in enumerate(self.segments):
            if t < s.t1:
                return k
        return len(self.segments) - 1

    def angle(self, t) -> np.ndarray:
        """Motor angle ``phi(t)`` (integral of omega)."""
        t = np.asarray(t, dtype=float)
        out = np.zeros_like(t)
        for s in self.segments:
            out += s.omega * np.clip(t - s.t0, 0.0, s.t1 - s.t0)
        return out

    def switch_times(self):
        """Start times of the phases after the first."""
        return [s.t0 for s in self.segments[1:]]


class MotorSchedules(Schedule):
    """Every motor's ``omega(t)`` when flagella have their own protocols
    (``[[flagellum]] protocol``): a :class:`Schedule` whose segments are the intervals
    between any motor's switch times, each with ``omega`` one value per motor, (n_motors,),
    and ``label`` the reference protocol's (``motor.protocol``: the run's length and the
    phases its summaries use). :func:`motor_schedule` builds one only where the protocols
    differ; a system of motors that share one keeps the scalar :class:`Schedule`."""

    def __init__(self, reference, protocols):
        ref = Schedule(reference)
        each = [Schedule(p) for p in protocols]
        cuts = sorted({0.0, ref.t_end, *(s.t1 for m in each for s in m.segments
                                          if s.t1 < ref.t_end)})
        segs = []
        for t0, t1 in zip(cuts[:-1], cuts[1:]):
            if t1 - t0 <= 1e-12 * ref.t_end:
                continue
            mid = 0.5 * (t0 + t1)
            segs.append(Segment(t0, t1, np.array([m(mid) for m in each]),
                                ref.segments[ref.segment_index(mid)].label))
        self.segments = tuple(segs)
        self.t_end = ref.t_end
        self.reference = ref

    def angle(self, t) -> np.ndarray:  # pragma: no cover - not meaningful for several
        raise NotImplementedError("MotorSchedules: each motor has its own angle")


def motor_schedule(config):
    """``config``'s motor schedule: one :class:`Schedule` when every motor follows
    ``motor.protocol``; :class:`MotorSchedules` when a ``[[flagellum]]`` has a protocol of its
    own."""
    ref = config.motor.protocol
    own = [f.protocol for f in config.flagella]
    if not any(p is not None and tuple(p) != tuple(ref) for p in own):
        return Schedule(ref)
    return MotorSchedules(ref, [ref if p is None else p for p in own])
