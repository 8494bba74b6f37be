"""The flagellar hook: a short elastic joint between the motor and the filament.

The paper (Discussion): "the hook enables a bacterium to wrap its filament around its cell body
without forming any localized bend". Two representations of one hook of length ``l_h``,
bending stiffness ``A_h`` and twist stiffness ``C_h`` (core units: ``A = 1``, lengths in ``L``):

* :class:`LumpedHook` (``joint.hook_segments = 0``): the clamp's kinematics (the motor holds
  the first bond), with vertex 1, between the motor axis and the first free bond, a bending
  spring ``A_h/l_h`` and a twist spring ``C_h/l_h`` instead of the filament's ``A/b``,
  ``C/b``: the energy ``A_h/(2 l_h) |kappa - kappa_bar|^2 + C_h/(2 l_h) (m - m_bar)^2`` of a
  rod of length ``l_h`` bent and twisted uniformly, with the curvature measured by the turning
  angle (``angle_law``: a hook bends through large angles, where the discrete rod's
  ``2 tan(psi/2)`` would make the spring 7 % stiffer at 0.46 rad and 2.5x at pi/2; the clamp
  keeps the rod's measure). The rest angle is the initial shape's at the
  vertex (the kink to the helix for ``clamp.lead = "kink"``), so the initial state is
  stress-free.
* :class:`ResolvedHook` (``hook_segments = n >= 2``): ``n`` bonds of length ``l_h/n`` along the
  motor axis inserted between the motor's bond and the filament, which keeps its own beads (the
  contour grows by ``l_h``). The hook's vertices carry the compliance ``l_h/A_h`` in total:
  ``l_h/(2n)/A_h`` at each end, ``l_h/(n A_h)`` between; the junction to the filament adds the
  filament's half bond ``b/(2A)``. The hook is straight at rest; the kink to the helix sits at
  the junction.

Both agree where both apply (``l_h << L``): tests/unit/test_hook.py compares their torque
balance with the analytic one. The universal-joint limit is ``A_h -> 0`` with the twist kept.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from flagwrap.elasticity.rod import turning_angle_scale
from flagwrap.joints.clamp import AxialClamp


class LumpedHook(AxialClamp):
    """The clamp's kinematics with vertex 1 a spring ``k_bend = A_h/l_h``, ``k_twist = C_h/l_h``
    (core units ``A/L``)."""

    kind = "hook"

    def __init__(self, x0, theta0, k_bend: float, k_twist: float, axis=(0.0, 0.0, -1.0),
                 origin=(0.0, 0.0, 0.0), n_beads: int = 2):
        super().__init__(x0, theta0, axis, origin, n_beads)
        if not (k_bend > 0 and k_twist > 0):
            raise ValueError("LumpedHook: k_bend and k_twist must be > 0")
        self.k_bend = float(k_bend)
        self.k_twist = float(k_twist)
        v = self.vertex
        ta = (x0[v] - x0[v - 1]) / np.linalg.norm(x0[v] - x0[v - 1])
        tb = (x0[v + 1] - x0[v]) / np.linalg.norm(x0[v + 1] - x0[v])
        c = float(np.clip(ta @ tb, -1.0, 1.0))
        #: rest turning angle at the hook and the factor psi/|kb| that rescales its curvature
        self.rest_angle = float(np.arccos(c))
        self._g0 = turning_angle_scale(2.0 * np.sqrt(max(1.0 - c, 0.0) / (1.0 + c)))

    def rest(self, rest):
        v = self.vertex
        r = super().rest(rest).with_vertex(v, cbend=self.k_bend, ctwist=self.k_twist,
                                           kbar=rest.kbar[v] * self._g0)
        law = r.angle_law.copy()
        law[v] = True
        return dataclasses.replace(r, angle_law=law)


def insert_hook(x0: np.ndarray, theta0: np.ndarray, length: float, segments: int,
                held: int = 2):
    """``x0`` with ``segments`` bonds of ``length/segments`` inserted after bead ``held - 1``
    (the motor's last held bead), along the motor's bond; the beads beyond move by ``length``
    along it (their shape is unchanged)."""
    m = held - 2  # the motor's bond
    t0 = x0[m + 1] - x0[m]
    t0 = t0 / np.linalg.norm(t0)
    s = length / segments * np.arange(1, segments + 1)
    hook = x0[m + 1] + s[:, None] * t0
    x = np.concatenate([x0[:held], hook, x0[held:] + length * t0])
    theta = np.concatenate([theta0[:m + 1], np.full(segments, theta0[m]), theta0[m + 1:]])
    return x, theta


class ResolvedHook(AxialClamp):
    """A hook of ``segments`` short bonds after the motor's bond (see the module docstring).

    ``bending``, ``twist``: ``A_h``, ``C_h`` [A]; ``length``: ``l_h`` [L]; ``rod_bending``,
    ``rod_twist``: the filament's ``A``, ``C`` [A]; ``bond``: its bond ``b`` [L].
    """

    kind = "hook"

    def __init__(self, x0, theta0, length, segments, bending, twist, rod_bending, rod_twist,
                 bond, axis=(0.0, 0.0, -1.0), origin=(0.0, 0.0, 0.0), n_beads: int = 2):
        super().__init__(x0, theta0, axis, origin, n_beads)
        if not (length > 0 and segments >= 2 and bending > 0 and twist > 0):
            raise ValueError("ResolvedHook: length, bending, twist > 0 and segments >= 2 needed")
        self.length, self.segments = float(length), int(segments)
        self.bending, self.twist = float(bending), float(twist)
        self.rod_bending, self.rod_twist, self.bond = float(rod_bending), float(rod_twist), float(bond)
        self.exit_bond = self.vertex + self.segments

    def _compliances(self, modulus, rod_modulus):
        """Per-vertex ``l_i/K_i`` of vertices 1..n+1 (their sum over the hook is ``l_h/K_h``)."""
        n, lh = self.segments, self.length
        c = np.full(n + 1, lh / (n * modulus))
        c[0] = c[-1] = lh / (2 * n * modulus)
        c[-1] += 0.5 * self.bond / rod_modulus
        return c

    def rest(self, rest):
        n, v = self.segments, self.vertex
        rest = super().rest(rest)
        cb = rest.cbend.copy()
        ct = rest.ctwist.copy()
        cb[v:v + n + 1] = 1.0 / self._compliances(self.bending, self.rod_bending)
        ct[v:v + n + 1] = 1.0 / self._compliances(self.twist, self.rod_twist)
        return dataclasses.replace(rest, cbend=cb, ctwist=ct)
