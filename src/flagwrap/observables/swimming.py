"""A free swimmer's observables from its run file: the filament in the body's frame, and per
motor phase the swimming speed, the body's counter-rotation, the motor's rate, the
displacement per motor turn, the motor's power and the Lighthill efficiency
(``flagwrap analyze``; docs/bacterium.md, "Efficiency").

Efficiency. Lighthill's (Lighthill 1975, *Mathematical Biofluiddynamics*; Purcell, Proc.
Natl. Acad. Sci. 94, 11307 (1997)): the power it would take to tow the cell body alone at
the swimming speed, over the power the motor delivers, ``eta = zeta U^2 / <sum_k N_k
Omega_k>``, ``zeta`` the body's translational drag along its axis in free space (its blobs'
resistance, :func:`body_drag`), ``N_k`` and ``Omega_k`` each motor's torque and rate relative
to the body. The free-space drag also beside a wall or in a tube: the efficiency then
compares the same useful work with what confinement costs the motor.

Rates come from differences of the recorded pose and motor angle over the second half of each
phase, not from the recorded instantaneous velocities: those are derivatives of a stiff
state, which carry its error times the stiffness (docs/bacterium.md, "Checks").
"""

from __future__ import annotations

import math

import numpy as np

from flagwrap.geometry.frames import quaternion_matrix as quaternion_matrices  # (n, 4) -> (n, 3, 3)


def body_frame(position: np.ndarray, body_position: np.ndarray,
               body_orientation: np.ndarray) -> np.ndarray:
    """Bead positions (time, bead, 3) in the body's frame: ``x' = R^T (x - X)``."""
    R = quaternion_matrices(np.asarray(body_orientation, float))
    d = np.asarray(position, float) - np.asarray(body_position, float)[:, None, :]
    return np.einsum("tji,tbj->tbi", R, d)


def _rotation_angle_about(R0: np.ndarray, R1: np.ndarray, axis: np.ndarray) -> float:
    """Angle [rad] of the rotation ``R1 R0^T`` projected on ``axis`` (its rotation vector's
    component along it), for a rotation below pi."""
    D = R1 @ R0.T
    c = max(-1.0, min(1.0, 0.5 * (np.trace(D) - 1.0)))
    th = math.acos(c)
    if th < 1e-12:
        return 0.0
    v = np.array([D[2, 1] - D[1, 2], D[0, 2] - D[2, 0], D[1, 0] - D[0, 1]]) / (2 * math.sin(th))
    return float(th * (v @ axis))


def turn_angles(R: np.ndarray, axes: np.ndarray) -> np.ndarray:
    """The body's turn [rad] between successive frames ``R`` (F, 3, 3), each about its own
    axis ``axes`` (F - 1, 3) (:func:`_rotation_angle_about`)."""
    return np.array([_rotation_angle_about(R[k], R[k + 1], axes[k]) for k in range(len(R) - 1)])


def body_drag(config) -> float:
    """The cell body's translational drag along its axis in free space [N s/m]: ``R_zz`` of
    its blobs' resistance (:func:`flagwrap.body.multiblob.resistance_matrix`, viscosity 1,
    lengths in L) times ``eta L``."""
    from flagwrap.body.multiblob import cell_body_blobs, resistance_matrix

    blobs, radii = cell_body_blobs(config)
    Rzz = resistance_matrix(blobs, radii[0])[2, 2]
    return float(Rzz * config.fluid.viscosity * config.filament.length)


def motor_power(ds) -> np.ndarray:
    """The motors' power ``sum_k N_k Omega_k`` (time,) [W] from a run file: each motor's
    torque and rate relative to the body (``motor_torques``/``motor_rates`` for several
    flagella, else ``motor_torque``/``omega``); positive when the motors do work on the
    fluid."""
    if "motor_torques" in ds.variables:
        return (ds["motor_torques"].values * ds["motor_rates"].values).sum(axis=1)
    return ds["motor_torque"].values * ds["omega"].values


def screw_progress(X: np.ndarray, R: np.ndarray, axis: np.ndarray) -> float:
    """The translation along the screw axis of the rigid motion from pose ``(X[0], R[0])`` to
    ``(X[1], R[1])`` (Chasles' theorem: every rigid motion is a rotation about an axis and a
    translation along it; the translation is the same for every body point), signed + along
    ``axis``. Over a whole period of a periodic swimmer it is the progress along the axis of
    its helical path (Purcell, Am. J. Phys. 45, 3 (1977)), whatever the window's start: a
    wobbling cell's body-axis displacement depends on the phase its window starts at. Without
    rotation (below 1e-9 rad) the displacement along ``axis``; the axis from scipy's rotation
    vector (a half turn included)."""
    from scipy.spatial.transform import Rotation

    d = np.asarray(X[1], float) - np.asarray(X[0], float)
    w = Rotation.from_matrix(np.asarray(R[1], float) @ np.asarray(R[0], float).T).as_rotvec()
    s = np.linalg.norm(w)
    if s < 1e-9:
        return float(d @ axis)
    n = w / s
    return float(d @ n) * (1.0 if n @ axis >= 0 else -1.0)


