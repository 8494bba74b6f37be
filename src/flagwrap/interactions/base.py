"""The interface of an interaction: an extra energy term ``U(x, theta)`` of the system.

:class:`flagwrap.system.rod_system.RodSystem` evaluates its fused kernel (the filament's elasticity, the
joint, the body contact, gravity) and then every interaction in ``system.interactions``:

* ``energy_grad(x, theta, grad_x, grad_theta) -> float``: the energy [A/L]; *adds*
  ``dU/dx`` (N, 3) and ``dU/dtheta`` (N-1,) to the arrays (all beads, clamped ones included:
  their share goes into the motor torque);
* ``hessian_coo(x, theta)`` -> ``(rows, cols, vals)`` or ``None``: ``d^2U`` as COO triplets
  over the full coordinates (bead ``i`` component ``c`` is ``3 i + c``, twist ``j`` is
  ``3 N + j``); the system maps them onto the unknowns and adds ``-d^2U`` to the Jacobian.
  ``None`` leaves the term out of ``W`` (the W-methods keep their order with any ``W``;
  only the step size can suffer where the term is stiff);
* ``stage_hessian_coo(x, theta)`` (optional): the same for the stage solver's ``W`` only,
  where a different stiffness steps better than the exact one (the boundary contacts look
  their stiffness ahead of the law's cut-off: :mod:`flagwrap.interactions.wall`); without
  it ``W`` takes ``hessian_coo``, and the stability tools always do;
* ``nonlocal_hessian``: true when the triplets couple beads far apart along the chain (the
  banded solvers, whose band is fixed per system, leave those out; dense and Krylov use them);
* ``rotation_invariant``: true when ``U`` is unchanged by a rotation of everything about the
  motor axis (distances only, or axisymmetric fields); the rotating frame
  (:mod:`flagwrap.system.rotating`) and the stability tool refuse an interaction without it;
* ``name``: a label for messages and energies.

The Jacobian's motor-angle column omits interactions (the joint's beads move with ``phi``, an
interaction's pull on them enters ``W`` only through their free partners).

A new interaction is a class with these members, passed as ``RodSystem(config,
interactions=[...])``: tests/unit/test_extension.py defines one in the test file and runs it.
"""

from __future__ import annotations


class Interaction:
    """Base class (a documentation anchor: any object with these members works)."""

    name = "interaction"
    nonlocal_hessian = False
    rotation_invariant = False

    def energy_grad(self, x, theta, grad_x, grad_theta) -> float:  # pragma: no cover
        raise NotImplementedError

    def hessian_coo(self, x, theta):
        return None
