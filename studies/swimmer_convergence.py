"""The rigid swimmer's convergence with the blob resolution (docs/bacterium.md).

    python studies/swimmer_convergence.py      # prints the tables (markdown), ~30 s

The Fig. 4(a) helix (its 59 free beads, core units: lengths in L, viscosity 1, motor rate
omega = 1 about a = (0, 0, -1)) on a rigid blob body, solved by
:func:`flagwrap.body.rigid_swimmer.rigid_swimmer`:

1. a sphere of hydrodynamic radius R_s = 0.125, lowest point at the origin, at icosphere
   levels 1-4. Blob radius: half the *mean* nearest-neighbour distance (as in the sphere table
   of docs/bacterium.md). The blob shape is scaled as a whole, so R_t is proportional to the
   shell radius R_g, and one evaluation of ``effective_radii`` on the unit shell gives the
   R_g that makes R_t = R_s exactly: every level is the same hydrodynamic sphere.
2. the paper's capped cylinder (radius 0.125, cylinder 0.625), blob spacing 0.08 to 0.021,
   blob radius half the spacing (the default rule), no radius adjustment.
3. the same bodies without hydrodynamic interaction between body and helix:
   V_B = -(R_B + R_H)^-1 R_H omega [0; a], each R from its own spheres (the sphere's R_B
   exact: 6 pi R_s, 8 pi R_s^3 about its centre).

Reported: U.a (the swimming speed along a; negative: the cell moves body first, toward +z),
the body's Omega_z (counter-rotation), the motor torque tau, |U_lateral| (the velocity of the
origin across the axis, mostly the body's wobble), the relative change from the previous
resolution, the observed order and the Richardson-extrapolated value from the finest three
(and, as a check on it, the two finest extrapolated at the nearest integer order).
"""

from __future__ import annotations

import math
import sys
import time
from pathlib import Path

import numpy as np
from scipy.optimize import brentq
from scipy.spatial import cKDTree

R_S = 0.125  # sphere's hydrodynamic radius, cylinder's radius (L)
CYL_LENGTH = 0.625
SPACINGS = (0.08, 0.06, 0.042, 0.03, 0.021)
DEFAULT_SPACING = 0.042  # R_cell / 3
LEVELS = (1, 2, 3, 4)
AXIS = np.array([0.0, 0.0, -1.0])


def helix():
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
    from conftest import make_config

    from flagwrap.system.rod_system import RodSystem

    s = RodSystem(make_config())
    return np.ascontiguousarray(s.x0[s.nc:]), float(s.radius)


def solve(body, ab, H, a):
    """One swimmer: its numbers, the min bead-blob distance over (a_b + a), seconds."""
    from flagwrap.body.rigid_swimmer import rigid_swimmer

    t = time.perf_counter()
    r = rigid_swimmer(body, ab, H, a, axis=AXIS, omega=1.0)
    dt = time.perf_counter() - t
    assert r.residual_force < 1e-9 and r.residual_torque < 1e-9
    gap = cKDTree(body).query(H)[0].min() / (ab + a)
    return {"U": r.speed(AXIS), "Om": float(r.Omega[2]), "tau": r.tau,
            "lat": float(np.hypot(r.U[0], r.U[1])), "gap": gap, "s": dt}


def no_hi(RB, RH):
    """V_B without body-helix interaction: -(R_B + R_H)^-1 R_H omega [0; a]."""
    V = -np.linalg.solve(RB + RH, RH @ np.concatenate([np.zeros(3), AXIS]))
    return {"U": float(V[:3] @ AXIS), "Om": float(V[5])}


def sphere_resistance(R, centre):
    """Exact resistance of a sphere of radius R at ``centre``, about the origin."""
    c = np.asarray(centre, float)
    X = np.array([[0, -c[2], c[1]], [c[2], 0, -c[0]], [-c[1], c[0], 0.0]])  # [c]_x
    ft, fr = 6 * math.pi * R, 8 * math.pi * R ** 3
    # F = ft (U + Omega x c);  T about 0 = c x F + fr Omega
    Rm = np.zeros((6, 6))
    Rm[:3, :3] = ft * np.eye(3)
    Rm[:3, 3:] = -ft * X
    Rm[3:, :3] = ft * X
    Rm[3:, 3:] = -ft * X @ X + fr * np.eye(3)
    return Rm


