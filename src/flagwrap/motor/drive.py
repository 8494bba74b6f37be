"""What the motor prescribes: its rate, its torque, or a torque-speed curve (``motor.kind``).

The motor angle ``phi`` turns the joint relative to the body. Its rotor (the joint's clamped
beads and bonds) has no inertia, so its torque balance holds at every instant::

    zeta_r dphi/dt = tau_m(dphi/dt) + G_phi,        G_phi = -dE/dphi,

``zeta_r`` the rotational drag of the clamped bond (``M 8 pi a^3 w_0``, as in
:meth:`~flagwrap.system.rod_system.RodSystem.motor_torque`: the motor's own friction in
this model) and ``G_phi`` the filament's elastic torque on the rotor. Each drive is one class:

* :class:`SpeedDrive` (``kind = "speed"``, the paper's rig): ``dphi/dt = omega(t)``, the
  protocol's rate; ``phi`` is prescribed (no error control).
* :class:`TorqueDrive` (``"torque"``): ``tau_m = s tau`` in the phase's direction ``s``
  (+1 CCW, -1 CW, 0 stop: a free-wheeling rotor), so ``dphi/dt = (s tau + G_phi) / zeta_r``.
* :class:`TorqueSpeedDrive` (``"torque-speed"``): the linear curve from stall to zero load,
  ``tau_m = s tau_s (1 - s dphi/dt / omega_0)`` (in the phase's direction ``s``), so
  ``dphi/dt = (s tau_s + G_phi) / (zeta_r + tau_s / omega_0)``. The bacterial motor's curve is
  flat up to a knee and then falls linearly to zero at ``omega_0`` (Berg, Annu. Rev.
  Biochem. 72, 19 (2003); Chen & Berg, Biophys. J. 78, 1036 (2000)); the line through stall
  and zero load is its one-parameter-pair simplification, exact at both ends.

Both torque drives make ``phi`` an unknown like the others (error-controlled, kind "angle"),
and their rate is linear in ``G_phi``: :meth:`mobility` = ``d(dphi/dt)/dG_phi`` enters the
stage solver's ``W`` (its motor-angle row). A stop phase of a torque drive switches the motor
off: the rotor free-wheels (``tau_m = 0``).
"""

from __future__ import annotations


class SpeedDrive:
    """The protocol's rate (``dphi/dt = omega``)."""

    kind = "speed"
    free = False  # phi is prescribed

    def rate(self, omega: float, G_phi: float) -> float:
        return omega

    def mobility(self, omega: float) -> float:
        """``d(dphi/dt)/dG_phi`` in the phase of ``omega``."""
        return 0.0


class TorqueDrive:
    """Constant torque ``tau`` (core units) in the phase's direction."""

    kind = "torque"
    free = True

    def __init__(self, tau: float, zeta: float):
        if not (tau > 0 and zeta > 0):
            raise ValueError("TorqueDrive: tau and zeta must be > 0")
        self.tau = float(tau)
        self.zeta = float(zeta)

    def mobility(self, omega: float) -> float:
        """``d(dphi/dt)/dG_phi``: ``1/zeta`` (a stop phase is a free-wheeling rotor)."""
        return 1.0 / self.zeta

    def rate(self, omega: float, G_phi: float) -> float:
        s = (omega > 0) - (omega < 0)
        return (s * self.tau + G_phi) * self.mobility(omega)

    def torque(self, rate: float, omega: float) -> float:
        """The torque the motor exerts at ``rate`` in the phase of ``omega`` (core units)."""
        return ((omega > 0) - (omega < 0)) * self.tau


class TorqueSpeedDrive(TorqueDrive):
    """The linear torque-speed curve: stall torque ``tau`` and zero-load rate ``omega_0``
    (core units)."""

    kind = "torque-speed"

    def __init__(self, tau: float, omega_0: float, zeta: float):
        super().__init__(tau, zeta)
        if not omega_0 > 0:
            raise ValueError("TorqueSpeedDrive: omega_0 must be > 0")
        self.omega_0 = float(omega_0)

    def mobility(self, omega: float) -> float:
        """``1/(zeta + tau_s/omega_0)`` while the motor drives, ``1/zeta`` when it stops."""
        return 1.0 / (self.zeta + self.tau / self.omega_0) if omega != 0 else 1.0 / self.zeta

    def torque(self, rate: float, omega: float) -> float:
        s = (omega > 0) - (omega < 0)
        return s * self.tau * (1.0 - s * rate / self.omega_0) if s else 0.0


def make_drive(config, zeta: float):
    """The drive of ``config.motor`` with the rotor drag ``zeta`` (core units)."""
    m, sc = config.motor, config.scales
    if m.kind == "speed":
        return SpeedDrive()
    tau = sc.to_torque(m.stall_torque)
    if m.kind == "torque":
        return TorqueDrive(tau, zeta)
    return TorqueSpeedDrive(tau, sc.to_rate(m.zero_load_speed), zeta)
