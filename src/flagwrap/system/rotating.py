"""The equations of motion in the frame that turns with the motor.

The lab-frame system (:mod:`flagwrap.system.rod_system`) is
``dx/dt = Mob(x) G_x``, ``dtheta_j/dt = G_theta_j / zeta_j`` with the motor angle ``phi``
turning the clamp, ``dphi/dt = omega``. Write every vector in the frame that turns with the
clamp about the motor axis ``a`` (``x = R(phi) x'``). The energy is invariant under rotations.
The RPY mobility is covariant, ``Mob(R x) = R Mob(x) R^T``. The cell body is a body of
revolution about the axis (its shape's ``axisymmetric``), and gravity is parallel to it. So
in that frame the clamp stands still and the equations are autonomous:

    dx'/dt      = Mob(x') G_x(x', theta')  - omega a x x'
    dtheta'_j/dt = G_theta_j / zeta_j       - omega (a . t'_j)

The twist term comes from the reference frames. In the lab, a bond's reference director is
transported in time along its moving tangent (no twist about ``t``). Seen from the turning
frame, that director turns about ``t'`` at ``-omega (a . t')`` relative to one transported in
the turning frame. So an angle measured from the turning frame's own transported director
changes by that much less (derivation in docs/stability.md). The clamped bond obeys the same
rule: in the lab it turns at ``twist_rate = a . t_0`` per radian of ``phi``
(:class:`~flagwrap.joints.clamp.AxialClamp`), and in the turning frame it is fixed.

A steadily whirling helix is a fixed point of these equations. It can be found by Newton and
its linear stability read from their Jacobian (:mod:`flagwrap.stability`). The Jacobian is
taken in the chart whose reference frames are those of the point itself. A chart change
alters the reference director's twist only at second order in the displacement, so the
linearisation is the same in every chart.

``omega`` and ``M`` are in core units (time ``1/omega_ref``): ``omega = +-speed``. The mobility
scales as ``1/M`` for translation and twist alike, so one system built at ``M_0`` serves every
``M`` through the factor ``M_0 / M``.
"""

from __future__ import annotations

import math

import numpy as np

from flagwrap.errors import UserInputError
from flagwrap.system.rod_system import RodSystem


def cross_matrix(a) -> np.ndarray:
    """``[a]_x`` with ``[a]_x v = a x v``."""
    return np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])


def subtract_rotation(f, system, info, omega: float, axis, A) -> None:
    """The turning frame's terms, in place on a lab-layout velocity ``f``:
    ``- omega a x x_i`` for the free beads and ``- omega (a . t_j)`` for the free bonds
    (module docstring); ``A = [a]_x``. ``a x x_i`` for every bead is one product with
    ``[a]_x`` (np.cross cost more than the forces here)."""
    if omega == 0.0:
        return
    s = system
    f[s.sl_x] -= omega * (info.x[s.nc:] @ A.T).ravel()
    f[s.sl_th] -= omega * (info.frames.t[s.ec:] @ axis)