def order_and_limit(h, f):
    """Observed order p of f = f_inf + C h^p from the last three points, and f_inf."""
    (h1, h2, h3), (f1, f2, f3) = h[-3:], f[-3:]
    q = (f1 - f2) / (f2 - f3)
    if not q > 0:
        return math.nan, math.nan
    def g(p):
        return (h1 ** p - h2 ** p) / (h2 ** p - h3 ** p) - q

    try:
        p = brentq(g, 0.05, 12.0)
    except ValueError:
        return math.nan, math.nan
    return p, limit_at(h, f, p)


def limit_at(h, f, p):
    """Richardson's f_inf from the last two points at order p."""
    (h2, h3), (f2, f3) = h[-2:], f[-2:]
    return f3 - (f2 - f3) * h3 ** p / (h2 ** p - h3 ** p)


def local_orders(h, f):
    return [order_and_limit(h[k - 2:k + 1], f[k - 2:k + 1])[0] for k in range(2, len(f))]


KEYS = (("U", "U.a"), ("Om", "Omega_z"), ("tau", "tau"))


def table(rows, first_cols, h):
    """The per-resolution table, then order / extrapolation per quantity."""
    head = [c for c, _ in first_cols] + ["min gap / (a_b + a)"]
    for _, name in KEYS:
        head += [name, "rel. change"]
    head += ["abs U_lateral", "solve s"]
    print("| " + " | ".join(head) + " |")
    print("|" + "---:|" * len(head))
    for k, r in enumerate(rows):
        cells = [fmt(r) for _, fmt in first_cols] + [f"{r['gap']:.2f}"]
        for key, _ in KEYS:
            rel = "-" if k == 0 else f"{(r[key] - rows[k - 1][key]) / r[key]:+.1e}"
            cells += [f"{r[key]:.6g}", rel]
        cells += [f"{r['lat']:.5f}", f"{r['s']:.2f}"]
        print("| " + " | ".join(cells) + " |")
    print()
    print("| quantity | observed order (successive triples) | extrapolated (finest three) | "
          "finest - extrap. (rel.) | extrapolated at the integer order |")
    print("|---|---|---:|---:|---:|")
    out = {}
    for key, name in KEYS:
        f = [r[key] for r in rows]
        p, lim = order_and_limit(h, f)
        pi = round(p)
        lim_i = limit_at(h, f, pi)
        orders = ", ".join("-" if math.isnan(x) else f"{x:.2f}" for x in local_orders(h, f))
        out[key] = (p, lim, lim_i)
        print(f"| {name} | {orders} | {lim:.6g} | {(f[-1] - lim) / lim:+.1e} | "
              f"{lim_i:.6g} (p = {pi}) |")
    print()
    return out


def cylinder_rows(make_body, H, a, RH):
    """The rigid swimmer on ``make_body(spacing)`` (blob radius half the spacing) at every
    spacing; with ``RH`` also the swimmer without body-helix interaction."""
    from flagwrap.body.multiblob import nearest_spacing, resistance_matrix

    rows = []
    for sp in SPACINGS:
        body = make_body(sp)
        r = solve(body, 0.5 * sp, H, a)
        r.update(n=len(body), sp=sp, ratio=nearest_spacing(body) / (0.5 * sp))
        if RH is not None:
            ref = no_hi(resistance_matrix(body, 0.5 * sp), RH)
            r.update(noU=ref["U"], noOm=ref["Om"])
        rows.append(r)
    return rows


def report_default(rows, cyl, how: str) -> None:
    d = next(r for r in rows if r["sp"] == DEFAULT_SPACING)
    print(f"Default spacing {DEFAULT_SPACING:g} L ({d['n']} blobs){how} against the "
          "extrapolation (observed order / integer order): "
          + ", ".join(f"{name} {(d[k] - cyl[k][1]) / cyl[k][1]:+.1e} / "
                      f"{(d[k] - cyl[k][2]) / cyl[k][2]:+.1e}" for k, name in KEYS) + "\n")


