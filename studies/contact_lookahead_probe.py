"""A probe for the constriction study's stall (docs/confinement.md, "C. insecticola into a
constriction"): resume a run from its checkpoint with the stage matrix ``W``'s boundary
contact stiffness looked ahead ``DELTA`` nm (:data:`flagwrap.interactions.wall.STAGE_LOOKAHEAD`
sets the package's own, half the contact law's repulsive shell: 1.1 nm here), or with
``DELTA = exact``: the exact Hessian in ``W`` and no pose block for the body's blobs (the
package's ``W`` before the lookahead). The forces are the same in every case, and a W-method
keeps its order for any ``W``: only the steps differ. Patches the package for this process
only: a measurement, not a feature.

Run: ``timeout -s TERM 240 python studies/contact_lookahead_probe.py CHECKPOINT DELTA``
(DELTA in nm, ``package`` or ``exact``); prints how far the run got before the signal.
"""
import sys
import time
import tomllib

from flagwrap.interactions.wall import _BoundaryContact
from flagwrap.io.checkpoint import read_checkpoint
from flagwrap.io.config import config_from_dict
from flagwrap.simulation import TWO_PI, RunInterrupted, Simulation
from flagwrap.system.swimmer import SwimmerSystem

ck = read_checkpoint(sys.argv[1])
mode = sys.argv[2]
cfg = config_from_dict(tomllib.loads(ck.config_toml))
L = cfg.filament.length
if mode == "exact":
    _BoundaryContact.stage_law = _BoundaryContact.law
    SwimmerSystem.pose_stiffness = lambda self, y: None
elif mode != "package":
    delta = float(mode) * 1e-9 / L
    _init = _BoundaryContact.__init__

    def init(self, *args, **kw):
        _init(self, *args, **kw)
        self.lookahead = delta
        self._k_ahead = float(self.law([self.cutoff - delta])[2][0])
    _BoundaryContact.__init__ = init
sim = Simulation(cfg)
t0, n0, r0 = ck.t, ck.n_steps, ck.n_rejected
start = time.perf_counter()
try:
    tr = sim.run(resume=ck)
except RunInterrupted as exc:
    tr = exc.trajectory
print(f"W {mode}: t/T {t0 / TWO_PI:.4f} -> {tr.t[-1] / TWO_PI:.4f} in "
      f"{time.perf_counter() - start:.0f} s; {tr.n_steps - n0} steps, "
      f"{tr.n_rejected - r0} rejected", flush=True)