def check_rotating_frame(system, blob_body: bool = False, placed=()) -> None:
    """Refuse a system whose equations are not autonomous in the turning frame (one line,
    naming the part that breaks the symmetry about the motor axis). ``blob_body``: accept a
    no-slip blob body as if it were symmetric (its blobs held at one angle in the turning
    frame: the linear-stability approximation of :class:`RotatingFrame`). ``placed``:
    interactions the frame itself places at each state (a free cell's boundary contact:
    :class:`~flagwrap.system.swimmer.SwimmerRotating`), exact at any angle."""
    parts = getattr(system, "parts", ())
    if len(parts) > 1:
        raise UserInputError(
            f"the turning frame (numerics.frame = 'rotating', flagwrap stability) needs one "
            f"flagellum on the motor axis; this system has {len(parts)} ([[flagellum]] tables)")
    joint = system.joint
    axis = getattr(joint, "axis", None)
    if axis is None or not hasattr(joint, "x_ref"):
        raise UserInputError(
            f"the rotating frame needs a joint that turns rigidly about the motor axis; "
            f"{type(joint).__name__} does not (use [joint] kind = \"clamp\" or \"hook\")")
    a = np.asarray(axis, float)
    ez = np.array([0.0, 0.0, 1.0])
    if np.linalg.norm(np.cross(a, ez)) > 1e-12:
        # the body's axis and gravity are along z: the motor axis must be too
        raise UserInputError("the rotating frame needs the motor axis along the body axis z")
    o = np.asarray(getattr(joint, "origin", np.zeros(3)), float)
    if math.hypot(o[0], o[1]) > 1e-12:
        raise UserInputError(
            "the rotating frame needs the motor on the body axis; this flagellum's anchor is "
            f"{math.hypot(o[0], o[1]):.3g} L off it ([[flagellum]] anchor)")
    shape = getattr(getattr(system, "body", None), "body_shape", None)
    if shape is not None and not shape.axisymmetric:
        raise UserInputError(
            f"the rotating frame needs a body symmetric about the motor axis; body.shape = "
            f"{shape.name!r} is not (its class says axisymmetric = False): use the lab frame")
    g = np.asarray(system.gravity)
    if np.any(np.abs(g[:, :2]) > 0.0):
        raise UserInputError("the rotating frame needs gravity along the motor axis")
    if not blob_body and not getattr(system.mobility, "axisymmetric", True):
        raise UserInputError(
            f"the rotating frame needs a mobility symmetric about the motor axis; "
            f"{type(system.mobility).__name__} (a no-slip blob body) is not: use the lab frame")
    for it in system.interactions:
        if not getattr(it, "rotation_invariant", False) and not any(it is p for p in placed):
            raise UserInputError(
                f"the rotating frame needs every interaction to be invariant under rotations "
                f"about the motor axis; {getattr(it, 'name', type(it).__name__)!r} does not say "
                f"it is (set rotation_invariant = True on it if it is)")


