"""Degree-of-freedom layout: named blocks of the state vector ``y`` and what depends on them.

Every consumer that needs to know where positions, twist angles or the motor angle live in
``y`` (error norms and weights, the unknown count of the resource estimate, packing) asks the
layout instead of assuming "positions first, then twists, the motor angle last". A block has a
``kind`` that sets how its error is measured:

* ``"position"``: bead coordinates [L], error held to ``tol``;
* ``"angle"``: twist angles [rad], error held to ``10 tol`` (a twist angle of 10 tol moves a
  bond's surface by 10 tol a, ~0.04 tol L at the paper's a/L: docs/numerics.md);
* ``"prescribed"``: driven coordinates (the motor angle), no error (weight ``inf``);
* ``"order"``: a polymorph order parameter in ``[-1, 1]`` (docs/polymorph.md), error held to
  ``tol`` (the wells are 2 apart).

Filaments with clamps: ``[x_free (3 n_b), theta_free (n_e), phi (one per motor)]``
(:meth:`DofLayout.clamped_filament`); a free body adds its pose.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

KINDS = ("position", "angle", "prescribed", "order")
#: error tolerance of each kind, in units of the integrator's ``tol``
TOL_FACTOR = {"position": 1.0, "angle": 10.0, "order": 1.0}


@dataclass(frozen=True)
class Block:
    """``size`` unknowns of one ``kind`` starting at ``start``."""

    name: str
    kind: str
    start: int
    size: int

    @property
    def slice(self) -> slice:
        return slice(self.start, self.start + self.size)


class DofLayout:
    """Blocks in order; ``layout["x"]`` is a block's slice, ``layout.size`` the unknown count."""

    def __init__(self, blocks):
        out, start = [], 0
        for name, kind, size in blocks:
            if kind not in KINDS:
                raise ValueError(f"DofLayout: block {name!r} has unknown kind {kind!r}")
            if size < 0:
                raise ValueError(f"DofLayout: block {name!r} has negative size {size}")
            out.append(Block(name, kind, start, int(size)))
            start += int(size)
        names = [b.name for b in out]
        if len(set(names)) != len(names):
            raise ValueError(f"DofLayout: duplicate block names in {names}")
        self.blocks = tuple(out)
        self.size = start
        self._by_name = {b.name: b for b in out}

    @classmethod
    def clamped_filament(cls, n_free_beads: int, n_free_bonds: int,
                         motor: str = "prescribed", n_motors: int = 1) -> "DofLayout":
        """Filaments behind motor clamps: free bead positions, free twist angles, motor
        angles (``motor = "angle"``: a torque-driven motor's angle, an unknown like the rest),
        one per filament (:mod:`flagwrap.system.parts`)."""
        return cls([("x", "position", 3 * n_free_beads), ("theta", "angle", n_free_bonds),
                    ("phi", motor, n_motors)])

    def __getitem__(self, name: str) -> slice:
        return self._by_name[name].slice

    def block(self, name: str) -> Block:
        return self._by_name[name]

    def error_weights(self, tol: float) -> np.ndarray:
        """The absolute error each unknown is held to (``inf`` for prescribed ones)."""
        w = np.full(self.size, np.inf)
        for b in self.blocks:
            if b.kind in TOL_FACTOR:
                w[b.slice] = TOL_FACTOR[b.kind] * tol
        return w

    def scaled_error(self, err: np.ndarray, tol: float) -> float:
        """Max-norm of ``err`` against :meth:`error_weights` (prescribed blocks excluded)."""
        worst = 0.0
        for b in self.blocks:
            if b.kind in TOL_FACTOR and b.size:
                worst = max(worst, np.abs(err[b.slice]).max() / (TOL_FACTOR[b.kind] * tol))
        return float(worst)

    def locate(self, k: int) -> tuple[str, int]:
        """``(block name, index within the block)`` of unknown ``k``."""
        for b in self.blocks:
            if b.start <= k < b.start + b.size:
                return b.name, k - b.start
        raise IndexError(f"unknown {k} outside the layout (size {self.size})")

    def free(self) -> np.ndarray:
        """Indices of the unknowns that are not prescribed (e.g. for a static Newton solve)."""
        return np.concatenate([np.arange(b.start, b.start + b.size) for b in self.blocks
                               if b.kind != "prescribed"] or [np.zeros(0, int)])

    def __repr__(self) -> str:
        return "DofLayout(" + ", ".join(f"{b.name}:{b.kind}[{b.size}]" for b in self.blocks) + ")"
