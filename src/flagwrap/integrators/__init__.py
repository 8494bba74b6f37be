"""Time steppers behind one interface (``step``, ``order``, ``adaptive``): the Rosenbrock
W-methods are one stepper over tableaus (``rosenbrock.RosenbrockW``, ``tableau``), step-size
control is its own object (``controller.IController``)."""

from flagwrap.integrators.base import Integrator, StepResult
from flagwrap.integrators.euler import ExplicitEuler
from flagwrap.integrators.rosenbrock import ROS2, ROS34PW2, RosenbrockW

REGISTRY = {"ros34pw2": ROS34PW2, "ros2": ROS2, "euler": ExplicitEuler}


def make_integrator(name: str, tol: float = 1e-5, linear_solver: str = "auto") -> Integrator:
    if name not in REGISTRY:
        raise ValueError(f"unknown integrator {name!r}; known: {', '.join(REGISTRY)}")
    cls = REGISTRY[name]
    return cls() if name == "euler" else cls(tol=tol, linear_solver=linear_solver)


__all__ = ["Integrator", "StepResult", "ExplicitEuler", "ROS2", "ROS34PW2", "RosenbrockW",
           "make_integrator", "REGISTRY"]
