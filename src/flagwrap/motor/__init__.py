"""Motor protocols (angular velocity against time). The joints the motor drives (the clamp,
the hook) live in :mod:`flagwrap.joints`; ``AxialClamp`` is re-exported here for old imports."""

from flagwrap.joints.clamp import AxialClamp
from flagwrap.motor.protocol import Schedule

__all__ = ["Schedule", "AxialClamp"]
