"""ROS34PW2 (Rang & Angermann 2005): the tableau is :data:`flagwrap.integrators.tableau.ROS34PW2`
and the step :class:`flagwrap.integrators.rosenbrock.RosenbrockW`; kept for its names
(``GAMMA`` and the transformed coefficients ``A_T``, ``C_T``, ``M_T``, ``E_T``)."""

from flagwrap.integrators.rosenbrock import ROS34PW2
from flagwrap.integrators.tableau import ROS34PW2 as _TB

GAMMA = _TB.gamma
A_T, C_T, M_T, E_T = _TB.a, _TB.c, _TB.m, _TB.e

__all__ = ["ROS34PW2", "GAMMA", "A_T", "C_T", "M_T", "E_T"]
