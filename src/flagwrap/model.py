"""Old name of :mod:`flagwrap.system.rod_system` (the assembled system, ``RodSystem``)."""

from flagwrap.system.rod_system import ForceInfo, RodSystem  # noqa: F401
