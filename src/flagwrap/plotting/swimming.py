"""A free swimmer's run at a glance (``flagwrap analyze RUN.nc --figure PNG``).

Three panels against time [s], the CCW -> CW switches marked: (a) the body's displacement
along its initial axis [um] (+ body first); (b) the motor's rate relative to the body and the
body's rotation about its own axis [Hz], from differences of the recorded angles; (c) the
free end's height above the pole in the body's frame, ``(z'(L) - z'(0))/L`` (the buckling
observable of docs/analysis.md, seen from the body).
"""

from __future__ import annotations

import numpy as np


def swimming_series(ds) -> dict:
    """Time series of a free swimmer's run dataset (SI): ``t``, ``displacement`` along the
    initial body axis, ``motor_hz`` and ``body_hz`` (rates between saved frames, at their
    midpoints ``t_mid``), ``height`` (T, flagella) of each free end in the body frame over L."""
    from flagwrap.io.runfile import filament_slices
    from flagwrap.observables.swimming import body_frame, quaternion_matrices, turn_angles
    from flagwrap.observables.tip import free_end_heights

    t = ds["time"].values
    X = ds["body_position"].values
    R = quaternion_matrices(ds["body_orientation"].values)
    e0 = R[0][:, 2]
    disp = (X - X[0]) @ e0
    phi = ds["motor_angle"].values
    dt = np.diff(t)
    turn = turn_angles(R, 0.5 * (R[:-1, :, 2] + R[1:, :, 2]))
    xb = body_frame(ds["position"].values, X, ds["body_orientation"].values)
    L = float(ds.attrs["length"])
    return dict(t=t, displacement=disp, t_mid=0.5 * (t[1:] + t[:-1]),
                motor_hz=np.diff(phi) / dt / (2 * np.pi), body_hz=turn / dt / (2 * np.pi),
                height=free_end_heights(xb, L, filament_slices(ds)))


def plot_swimming(ds, path):
    """Draw the three panels (module docstring) to ``path`` (PNG or PDF)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from flagwrap.io.atomic import atomic_write

    s = swimming_series(ds)
    om = ds["omega"].values
    switches = s["t"][1:][np.diff(np.sign(om)) != 0]
    fig, ax = plt.subplots(3, 1, figsize=(6.0, 6.4), sharex=True)
    ax[0].plot(s["t"], s["displacement"] * 1e6, color="C0")
    ax[0].set_ylabel("displacement [um]\n(+ body first)")
    ax[1].plot(s["t_mid"], s["motor_hz"], color="C3", label="motor (relative to body)")
    ax[1].plot(s["t_mid"], s["body_hz"], color="C2", label="body about its axis")
    ax[1].axhline(0, color="0.7", lw=0.6)
    ax[1].set_ylabel("rate [Hz]")
    ax[1].legend(fontsize=7, frameon=False)
    many = s["height"].shape[1] > 1
    for k, h in enumerate(s["height"].T):  # one line per flagellum
        ax[2].plot(s["t"], h, color=f"C{k}" if many else "k",
                   label=f"flagellum {k}" if many else None)
    if many:
        ax[2].legend(fontsize=7)
    ax[2].set_ylabel("free-end height\n(body frame) / L")
    ax[2].set_xlabel("t [s]")
    for a in ax:
        for ts in switches:
            a.axvline(ts, color="0.5", ls="--", lw=0.7)
    ax[0].set_title(f"{ds.attrs.get('title', '')}", fontsize=8)
    fig.tight_layout()
    suffix = str(path).rsplit(".", 1)[-1]
    atomic_write(path, lambda tmp: fig.savefig(tmp, dpi=150, format=suffix))
    plt.close(fig)
    return path
