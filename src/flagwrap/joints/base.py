"""The interface of a joint between the motor and the filament.

A joint decides three things, so that a new joint is a new class and no edit of
:class:`flagwrap.system.rod_system.RodSystem`, the integrators or the loop:

1. **shape**: a joint is built for the stress-free shape it is given, and may have added beads
   to it first (the resolved hook inserts its short bonds: :func:`flagwrap.joints.insert_hook`);
   :func:`flagwrap.joints.make_joint` returns the joint with its shape.
2. **stiffness** (:meth:`Joint.rest`): the joint's vertices get their own coefficients
   (``RestState.with_vertex``); the lumped hook replaces vertex 1's ``A/b`` by ``A_h/l_h``.
3. **kinematics**: which beads and twist angles the motor prescribes, as functions of the
   motor angle ``phi`` (``n_beads``, ``n_edges``, :meth:`positions`, :meth:`theta`,
   :meth:`generalized_force`). The fused force kernel (:mod:`flagwrap.system.kernels`)
   implements one kind, a rigid rotation about ``axis`` of the reference beads ``x_ref`` and
   twist angles ``theta_ref + twist_rate phi``; every joint so far is driven that way
   (:class:`~flagwrap.joints.clamp.AxialClamp`'s kinematics).

Observables (:meth:`observables`): the angle between the motor axis and the first bond of the
filament proper and the bending and twist torques at the joint's vertex, recorded every frame
(``hook_angle``, ``hook_torque``, ``hook_twist_torque`` in the run file).
"""

from __future__ import annotations

import math

import numpy as np

from flagwrap.elasticity.rod import turning_angle_scale


class Joint:
    """Base class: the identity stiffness and the observables; subclasses set the kinematics."""

    #: the joint's vertex (where its torque is measured) and the first bond of the filament
    #: proper (whose angle to the motor axis is the joint's angle)
    vertex = 1
    exit_bond = 1
    #: the motor's bond (the last one it holds), from which the joint's angle is measured
    motor_bond = 0
    kind = "joint"

    def rest(self, rest):
        return rest

    def observables(self, x, theta, m1, m2, frames, rest) -> tuple[float, float, float]:
        """``(angle [rad], bending torque [A/L], twist torque [A/L])`` at the joint.

        Angle: between the motor's bond (:attr:`motor_bond`) and :attr:`exit_bond`. Torques at
        :attr:`vertex`: ``cb |kappa - kappa_bar|`` and ``ct (m - m_bar)`` (the elastic
        kernel's terms, :mod:`flagwrap.elasticity._kernels`; at an ``angle_law`` vertex the
        curvatures in the turning-angle measure its ``kappa_bar`` is in).
        """
        i = self.vertex
        t = frames.t
        c = float(np.clip(np.dot(t[self.motor_bond], t[self.exit_bond]), -1.0, 1.0))
        ta, tb = t[i - 1], t[i]
        kb = 2.0 * np.cross(ta, tb) / (1.0 + np.dot(ta, tb))
        g = turning_angle_scale(float(np.linalg.norm(kb))) if rest.angle_law[i] else 1.0
        k1 = 0.5 * g * np.dot(m2[i - 1] + m2[i], kb)
        k2 = -0.5 * g * np.dot(m1[i - 1] + m1[i], kb)
        bend = rest.cbend[i] * math.hypot(k1 - rest.kbar[i, 0], k2 - rest.kbar[i, 1])
        twist = rest.ctwist[i] * (theta[i] - theta[i - 1] + frames.rt[i] - rest.mbar[i])
        return math.acos(c), float(bend), float(twist)
