"""Reference scales and the one place where SI quantities become dimensionless.

The simulator's core works in the units of the paper's scaling argument:

* length: the filament contour length ``L``                         [m]
* time:   ``1/omega`` with ``omega`` the reference motor angular speed [s]
  (the speed of the CW phase, the one that defines ``M``); one motor turn is ``2 pi``
* force:  ``A / L**2`` with ``A = pi E a**4 / 4`` the bending modulus [N]
* energy and torque: ``A / L``                                      [J], [N m]

With these units the overdamped equation of motion ``dx/dt = mu F`` reads
``dx/dt = (1/M) mu_hat(x) F`` where ``M = eta omega L**4 / A`` (main text, after Ref. Machin
1958) is the only dynamical parameter and ``mu_hat = eta L mu`` is a purely geometric mobility.

Nothing outside this module and :mod:`flagwrap.io` converts units.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

#: standard gravity [m s^-2]
G_ACCEL = 9.80665
#: Boltzmann constant [J K^-1]
K_B = 1.380649e-23

# prefixes for the bacterial scale (microns, pN) and the experimental scale (mm, MPa)
MICRON = 1e-6
MM = 1e-3
PN = 1e-12
NM = 1e-9
MPA = 1e6
PN_NM = PN * NM  # torque unit pN nm in N m
PN_UM2 = PN * MICRON**2  # bending modulus unit pN um^2 in N m^2


def bending_modulus(youngs_modulus: float, radius: float) -> float:
    """Bending modulus ``A = pi E a^4 / 4`` of a round rod [N m^2] (main text, after Eq. 1)."""
    return math.pi * youngs_modulus * radius**4 / 4.0


def twist_modulus(bending: float, poisson_ratio: float) -> float:
    """Twist modulus ``C = A / (1 + nu)`` of a round isotropic rod [N m^2] (main text, after Eq. 1)."""
    return bending / (1.0 + poisson_ratio)


def machin_number(viscosity: float, omega: float, length: float, bending: float) -> float:
    """Sperm/Machin number ``M = eta omega L^4 / A`` (dimensionless; main text)."""
    return viscosity * omega * length**4 / bending


def reynolds_number(density: float, radius: float, omega: float, viscosity: float) -> float:
    """``Re = rho R^2 omega / eta`` with the helix radius ``R`` as length scale (main text)."""
    return density * radius**2 * omega / viscosity


def gravity_number(delta_density: float, radius: float, length: float, bending: float) -> float:
    """Gravity number ``G = (rho_f - rho) g pi a^2 L^3 / A`` (dimensionless).

    ``delta_density = rho_f - rho`` [kg m^-3]: positive for a filament lighter than the fluid
    (buoyant), whose net force points up, toward the clamp of a filament hanging below the
    motor, and so compresses it. ``G`` is the buoyant weight per length ``q`` in units of
    ``A / L^3``; a straight clamped-free column so loaded toward its clamp buckles at
    ``q L^3 / A = 7.837`` (Greenhill 1881; Timoshenko & Gere, *Theory of Elastic Stability*,
    2nd ed., section 2.13). In core units the force on a bead carrying contour ``l`` is
    ``G l / L`` along ``+z`` (force unit ``A / L^2``).
    """
    return delta_density * G_ACCEL * math.pi * radius**2 * length**3 / bending


@dataclass(frozen=True)
class Scales:
    """Reference scales of one run.

    Attributes
    ----------
    length : float
        ``L`` [m].
    omega : float
        reference motor angular speed [rad/s]; the time unit is ``1/omega``.
    bending : float
        ``A`` [N m^2].
    viscosity : float
        ``eta`` [Pa s].
    """

    length: float
    omega: float
    bending: float
    viscosity: float

    @property
    def time(self) -> float:
        """Time unit ``1/omega`` [s]."""
        return 1.0 / self.omega

    @property
    def period(self) -> float:
        """Motor period ``T = 2 pi / omega`` [s]."""
        return 2.0 * math.pi / self.omega

    @property
    def force(self) -> float:
        """Force unit ``A/L^2`` [N]."""
        return self.bending / self.length**2

    @property
    def energy(self) -> float:
        """Energy (and torque) unit ``A/L`` [J] = [N m]."""
        return self.bending / self.length

    torque = energy

    @property
    def machin(self) -> float:
        """``M = eta omega L^4 / A``."""
        return machin_number(self.viscosity, self.omega, self.length, self.bending)

    # conversions -------------------------------------------------------------------------
    def to_length(self, x_si):
        return x_si / self.length

    def from_length(self, x):
        return x * self.length

    def to_time(self, t_si):
        return t_si * self.omega

    def from_time(self, t):
        return t / self.omega

    def to_force(self, f_si):
        return f_si / self.force

    def from_force(self, f):
        return f * self.force

    def from_torque(self, n):
        return n * self.torque

    def to_torque(self, n_si):
        return n_si / self.torque

    def to_rate(self, hz):
        """A frequency [Hz] as an angular velocity in core units (``2 pi f / omega``)."""
        return 2.0 * math.pi * hz / self.omega


def hook_spring(hook_modulus: float, hook_length: float, bending: float, length: float) -> float:
    """A lumped joint's spring ``K_h / l_h`` (bending ``A_h`` or twist ``C_h`` over the hook
    length) in the core torque unit ``A / L``: ``K_h L / (A l_h)`` (docs/hook.md)."""
    return hook_modulus * length / (bending * hook_length)
