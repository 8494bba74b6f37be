"""Rigid cell body (cylinder + hemispherical cap) and its short-ranged repulsion."""

from flagwrap.body.cell_body import CappedCylinder

__all__ = ["CappedCylinder"]
