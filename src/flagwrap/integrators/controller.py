"""Step-size control as its own object (kept out of the steppers, as in diffrax's
``_step_size_controller``): the elementary (I) controller of Hairer, Norsett & Wanner,
Solving ODEs I, Sec. II.4."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class IController:
    """``h_next = h min(grow, max(shrink, safety err^(-1/(q+1))))`` for a scaled error ``err``
    of an embedded estimate of order ``q``; a step is accepted when ``err <= 1``; a step that
    failed outright (singular W, non-finite stage) is retried at ``shrink h``."""

    safety: float = 0.9
    grow: float = 4.0
    shrink: float = 0.2

    def accept(self, err: float) -> bool:
        return err <= 1.0

    def propose(self, h: float, err: float, estimate_order: int) -> float:
        fac = self.safety * (1.0 / max(err, 1e-10)) ** (1.0 / (estimate_order + 1))
        return h * min(self.grow, max(self.shrink, fac))

    def after_failure(self, h: float) -> float:
        return h * self.shrink
