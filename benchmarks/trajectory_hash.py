"""Fingerprint of the Fig. 4(a) trajectory, to compare two commits exactly (issue 15's "same
steps, same numbers"): 1 CCW + 1 CW turn of examples/fig4a.toml (HI on, default numerics),
printing the step counts and a SHA-256 of the saved positions and motor torque.

    python benchmarks/trajectory_hash.py                     # this checkout
    PYTHONPATH=/path/to/other/src python benchmarks/trajectory_hash.py   # another commit

Equal hashes mean bit-identical saved frames (same machine, same thread count), with the
sign of zero left out (``x + 0.0``): a bead at the origin may be -0.0 or +0.0 by the order of
an exact addition, the same number.
"""

import dataclasses
import hashlib
from pathlib import Path

import numpy as np

from flagwrap.io.config import load_config
from flagwrap.params import Phase
from flagwrap.simulation import simulate

cfg = load_config(Path(__file__).resolve().parents[1] / "examples" / "fig4a.toml")
cfg = cfg.replace(motor=dataclasses.replace(cfg.motor, protocol=(Phase("ccw", 1.0), Phase("cw", 1.0))))
traj = simulate(cfg)
a = traj.arrays()
digest = hashlib.sha256(np.ascontiguousarray(a["x"] + 0.0).tobytes()
                        + np.ascontiguousarray(a["motor_torque"] + 0.0).tobytes()).hexdigest()[:16]
print(f"fig4a 1+1 turns: {traj.n_steps} steps ({traj.n_rejected} rejected), frames {len(a['t'])}, "
      f"sha256 {digest}, free end {a['x'][-1, -1]}")
