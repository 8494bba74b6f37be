"""A probe for the constriction study's stall (docs/confinement.md, "C. insecticola into a
constriction"): resume a run from its checkpoint with the tube contact's stiffness in the
stage matrix W looked ahead ``DELTA`` nm into the contact (each bead within DELTA of the cut-off
gets the stiffness it would have DELTA inside; the forces are unchanged, and a W-method keeps
its order for any W). Patches the package for this process only: a measurement, not a feature.

Run: ``timeout -s TERM 200 python studies/contact_lookahead_probe.py CHECKPOINT DELTA``
(DELTA = 0: the package's own W); prints how far the run got before the signal.
"""
import re
import sys
import time

import numpy as np

from flagwrap.io.checkpoint import read_checkpoint
from flagwrap.io.config import config_from_dict, config_to_toml

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib
import flagwrap.interactions.wall as iw
from flagwrap.simulation import TWO_PI, RunInterrupted, Simulation

ck = read_checkpoint(sys.argv[1]); delta_nm = float(sys.argv[2])
# (a checkpoint written before run files stored numpy scalars as numbers)
cfg = config_from_dict(tomllib.loads(re.sub(r"np\.float64\(([^)]*)\)", r"\1", ck.config_toml)))
ck.config_toml = config_to_toml(cfg)
L = cfg.filament.length
if delta_nm > 0:
    d = delta_nm * 1e-9 / L
    orig_h = iw._BoundaryContact.law
    def hess(self, x, theta, _orig=iw.TubeContact.hessian_coo):
        def law2(g):
            e, dU, d2U = orig_h(self, g)
            near = g < self.cutoff + d
            if near.any():
                _, _, k2 = orig_h(self, np.minimum(g[near], self.cutoff - d))
                d2U = d2U.copy()
                d2U[near] = np.maximum(d2U[near], k2)
            return e, dU, d2U
        self.law = law2
        try:
            return _orig(self, x, theta)
        finally:
            del self.law
    iw.TubeContact.hessian_coo = hess
sim = Simulation(cfg)
t0, n0, r0 = ck.t, ck.n_steps, ck.n_rejected
start = time.perf_counter()
try:
    tr = sim.run(resume=ck)
except RunInterrupted as exc:
    tr = exc.trajectory
print(f"delta {delta_nm} nm: t/T {t0 / TWO_PI:.4f} -> {tr.t[-1] / TWO_PI:.4f} in {time.perf_counter() - start:.0f} s; {tr.n_steps - n0} steps, {tr.n_rejected - r0} rejected", flush=True)