def main():
    from flagwrap.body.multiblob import (
        capped_cylinder_blobs,
        effective_radii,
        nearest_spacing,
        resistance_matrix,
        sphere_blobs,
    )
    from flagwrap.hydrodynamics.mobility import RPYMobility

    t0 = time.perf_counter()
    H, a = helix()
    RH = resistance_matrix(H, a, mobility=RPYMobility(a).matrix(H))
    print(f"helix: {len(H)} free beads, a = {a:g} L; omega = 1 about a = (0, 0, -1)\n")

    # 1. the sphere
    print(f"## Sphere, R_t = R_s = {R_S:g} L, lowest point at the origin\n")
    rows = []
    for lev in LEVELS:
        u = sphere_blobs(1.0, lev)
        nn = cKDTree(u).query(u, k=2)[0][:, 1]
        ab1 = 0.5 * nn.mean()
        Rt1, Rr1 = effective_radii(u, ab1)
        Rg = R_S / Rt1  # R_t scales with the shape
        body = Rg * u + np.array([0.0, 0.0, R_S])
        r = solve(body, ab1 * Rg, H, a)
        r.update(n=len(u), ab=ab1 * Rg, Rg=Rg, rr=Rr1 / Rt1,
                 ratio=nearest_spacing(u) / ab1)
        rows.append(r)
    cols = [("blobs", lambda r: f"{r['n']}"), ("a_b", lambda r: f"{r['ab']:.5f}"),
            ("R_g", lambda r: f"{r['Rg']:.5f}"), ("R_r / R_t", lambda r: f"{r['rr']:.4f}"),
            ("widest gap / a_b", lambda r: f"{r['ratio']:.2f}")]
    sph = table(rows, cols, [r["ab"] for r in rows])
    ref = no_hi(sphere_resistance(R_S, (0.0, 0.0, R_S)), RH)
    print(f"No body-helix interaction (exact sphere R_s): U.a = {ref['U']:.6g}, "
          f"Omega_z = {ref['Om']:.6g}; with it (extrapolated) / without: "
          f"U {sph['U'][1] / ref['U']:.4f}, Omega_z {sph['Om'][1] / ref['Om']:.4f}\n")

    # 2. the paper's capped cylinder
    print(f"## Capped cylinder, radius {R_S:g} L, cylinder {CYL_LENGTH:g} L, "
          "blob radius = spacing / 2\n")
    rows = cylinder_rows(lambda sp: capped_cylinder_blobs(R_S, CYL_LENGTH, sp), H, a, RH)
    cols = [("spacing", lambda r: f"{r['sp']:g}"), ("blobs", lambda r: f"{r['n']}"),
            ("widest gap / a_b", lambda r: f"{r['ratio']:.2f}")]
    report_default(rows, table(rows, cols, [r["sp"] for r in rows]), "")
    # 2b. the same, blobs inset by BLOB_INSET a_b (what the simulator's cell_body_blobs does)
    from flagwrap.body.multiblob import BLOB_INSET, inset_capped_cylinder_blobs

    print(f"## Capped cylinder, blobs inset by {BLOB_INSET:g} a_b (the simulator's cell body)\n")
    rows_in = cylinder_rows(lambda sp: inset_capped_cylinder_blobs(R_S, CYL_LENGTH, sp, 0.5 * sp),
                            H, a, None)
    report_default(rows_in, table(rows_in, cols, [r["sp"] for r in rows_in]), ", inset,")
    print("No body-helix interaction (each body's own R):\n")
    print("| spacing | U.a, no HI | U.a / no HI | Omega_z, no HI | Omega_z / no HI |")
    print("|---:|---:|---:|---:|---:|")
    for r in rows:
        print(f"| {r['sp']:g} | {r['noU']:.6g} | {r['U'] / r['noU']:.4f} | {r['noOm']:.6g} | "
              f"{r['Om'] / r['noOm']:.4f} |")
    print(f"\ntotal {time.perf_counter() - t0:.0f} s")


if __name__ == "__main__":
    main()