class RotatingFrame:
    """The system's equations in the frame turning with the motor at ``omega`` (core units).

    The unknowns are ``z = y[:-1]``, the lab state vector without the motor angle, written in
    the turning frame. The clamp is then at its reference position (``phi = 0``).

    ``blob_body = True`` accepts a fixed no-slip body (:class:`~flagwrap.body.
    fixed_mobility.FixedBodyMobility`): its blob shell, not quite symmetric about the axis, is
    held at one angle in this frame, where it really turns at ``-omega``. The error is the
    shell's ripple; docs/bacterium.md measures it by turning the shell between two runs.
    """

    def __init__(self, system, omega: float, blob_body: bool = False):
        check_rotating_frame(system, blob_body=blob_body)
        if system.i_phi != system.ny - 1:
            raise ValueError("RotatingFrame: the motor angle must be the last unknown")
        self._setup(system, omega, system.ny - 1)

    def _setup(self, system, omega: float, n: int) -> None:
        """The frame of ``system`` turning at ``omega``, over its first ``n`` unknowns."""
        self.system = system
        self.omega = float(omega)
        self.axis = np.asarray(system.joint.axis, float)
        self.n = n
        self.n3 = 3 * system.nb
        self._A = cross_matrix(self.axis)

    def full(self, z) -> np.ndarray:
        """The lab state vector at ``phi = 0`` (where both frames coincide)."""
        y = np.empty(self.system.ny)
        y[:-1] = z
        y[-1] = 0.0
        return y

    def reduce(self, y) -> np.ndarray:
        """The unknowns ``z`` of a lab-layout state ``y`` (a copy): :meth:`full`'s inverse."""
        return np.array(y[:self.n], float)

    def scale(self, machin: float | None) -> float:
        return 1.0 if machin is None else self.system.machin / float(machin)

    def velocity(self, z, base, machin: float | None = None):
        """``dz/dt`` (turning frame) and the :class:`ForceInfo` at ``z``; ``machin``: the
        Machin number to use (default: the system's)."""
        s = self.system
        y = self.full(z)
        info = s.forces(y, base)
        f = s.apply_mobility(y, info.G)
        f *= self.scale(machin)
        subtract_rotation(f, s, info, self.omega, self.axis, self._A)
        return f[:-1], info

    def jacobian(self, z, base, machin: float | None = None, info=None) -> np.ndarray:
        """``d(dz/dt)/dz`` (n, n), dense, at ``z`` in the chart of ``base``.

        ``Mob (dG/dz) + (dMob/dx)[G] - omega (d rotation terms)``. ``dG/dz``: the system's
        Jacobian (exact stretching Hessian, the interactions' Hessians, coloured differences
        of the rest) averaged over steps ``+delta`` and ``-delta``. That makes its difference
        part central, second-order accurate. ``(dMob/dx)[G]``: central differences of the
        mobility product at fixed forces. The rotation terms are exact.
        """
        s = self.system
        y = self.full(z)
        if info is None:
            info = s.forces(y, base)
        n, n3 = self.n, self.n3
        d = s.fd_step
        JG = 0.5 * (s.force_jacobian(y, base, info.G, delta=d)
                    + s.force_jacobian(y, base, info.G, delta=-d))
        J = self._mobility_jacobian(y, info, JG[:n, :n])
        J *= self.scale(machin)
        om = self.omega
        for i in range(s.nb):  # - omega a x x'
            J[3 * i:3 * i + 3, 3 * i:3 * i + 3] -= om * self._A
        # - omega a . t_j: d t_j / d x_{j+1} = (I - t t) / l_j = -d t_j / d x_j
        x = info.x
        a = self.axis
        for j in range(s.ec, s.N - 1):
            e = x[j + 1] - x[j]
            ln = np.linalg.norm(e)
            t = e / ln
            g = (a - (a @ t) * t) / ln
            r = n3 + (j - s.ec)
            if j + 1 >= s.nc:
                k = 3 * (j + 1 - s.nc)
                J[r, k:k + 3] -= om * g
            if j >= s.nc:
                k = 3 * (j - s.nc)
                J[r, k:k + 3] += om * g
        return J

    def mobility_product(self, y, X) -> np.ndarray:
        """``Mob X`` (n, k): the mobility over the unknowns ``z`` at the system's Machin number
        (the beads' block and the twists' local drag) times ``X`` (n, k), the forces' change
        along k directions."""
        s, n, n3 = self.system, self.n, self.n3
        Mxx, mt = s.mobility_blocks(y)
        out = np.empty((n, X.shape[1]))
        out[:n3] = Mxx @ X[:n3]
        out[n3:] = mt[:, None] * X[n3:n]
        return out

    def _mobility_jacobian(self, y, info, JG) -> np.ndarray:
        """``Mob (dG/dz) + (dMob/dx)[G]`` (n, n) at the system's Machin number; ``JG``: the
        force Jacobian over ``z``. ``(dMob/dx)[G]``: the mobility at fixed forces,
        differenced bead by bead."""
        s, n3 = self.system, self.n3
        J = self.mobility_product(y, JG)
        if s.mobility.long_range:
            xf = np.ascontiguousarray(info.x[s.nc:])
            F = np.ascontiguousarray(info.G[:n3].reshape(-1, 3))
            h = 1e-4 * s.bond  # the mobility varies on the bead radius: (h/a)^2 ~ 1e-7
            xp = xf.copy()
            for k in range(n3):
                i, c = divmod(k, 3)
                xp[i, c] = xf[i, c] + h
                vp = s.mobility.apply(xp, F)
                xp[i, c] = xf[i, c] - h
                vm = s.mobility.apply(xp, F)
                xp[i, c] = xf[i, c]
                J[:n3, k] += (vp - vm).ravel() / (2.0 * h * s.machin)
        return J


def rotation(axis, angle: float) -> np.ndarray:
    """Rotation matrix by ``angle`` about the unit vector ``axis`` (right-handed)."""
    a = np.asarray(axis, float)
    K = cross_matrix(a)
    return np.eye(3) + np.sin(angle) * K + (1.0 - np.cos(angle)) * (K @ K)


