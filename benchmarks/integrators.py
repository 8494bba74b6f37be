"""Fast stepper (ROS34PW2, the default) against the paper-style explicit Euler reference, Fig. 4(a) case, HI on.

Run: ``python benchmarks/integrators.py [--quick]``

Measured in one process, on one core (BLAS limited to one thread):

1. explicit Euler with the default springs k = 1000 A/b^3 at its largest stable step (found by
   doubling until the run blows up, then halving once), timed over a fraction of a turn;
2. the default stepper (ROS34PW2, tol 1e-5) over the full protocol, 10 CCW + 10 CW turns;
3. a converged solution (tol = 1e-6) of the same protocol: the free-end trajectory of (2)
   must stay within 1 % of L and the motor torque within 2 % over the first CW turn;
4. the Euler reference and a converged ROS2 solution agree over the Euler window;
5. the fast stepper over the full protocol with the hydrodynamic interactions off.

Prints wall seconds per simulated motor turn for both and ``ratio: X`` = Euler / ROS34PW2 (the default stepper of 2).
``--quick`` runs 2 + 2 turns instead of 10 + 10 (for a smoke test of the script).
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import time

import numpy as np
from threadpoolctl import threadpool_limits

from flagwrap.cases import get_case
from flagwrap.integrators import ROS2, ExplicitEuler
from flagwrap.system.rod_system import RodSystem
from flagwrap.params import Phase
from flagwrap.simulation import Simulation

TWO_PI = 2 * math.pi


def case(ccw, cw, tol=None):
    cfg = get_case("fig4a")
    motor = dataclasses.replace(cfg.motor, protocol=(Phase("ccw", ccw), Phase("cw", cw)))
    num = cfg.numerics if tol is None else dataclasses.replace(cfg.numerics, tol=tol)
    return cfg.replace(motor=motor, numerics=num)


def euler_window(system, dt, n_steps):
    """n_steps of explicit Euler at fixed dt (core time units); returns (ok, wall, x, torque)."""
    integ = ExplicitEuler()
    y = system.initial_y()
    info = system.forces(y, system.frames0)
    t0 = time.perf_counter()
    for _ in range(n_steps):
        r = integ.step(system, y, info.frames, info, dt, 1.0)
        if not r.accepted:
            return False, time.perf_counter() - t0, None, None
        y, info = r.y, r.info
        strain = np.abs(np.linalg.norm(np.diff(info.x, axis=0), axis=1) / system.rest.l0 - 1).max()
        if not np.isfinite(strain) or strain > 0.05:
            return False, time.perf_counter() - t0, None, None
    wall = time.perf_counter() - t0
    return True, wall, info.x, system.motor_torque(info, y[-1], 1.0)


def largest_stable_dt(system, start=1e-9, probe_steps=3000):
    """Double dt (in turns) until Euler blows up within probe_steps; return the last stable."""
    dt = start
    last_ok = None
    while dt < 1e-4:
        ok, *_ = euler_window(system, dt * TWO_PI, probe_steps)
        if not ok:
            break
        last_ok = dt
        dt *= 2
    return last_ok


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true")
    args = ap.parse_args()
    turns = 2 if args.quick else 10
    with threadpool_limits(1):
        cfg = case(turns, turns)
        sys_e = RodSystem(cfg)
        print(f"case fig4a: N = {cfg.filament.n_beads}, M = {cfg.machin:.4g}, HI on, "
              f"k_s = {cfg.filament.stretch_stiffness:g} A/b^3, T = {cfg.scales.period:.1f} s")
        # -- 1. explicit Euler reference
        dt_e = largest_stable_dt(sys_e)
        dt_e *= 0.5  # margin below the blow-up step
        n_e = 20000
        ok, wall_e, x_e, tq_e = euler_window(sys_e, dt_e * TWO_PI, n_e)
        assert ok, "Euler reference unstable at half its probed limit"
        per_turn_e = wall_e / (n_e * dt_e)
        print(f"euler: dt = {dt_e:.3g} T ({dt_e * cfg.scales.period:.3g} s), {n_e} steps in "
              f"{wall_e:.2f} s -> {per_turn_e:.4g} s per motor turn")
        # -- 4. Euler vs converged ROS2 over the Euler window
        sim = Simulation(cfg.replace(motor=dataclasses.replace(
            cfg.motor, protocol=(Phase("ccw", n_e * dt_e),))), integrator=ROS2(tol=1e-7))
        tr = sim.run()
        dx = np.abs(np.asarray(tr.x)[-1] - x_e).max()
        print(f"euler vs ROS2(tol=1e-7) after {n_e * dt_e:.3g} turns: max |dx| = {dx:.2e} L, "
              f"torque {tq_e:.6g} vs {tr.motor_torque[-1]:.6g}")
        # -- 2. fast stepper, full protocol
        t0 = time.perf_counter()
        fast = Simulation(cfg).run()
        wall_f = time.perf_counter() - t0
        assert fast.ok, fast.message
        per_turn_f = wall_f / (2 * turns)
        print(f"{cfg.numerics.integrator} (tol = {cfg.numerics.tol:g}): {2 * turns} turns, {fast.n_steps} steps "
              f"({fast.n_rejected} rejected) in {wall_f:.1f} s -> {per_turn_f:.3g} s per motor turn")
        # -- 3. accuracy against a converged solution
        t0 = time.perf_counter()
        ref = Simulation(case(turns, turns, tol=1e-6)).run()
        wall_r = time.perf_counter() - t0
        a, b = fast.arrays(), ref.arrays()
        n = min(len(a["t"]), len(b["t"]))
        assert np.allclose(a["t"][:n], b["t"][:n])
        tip_err = np.abs(a["x"][:n, -1] - b["x"][:n, -1]).max()
        turn = a["t"][:n] / TWO_PI
        win = (turn > turns) & (turn <= turns + 1)
        tq_err = np.abs(a["motor_torque"][:n][win] - b["motor_torque"][:n][win]).max() / np.abs(
            b["motor_torque"][:n][win]).max()
        print(f"converged reference (tol = 1e-6): {ref.n_steps} steps in {wall_r:.1f} s")
        print(f"accuracy: max free-end deviation {tip_err:.2e} L (target 1e-2), "
              f"first-CW-turn torque deviation {tq_err:.2%} (target 2 %)")
        # -- 5. the same full protocol without hydrodynamic interactions (banded LU)
        cfg_off = cfg.replace(numerics=dataclasses.replace(cfg.numerics, hydrodynamics=False))
        t0 = time.perf_counter()
        off = Simulation(cfg_off).run()
        wall_off = time.perf_counter() - t0
        assert off.ok, off.message
        print(f"HI off, {cfg.numerics.integrator}: {2 * turns} turns, {off.n_steps} steps "
              f"({off.n_rejected} rejected) in {wall_off:.1f} s")
        print(f"wall per turn: euler {per_turn_e:.4g} s, {cfg.numerics.integrator} {per_turn_f:.4g} s")
        print(f"ratio: {per_turn_e / per_turn_f:.0f}")


if __name__ == "__main__":
    main()
