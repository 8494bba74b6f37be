"""Time steppers behind one interface (``step``, ``order``, ``adaptive``)."""

from flagwrap.integrators.base import Integrator, StepResult
from flagwrap.integrators.euler import ExplicitEuler
from flagwrap.integrators.rosenbrock import ROS2


def make_integrator(name: str, tol: float = 1e-3) -> Integrator:
    if name == "euler":
        return ExplicitEuler()
    if name == "rosenbrock":
        return ROS2(tol=tol)
    raise ValueError(f"unknown integrator {name!r}")


__all__ = ["Integrator", "StepResult", "ExplicitEuler", "ROS2", "make_integrator"]
