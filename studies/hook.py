"""Tables of docs/hook.md from the hook sweeps (issue 15).

    flagwrap sweep examples/sweeps/hook.toml        # M_c per helix and hook stiffness
    flagwrap sweep examples/sweeps/hook-grid.toml   # final states at 1, 2, 4, 8 x the line
    python studies/hook.py                          # prints both tables (markdown)

Columns: the helix (psi, n, R/L), the joint (clamp or k_h = A_h L/(A l_h)), M_c with its
bracket and the ratio to the clamp's, the states of the boundary search's test runs, and the
grid's state at each multiple of the paper's scaling line 0.06 (R/L)^-3.
"""

from __future__ import annotations

import math


def main():
    from flagwrap.plotting.hook import BOUNDARY_SWEEP, GRID_SWEEP, boundary_table, state_rows

    table = boundary_table(BOUNDARY_SWEEP)
    clamp = {(r["psi_deg"], r["turns"]): r["machin_c"] for r in table if r["hook_stiffness"] is None}
    print("| helix (psi, n, R/L) | joint | M_c | bracket | x clamp | test runs (M: state) |")
    print("|---|---|---:|---|---:|---|")
    for r in table:
        ref = clamp.get((r["psi_deg"], r["turns"]))
        joint = "clamp" if r["hook_stiffness"] is None else f"hook k_h = {r['hook_stiffness']:g}"
        mc = f"{r['machin_c']:.0f}" if r["machin_c"] else "-"
        br = (f"{r['m_lo']:.0f}-{r['m_hi']:.0f}" if r["m_lo"] and r["m_hi"] else
              f"{'>' + format(r['m_lo'], '.0f') if r['m_lo'] else '<' + format(r['m_hi'], '.0f')}")
        x = f"{r['machin_c'] / ref:.2f}" if r["machin_c"] and ref else "-"
        runs = ", ".join(f"{run['machin']:.0f}: {run['state']}" for run in r["runs"])
        print(f"| {r['psi_deg']:.3g}, {r['turns']:g}, {r['r_over_l']:.4f} | {joint} | {mc} | {br} | {x} | {runs} |")
    grid = state_rows(GRID_SWEEP)
    if not grid:
        return
    print()
    ratios = sorted({round(g["machin"] / (0.06 * g["r_over_l"] ** -3), 6) for g in grid})
    print("| helix (psi, n) | joint | " + " | ".join(f"M = {q:g} x line" for q in ratios) + " |")
    print("|---|---|" + "---|" * len(ratios))
    keys = sorted({(g["psi_deg"], g["turns"], g["hook_stiffness"] if g["hook_stiffness"] is not None else math.inf)
                   for g in grid}, key=lambda k: (k[0], k[1], -k[2]))
    for psi, n, kh in keys:
        cells = []
        for q in ratios:
            hit = [g for g in grid if g["psi_deg"] == psi and g["turns"] == n
                   and (g["hook_stiffness"] if g["hook_stiffness"] is not None else math.inf) == kh
                   and abs(g["machin"] / (0.06 * g["r_over_l"] ** -3) - q) < 1e-6 * q]
            cells.append(f"{hit[0]['state']} (M {hit[0]['machin']:.0f})" if hit else "-")
        joint = "clamp" if kh == math.inf else f"k_h = {kh:g}"
        print(f"| {psi:.3g}, {n:g} | {joint} | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()
