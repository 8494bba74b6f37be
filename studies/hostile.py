"""Run the hostile-input table of tests/unit/test_cli_hostile.py through the real command line
and print a markdown table of the outcomes (docs/robustness.md, "Hostile commands").

    python studies/hostile.py                        # this checkout
    PYTHONPATH=/path/to/old/src python studies/hostile.py --label "before"   # another version

Each row runs as its own process (``python -m flagwrap.cli.main``) with a 60 s time limit and a
4 GB address-space limit (an old version grew to 17 GB on one of them), in a fresh folder laid
out like the test's fixture; "changed" = a file that existed before differs afterwards.
"""

from __future__ import annotations

import argparse
import importlib.util
import resource
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _load_table():
    sys.path.insert(0, str(ROOT / "tests"))
    spec = importlib.util.spec_from_file_location("hostile", ROOT / "tests/unit/test_cli_hostile.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def _limit():
    resource.setrlimit(resource.RLIMIT_AS, (4 << 30, 4 << 30))


def _world(mod, d: Path):
    """The fixture's files, made with the flagwrap found on the path of this process."""
    return mod.make_world(d)


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--label", default="now")
    a = p.parse_args()
    mod = _load_table()
    print(f"| # | command | {a.label}: exit | traceback | changed | stderr (last line, cut) |")
    print("|---|---|---|---|---|---|")
    counts = {"ok": 0, "bad": 0}
    for i, (argv, needle) in enumerate(mod.HOSTILE):
        with tempfile.TemporaryDirectory() as tmp:
            d = Path(tmp)
            _world(mod, d)
            before = mod._snapshot(d)
            args = [x.format(d=d) for x in argv]
            try:
                r = subprocess.run([sys.executable, "-m", "flagwrap.cli.main", *args], capture_output=True,
                                   text=True, timeout=60, preexec_fn=_limit, cwd=d)
                code, err = r.returncode, r.stderr
            except subprocess.TimeoutExpired as exc:
                code, err = "timeout", (exc.stderr or b"").decode() if isinstance(exc.stderr, bytes) else (exc.stderr or "")
            changed = [k for k, v in before.items() if mod._snapshot(d).get(k) != v]
            tb = "Traceback" in err or "MemoryError" in err
            last = (err.strip().splitlines() or [""])[-1].replace("|", "/").replace(str(d), "D")[:110]
            good = code == 2 and not tb and not changed and needle in err
            counts["ok" if good else "bad"] += 1
            shown = " ".join(x.replace(str(d), "D") for x in args)
            print(f"| {i} | `flagwrap {shown}` | {code} | {'yes' if tb else 'no'} | "
                  f"{', '.join(changed) or '-'} | {last} |", flush=True)
    print(f"\n{a.label}: {counts['ok']} of {len(mod.HOSTILE)} rows are a one-line exit-2 error naming the "
          f"problem with nothing changed; {counts['bad']} are not.")


if __name__ == "__main__":
    main()
