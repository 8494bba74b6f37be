"""Joints between the motor and the filament: the interface (:mod:`flagwrap.joints.base`),
the paper's clamp (:mod:`flagwrap.joints.clamp`) and the flagellar hook
(:mod:`flagwrap.joints.hook`). :func:`make_joint` builds the one a config asks for."""

from __future__ import annotations

from flagwrap.joints.base import Joint
from flagwrap.joints.clamp import AxialClamp
from flagwrap.joints.hook import LumpedHook, ResolvedHook, insert_hook


def make_joint(config, x0, theta0, axis=(0.0, 0.0, -1.0), origin=(0.0, 0.0, 0.0)):
    """``(joint, x0, theta0)`` for ``config.joint`` from the filament's core-unit shape ``x0``
    (a resolved hook adds beads, so the shape comes back); ``axis``, ``origin``: the motor's
    axis and anchor (the shape ``x0`` already placed there)."""
    from flagwrap import units
    from flagwrap.geometry.helix import held_beads

    j = config.joint
    nh = held_beads(config.filament, config.clamp)
    if j.kind == "clamp":
        return AxialClamp(x0, theta0, axis, origin, nh), x0, theta0
    fil = config.filament
    A, L = fil.bending_modulus, fil.length
    C_h = fil.twist_modulus if j.hook_twist_modulus is None else j.hook_twist_modulus
    if j.hook_segments == 0:
        hook = LumpedHook(x0, theta0, units.hook_spring(j.hook_bending_modulus, j.hook_length, A, L),
                          units.hook_spring(C_h, j.hook_length, A, L), axis, origin, nh)
        return hook, x0, theta0
    x, th = insert_hook(x0, theta0, j.hook_length / L, j.hook_segments, nh)
    hook = ResolvedHook(x, th, j.hook_length / L, j.hook_segments,
                        bending=j.hook_bending_modulus / A, twist=C_h / A, rod_bending=1.0,
                        rod_twist=fil.twist_modulus / A, bond=fil.bond_length / L, axis=axis,
                        origin=origin, n_beads=nh)
    return hook, x, th


__all__ = ["Joint", "AxialClamp", "LumpedHook", "ResolvedHook", "insert_hook", "make_joint"]
