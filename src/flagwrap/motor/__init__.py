"""Motor protocols (angular velocity against time) and the clamp boundary condition."""

from flagwrap.motor.clamp import AxialClamp
from flagwrap.motor.protocol import Schedule

__all__ = ["Schedule", "AxialClamp"]