class AtReferenceAngle:
    """What a frame turning with the motor shares, whatever system it turns (a mixin before
    the system's class: :class:`RotatingSystem`, :class:`~flagwrap.system.swimmer.
    SwimmerRotating`): the forces, their Jacobians and the motor's torque are the system's
    own with the clamp at its reference angle ``phi = 0``, and no force depends on the motor
    angle, so its Jacobian column is dropped."""

    def _at_zero(self, y) -> np.ndarray:
        y0 = np.array(y, float)
        y0[self.i_phi] = 0.0
        return y0

    def _turn(self, y) -> np.ndarray:
        """``R(phi)`` (3, 3) at ``y``'s motor angle: this frame -> the system's own."""
        return rotation(self.axis, float(y[self.i_phi]))

    def pack(self, x, theta, phi, *pose, **kw) -> np.ndarray:
        """``y`` of this frame from the system's own beads ``x`` at motor angle ``phi`` (and
        a free body's pose): the positions turned back by ``phi`` about the motor axis
        (through the origin, where the frame's axis is: :func:`check_rotating_frame`)."""
        x_frame = np.asarray(x, float) @ rotation(self.axis, float(phi))  # R^T x, row-wise
        return super().pack(x_frame, theta, phi, *pose, **kw)

    def unpack(self, y):
        x, theta, _ = super().unpack(self._at_zero(y))
        return x, theta, float(y[self.i_phi])

    def record_view(self, y, info):
        """``info`` with its positions, gradients and reference frames turned by the motor
        angle into the system's own frame (twist angles and energies are frame-independent),
        then as the system records it (the rig: the lab; a free cell: its pose)."""
        import dataclasses

        from flagwrap.elasticity.rod import Frames

        R = self._turn(y)
        fr = info.frames
        turned = dataclasses.replace(info, x=info.x @ R.T, grad_x=info.grad_x @ R.T,
                                     frames=Frames(fr.t @ R.T, fr.d1 @ R.T, fr.rt))
        return super().record_view(y, turned)

    def forces(self, y, base):
        return super().forces(self._at_zero(y), base)

    def force_jacobian_coo(self, y, base, G0=None, delta=None, nonlocal_terms: bool = True,
                           stage: bool = False):
        r, c, v = super().force_jacobian_coo(self._at_zero(y), base, G0, delta, nonlocal_terms,
                                             stage)
        keep = c != self.i_phi
        return r[keep], c[keep], v[keep]

    def interaction_jacobian_coo(self, y, which: str = "all", stage: bool = False):
        return super().interaction_jacobian_coo(self._at_zero(y), which, stage)

    def motor_torque(self, info, phi: float, omega: float, y=None) -> float:
        """The system's own, from forces evaluated here with the clamp at ``phi = 0``."""
        return super().motor_torque(info, 0.0, omega)


class RotatingSystem(AtReferenceAngle, RodSystem):
    """A :class:`~flagwrap.system.rod_system.RodSystem` stepped in the frame turning with its
    motor (``numerics.frame = "rotating"``): the same system (its parts, layout, mobility and
    interactions, shared, not copied) under the equations of this frame.

    ``RotatingSystem(system)`` is a transformation, not a wrapper: the result *is* a
    ``RodSystem`` over the same data, with the methods that differ in this frame overridden
    and every other one the lab system's own (nothing is forwarded). The state vector keeps
    the lab layout, motor angle included (``dphi/dt = omega``, the angle of the frame); its
    positions and reference frames are in the turning frame. The forces are evaluated with
    the clamp at ``phi = 0``, and the velocity gains the terms of the module docstring. The
    rotation terms are not stiff (rate ``omega``), so ``W`` leaves them out, and the
    W-methods keep their order for such a ``W``. The Jacobian's motor-angle column is
    dropped: in this frame no force depends on the motor angle. :meth:`pack` takes lab
    positions and :meth:`record_view` turns a state back to the lab frame for the run file.
    """

    def __init__(self, system):
        check_rotating_frame(system)
        self.__dict__.update(system.__dict__)  # the same parts and buffers: a view
        self.axis = np.asarray(system.joint.axis, float)
        self._A = cross_matrix(self.axis)

    def velocity(self, y, info, omega: float) -> np.ndarray:
        f = self.apply_mobility(y, info.G)
        subtract_rotation(f, self, info, omega, self.axis, self._A)
        f[self.i_phi] = omega
        return f