def phase_summary(t, phi, body_position, body_orientation, t0, t1, power=None,
                  drag: float | None = None) -> dict:
    """The swimmer over ``[t0, t1]`` (SI: s, rad, m): its speed along the body axis (+ = body
    first, away from the filament) [m/s], the body's rotation rate about its axis [Hz] (+ =
    right-handed about the body axis +z, the sense opposite to a CCW motor), the motor's
    rate relative to the body [Hz] and the displacement along the axis per motor turn [m];
    with the motors' ``power`` (time,) [W] (:func:`motor_power`) its mean over the window
    [W], and with the body's ``drag`` [N s/m] too (:func:`body_drag`) the Lighthill
    efficiency ``drag speed^2 / power`` (module docstring)."""
    t = np.asarray(t, float)
    k = np.flatnonzero((t >= t0 - 1e-12 * abs(t1)) & (t <= t1 + 1e-12 * abs(t1)))
    nan = float("nan")
    if len(k) < 2:
        return dict(speed=nan, screw_speed=nan, screw_efficiency=nan, body_rotation_hz=nan,
                    motor_rate_hz=nan, displacement_per_turn=nan, motor_power=nan, efficiency=nan)
    i, j = k[0], k[-1]
    R = quaternion_matrices(np.asarray(body_orientation, float)[[i, j]])
    axis = R[0][:, 2] + R[1][:, 2]
    axis /= np.linalg.norm(axis)
    dt = t[j] - t[i]
    dX = float((np.asarray(body_position)[j] - np.asarray(body_position)[i]) @ axis)
    Rk = quaternion_matrices(np.asarray(body_orientation, float)[k])
    ang = sum(turn_angles(Rk, np.broadcast_to(axis, (len(Rk) - 1, 3))))  # pieces below pi
    dphi = float(np.asarray(phi)[j] - np.asarray(phi)[i])
    P = nan
    if power is not None:  # the time average, trapezoids over the saved frames
        pw = np.asarray(power, float)[k]
        P = float(np.sum(0.5 * (pw[1:] + pw[:-1]) * np.diff(t[k])) / dt)
    def lighthill(U):
        return drag * U ** 2 / P if drag is not None and P > 0 else nan

    screw = screw_progress(np.asarray(body_position)[[i, j]], R, axis) / dt
    return dict(speed=dX / dt, screw_speed=screw, screw_efficiency=lighthill(screw),
                body_rotation_hz=ang / dt / (2 * math.pi),
                motor_rate_hz=dphi / dt / (2 * math.pi),
                displacement_per_turn=dX / (abs(dphi) / (2 * math.pi)) if dphi else nan,
                motor_power=P, efficiency=lighthill(dX / dt))


def swimming_summary(ds, final_turns: float = 1.0) -> list[dict]:
    """One :func:`phase_summary` per motor phase of a free swimmer's run file (the second half
    of each phase), with the phase's direction, then one over the run's last ``final_turns``
    reference turns (direction "final": the settled state, e.g. the wrapped mode, without the
    transient that a phase's second half may still hold); an empty list for a fixed body."""
    if "body_position" not in ds.variables:
        return []
    from flagwrap.io.runfile import config_of
    from flagwrap.motor.protocol import Schedule

    cfg = config_of(ds)
    sched = Schedule(cfg.motor.protocol)
    T = 1.0 / cfg.scales.omega  # core time unit [s]
    t = ds["time"].values
    extra = dict(power=motor_power(ds), drag=body_drag(cfg))
    out = []
    for seg in sched.segments:
        t0, t1 = seg.t0 * T, min(seg.t1 * T, float(t[-1]))
        if t1 <= t0:
            break
        row = phase_summary(t, ds["motor_angle"].values, ds["body_position"].values,
                            ds["body_orientation"].values, 0.5 * (t0 + t1), t1, **extra)
        row.update(direction=seg.label, t0=t0, t1=t1)
        out.append(row)
    t1 = float(t[-1])
    t0 = max(float(t[0]), t1 - 2 * math.pi * final_turns * T)
    row = phase_summary(t, ds["motor_angle"].values, ds["body_position"].values,
                        ds["body_orientation"].values, t0, t1, **extra)
    row.update(direction="final", t0=t0, t1=t1)
    out.append(row)
    return out
