"""Discrete Kirchhoff rod: bending, twist and stretching energies and their exact gradients."""

from flagwrap.elasticity.rod import RestState, elastic_energy, elastic_forces, rest_state

__all__ = ["RestState", "rest_state", "elastic_energy", "elastic_forces"]
