"""Built-in cases: the TOML configs shipped with the package (``flagwrap/data/cases``).

Every ``flagwrap/data/cases/<name>.toml`` is a case called ``<name>``, usable wherever a
config path is (``flagwrap run hook``, ``flagwrap stability fig4a``, ``flagwrap.run("hook")``),
so a wheel install without the repository has every example. In a checkout
``examples/<name>.toml`` is a link to the same file: one copy, the package's.

The paper cases (``fig4a``, ``fig4b``, ``movie2`` ... ``movie7``): geometry from the SI movie
list and figure captions; the motor speed is set by the Machin number where the main text
prints it (Fig. 4), else by the SI frequency. Where the paper's numbers disagree (e.g. Fig.
4(a)'s M = 283 against SI Movie 3's f = 0.006 Hz, which gives M = 178), the printed
main-text value wins and the disagreement is listed in docs/model.md. The rest are the
hooked helix and the bacteria (docs/hook.md, docs/bacterium.md, docs/bundle.md).
"""

from __future__ import annotations

from functools import partial
from pathlib import Path

from flagwrap.errors import UserInputError

#: the folder of the shipped case files (package data)
CASES_DIR = Path(__file__).resolve().parent / "data" / "cases"


def case_files() -> dict:
    """name -> path of every shipped case file, by name."""
    return {p.stem: p for p in sorted(CASES_DIR.glob("*.toml"))}


def _load(path):
    from flagwrap.io.config import load_config

    return load_config(path)


#: name -> a function returning the case's :class:`~flagwrap.params.Config`
CASES = {name: partial(_load, path) for name, path in case_files().items()}


def describe(name: str, width: int = 100) -> str:
    """What the case is: its file's leading comment on one line, at most ``width`` characters."""
    words = []
    for line in case_files()[name].read_text(encoding="utf-8").splitlines():
        if not line.startswith("#"):
            break
        words += line.lstrip("#").split()
    text = " ".join(words)
    return text if len(text) <= width else text[:width - 3].rstrip() + "..."


def get_case(name: str):
    if name not in CASES:
        raise UserInputError(f"unknown case {name!r}; available: {', '.join(CASES)}")
    return CASES[name]()
