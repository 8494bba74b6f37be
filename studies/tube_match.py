"""The bead chain matched to a slender tube against slender-body theory (docs/bacterium.md,
"The chain matched to a tube"; issue 35). Prints the section's tables (~10 s):

    python studies/tube_match.py

1. The matched parameters (a_h / a, kappa) and the sphere chain's radii over b / a.
2. The bacterial helix of the issue (R 0.2, P 2.3, L 7 um, a 10 nm): A, B, D of the bead
   helix, spheres (a_h = a) and tube, against Johnson's slender body of radius a (blunt
   profile p = 12, length L), over the bead count.
3. A rigid swimmer: that helix on a free sphere of radius 0.5 um (0.1 um gap), speed, body
   rotation and motor torque from each helix's 6x6 matrix with the sphere's exact drag (the
   sphere-helix interaction left out of both), against slender-body theory's.
"""

from __future__ import annotations


def main() -> int:
    from flagwrap.body.multiblob import resistance_matrix
    from flagwrap.hydrodynamics.mobility import RPYMobility
    from flagwrap.hydrodynamics.tube import TubeMobility, tube_chain
    from flagwrap.theory.slender_body import (bead_helix, blunt_profile, chain_effective_radii,
                                              helix_centreline, johnson_resistance,
                                              propulsion_coefficients,
                                              sphere_and_helix_swimmer)

    print("| b / a | spheres: r_par / a | r_perp / a | tube: a_h / a | kappa |")
    print("|---:|---:|---:|---:|---:|")
    for ba in (2.6, 3.5, 4.44, 6.5, 7.0, 10.0, 14.0, 20.0):
        rp, rn = chain_effective_radii(1.0, ba)
        tc = tube_chain(1.0, ba)
        print(f"| {ba:g} | {rp:.3f} | {rn:.3f} | {tc.bead_radius:.3f} | {tc.kappa:.3f} |")

    L, R, P, a = 7.0, 0.2, 2.3, 0.01
    ref = johnson_resistance(helix_centreline(L, R, P), blunt_profile(a, L, 12), n=96)
    A0, B0, D0 = propulsion_coefficients(ref)
    centre = (0.0, 0.0, 0.5 + 0.1 + L / 2)
    s0 = sphere_and_helix_swimmer(ref, 0.5, centre)
    print(f"\nslender-body theory (viscosity 1, um): A = {A0:.4f}, B = {B0:.5f}, D = {D0:.5f}; "
          f"swimmer per unit motor rate: speed {s0[0]:.5f} um, body {s0[1]:+.5f}, "
          f"torque {s0[2]:.4f}")
    print("\n| N | b / a | beads | A | B | D | speed | body rotation | motor torque |")
    print("|---:|---:|---|---:|---:|---:|---:|---:|---:|")
    for N in (51, 71, 101, 151, 201):
        b = L / (N - 1)
        x, _ = bead_helix(L, R, P, N)
        for model in ("spheres", "tube"):
            if model == "tube":
                tc = tube_chain(a, b)
                mob, ah = TubeMobility(RPYMobility(tc.bead_radius), [(0, N)], tc.kappa), tc.bead_radius
            else:
                mob, ah = RPYMobility(a), a
            Rb = resistance_matrix(x, ah, mobility=mob.matrix(x))
            A, B, D = propulsion_coefficients(Rb)
            s = sphere_and_helix_swimmer(Rb, 0.5, centre)
            print(f"| {N} | {b / a:.2f} | {model} | {A / A0 - 1:+.3f} | {B / B0 - 1:+.3f} | "
                  f"{D / D0 - 1:+.3f} | {s[0] / s0[0] - 1:+.3f} | {s[1] / s0[1] - 1:+.3f} | "
                  f"{s[2] / s0[2] - 1:+.3f} |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
