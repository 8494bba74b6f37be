"""What the memory and scale benchmarks share: a case run in a fresh Python process on one
thread, whose last stdout line is a JSON record (``run``), and the prelude of its code
(imports, the studies on the path, ``rss_kb`` for the resident memory now)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = str(ROOT / "examples" / "p_putida_bundle.toml")

PRELUDE = f"""
import dataclasses, json, resource, sys, time
sys.path.insert(0, {str(ROOT / "studies")!r})
from bundle_vs_equivalent import case_config
from flagwrap.io.config import load_config
from flagwrap.params import Phase
from flagwrap.simulation import Simulation, make_system

def rss_kb():
    for line in open("/proc/self/status"):
        if line.startswith("VmRSS:"):
            return int(line.split()[1])
"""

ONE_THREAD = {"OMP_NUM_THREADS": "1", "NUMBA_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1",
              "MKL_NUM_THREADS": "1"}


def run(code: str) -> dict:
    """``PRELUDE + code`` in a fresh process on one thread: its last stdout line as JSON; a
    failure raises ``SystemExit`` with the child's last stderr line."""
    out = subprocess.run([sys.executable, "-c", PRELUDE + code], capture_output=True,
                         text=True, env={**os.environ, **ONE_THREAD}, check=False)
    if out.returncode:
        raise SystemExit(out.stderr.strip().splitlines()[-1])
    return json.loads(out.stdout.strip().splitlines()[-1])
