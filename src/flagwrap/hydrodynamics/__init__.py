"""Translational and rotational mobilities of the bead chain."""

from flagwrap.hydrodynamics.mobility import LocalMobility, Mobility, RPYMobility, make_mobility

__all__ = ["Mobility", "RPYMobility", "LocalMobility", "make_mobility"]
