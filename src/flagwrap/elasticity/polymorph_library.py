"""The polymorph library: flagellar polymorphs (helix radius, pitch, handedness) and the
torque-induced transitions between them, each number with its source.

The data live in ``flagwrap/data/polymorphs.toml`` (docs/polymorph.md). Every number is a
table ``{value, status, source[, note]}`` with ``status`` one of ``published``, ``derived``,
``assumption`` (a value no source prints for this organism, chosen for a stated reason: the
note must say it), ``gap``; a gap has no value and is kept as ``None`` (never filled in). Validation raises a
one-line :class:`UserInputError` naming the key and the allowed range: an unknown polymorph
name, a polymorph without ``radius_um`` or ``pitch_um`` (a value or an explicit gap), a
transition torque of the wrong sign, a domain-wall width below the bead spacing.

Torques follow Hotani (J. Mol. Biol. 156, 791, 1982): the forward transformation (``from``
-> ``to``, normal -> semicoiled) at a negative torque, the reverse at a positive one.
"""

from __future__ import annotations

import math
import sys
from collections.abc import Mapping
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import Any

from flagwrap.elasticity.polymorph import check_wall_resolution, helix_curvature_torsion
from flagwrap.errors import UserInputError

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    import tomli as tomllib

__all__ = ["STATUSES", "Sourced", "Polymorph", "Transition", "PolymorphLibrary",
           "parse_library", "default_library", "load_library_file"]

#: allowed provenance statuses
STATUSES = ("published", "derived", "assumption", "gap")
#: most a length in um or a torque in pN um may be (a physical value, not a typo)
_MAX = 1e6


@dataclass(frozen=True)
class Sourced:
    """One library value with where it comes from; ``value`` is ``None`` for a gap."""

    value: Any
    status: str
    source: str
    note: str = ""


@dataclass(frozen=True)
class Polymorph:
    """A helical polymorph. ``radius_um``/``pitch_um``/``handedness`` carry ``value None``
    where the library has a gap."""

    key: str
    organism: str
    form: str
    handedness: Sourced
    radius_um: Sourced
    pitch_um: Sourced

    @property
    def known(self) -> bool:
        """Whether radius, pitch and handedness all have values."""
        return None not in (self.radius_um.value, self.pitch_um.value, self.handedness.value)

    def curvature_torsion_per_um(self) -> tuple[float, float]:
        """Helix curvature and torsion [1/um] (:func:`helix_curvature_torsion`), or a
        one-line error naming the gap."""
        for name in ("radius_um", "pitch_um", "handedness"):
            if getattr(self, name).value is None:
                raise UserInputError(f"polymorph {self.key!r}: {name} is a gap in the library "
                                     f"({getattr(self, name).source}); give it explicitly")
        return helix_curvature_torsion(self.radius_um.value, self.pitch_um.value,
                                       self.handedness.value)


@dataclass(frozen=True)
class Transition:
    """A torque-induced transformation ``source_form -> target_form`` with its hysteresis."""

    key: str
    from_key: str
    to_key: str
    torque_forward_pn_um: Sourced
    torque_back_pn_um: Sourced
    wall_width_um: Sourced

    def wall_width(self, bead_spacing_um: float, wall_width_um: float | None = None) -> float:
        """The domain-wall width [um]: ``wall_width_um`` if given, else the library's, checked
        against the bead spacing (one line naming the key if below it or a gap)."""
        w = wall_width_um if wall_width_um is not None else self.wall_width_um.value
        name = f"transition {self.key!r}: wall_width_um"
        if w is None:
            raise UserInputError(f"{name} is a gap in the library ({self.wall_width_um.note or self.wall_width_um.source}); "
                                 f"give it (in [{bead_spacing_um:g}, inf) um, the bead spacing up)")
        return check_wall_resolution(w, bead_spacing_um, name)


@dataclass(frozen=True)
class PolymorphLibrary:
    polymorphs: tuple[Polymorph, ...]
    transitions: tuple[Transition, ...]
    bending_stiffness_pn_um2: Sourced | None = None

    def polymorph(self, key: str) -> Polymorph:
        for p in self.polymorphs:
            if p.key == key:
                return p
        raise UserInputError(f"unknown polymorph {key!r}; allowed: "
                             f"{', '.join(p.key for p in self.polymorphs)}")

    def transition(self, key: str) -> Transition:
        for t in self.transitions:
            if t.key == key:
                return t
        raise UserInputError(f"unknown polymorph transition {key!r}; allowed: "
                             f"{', '.join(t.key for t in self.transitions) or '(none)'}")


def _sourced(where: str, name: str, entry: Any, kind: str = "number",
             lo: float = 0.0, hi: float = _MAX, unit: str = "") -> Sourced:
    """One ``{value, status, source, note}`` table validated; ``kind`` is ``number`` (in the
    open interval ``(lo, hi)``) or ``handedness``."""
    label = f"{where}: {name}"
    if not isinstance(entry, Mapping):
        raise UserInputError(f"{label} must be a table {{value, status, source}}, got {entry!r}")
    status = entry.get("status")
    if status not in STATUSES:
        raise UserInputError(f"{label}: status must be one of {STATUSES}, got {status!r}")
    source = entry.get("source")
    if not isinstance(source, str) or not source.strip():
        raise UserInputError(f"{label} needs a non-empty 'source' string")
    note = str(entry.get("note", ""))
    if status == "gap":
        if "value" in entry:
            raise UserInputError(f"{label} has status 'gap' but a value; drop one")
        return Sourced(None, status, source, note)
    if "value" not in entry:
        raise UserInputError(f"{label} needs a 'value' (or status = \"gap\")")
    if status == "assumption" and not note.strip():
        raise UserInputError(f"{label} has status 'assumption': its 'note' must say why this value")
    v = entry["value"]
    if kind == "handedness":
        if v not in ("left", "right"):
            raise UserInputError(f"{label} must be 'left' or 'right', got {v!r}")
        return Sourced(v, status, source, note)
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
        raise UserInputError(f"{label} must be a finite number, got {v!r}")
    if not lo < v < hi:
        u = f" {unit}" if unit else ""
        raise UserInputError(f"{label} must be in ({lo:g}, {hi:g}){u}, got {v!r}")
    return Sourced(float(v), status, source, note)


def _key(where: str, raw: Mapping) -> str:
    key = raw.get("key")
    if not isinstance(key, str) or not key.strip():
        raise UserInputError(f"{where}: needs a non-empty string 'key'")
    return key.strip()


def parse_library(document: Mapping[str, Any], origin: str = "<toml>") -> PolymorphLibrary:
    """Build a :class:`PolymorphLibrary` from a parsed TOML document."""
    raw_p = document.get("polymorph")
    if not isinstance(raw_p, list) or not raw_p or not all(isinstance(r, Mapping) for r in raw_p):
        raise UserInputError(f"{origin}: needs at least one [[polymorph]] table")
    polys = []
    for k, raw in enumerate(raw_p):
        key = _key(f"{origin}: polymorph[{k}]", raw)
        where = f"{origin}: polymorph {key!r}"
        fields = {}
        for name in ("handedness", "radius_um", "pitch_um"):
            if name not in raw:
                allowed = "'left' or 'right'" if name == "handedness" else "in (0, 1e+06) um"
                raise UserInputError(f"{where}: {name} is missing; give a value {allowed} with its "
                                     "status and source, or status = \"gap\" with a source")
            fields[name] = _sourced(where, name, raw[name],
                                    "handedness" if name == "handedness" else "number", unit="um")
        polys.append(Polymorph(key=key, organism=str(raw.get("organism", "")),
                               form=str(raw.get("form", "")), **fields))
    keys = [p.key for p in polys]
    dup = sorted({k for k in keys if keys.count(k) > 1})
    if dup:
        raise UserInputError(f"{origin}: duplicate polymorph keys {dup}")
    trans = []
    raw_t = document.get("transition", [])
    if not isinstance(raw_t, list) or not all(isinstance(r, Mapping) for r in raw_t):
        raise UserInputError(f"{origin}: [[transition]] entries must be tables")
    for k, raw in enumerate(raw_t):
        key = _key(f"{origin}: transition[{k}]", raw)
        where = f"{origin}: transition {key!r}"
        for end in ("from", "to"):
            if raw.get(end) not in keys:
                raise UserInputError(f"{where}: {end} = {raw.get(end)!r} is not a polymorph of the "
                                     f"library; allowed: {', '.join(keys)}")
        if raw["from"] == raw["to"]:
            raise UserInputError(f"{where}: from and to are the same polymorph {raw['from']!r}")
        for name in ("torque_forward_pn_um", "torque_back_pn_um", "wall_width_um"):
            if name not in raw:
                raise UserInputError(f"{where}: {name} is missing; give {{value, status, source}} "
                                     "or {status = \"gap\", source}")
        fwd = _sourced(where, "torque_forward_pn_um", raw["torque_forward_pn_um"],
                       lo=-_MAX, hi=0.0, unit="pN um (negative: Hotani's sign for from -> to)")
        back = _sourced(where, "torque_back_pn_um", raw["torque_back_pn_um"],
                        lo=0.0, hi=_MAX, unit="pN um (positive: Hotani's sign for to -> from)")
        width = _sourced(where, "wall_width_um", raw["wall_width_um"], unit="um")
        trans.append(Transition(key, raw["from"], raw["to"], fwd, back, width))
    tkeys = [t.key for t in trans]
    dup = sorted({k for k in tkeys if tkeys.count(k) > 1})
    if dup:
        raise UserInputError(f"{origin}: duplicate transition keys {dup}")
    stiff = document.get("bending_stiffness_pn_um2")
    stiff = None if stiff is None else _sourced(origin, "bending_stiffness_pn_um2", stiff,
                                                unit="pN um^2")
    return PolymorphLibrary(tuple(polys), tuple(trans), stiff)


def default_library() -> PolymorphLibrary:
    """The packaged ``flagwrap/data/polymorphs.toml``."""
    text = resources.files("flagwrap").joinpath("data/polymorphs.toml").read_text(encoding="utf-8")
    return parse_library(tomllib.loads(text), "flagwrap/data/polymorphs.toml")


def load_library_file(path: str | Path) -> PolymorphLibrary:
    """A user library of the packaged schema; a missing or malformed file is one line."""
    p = Path(path)
    try:
        doc = tomllib.loads(p.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise UserInputError(f"polymorph library not found: {p}") from None
    except (IsADirectoryError, UnicodeDecodeError):
        raise UserInputError(f"{p} is not a UTF-8 TOML polymorph library") from None
    except OSError as exc:
        raise UserInputError(f"{p} cannot be read: {exc.strerror or exc}") from None
    except tomllib.TOMLDecodeError as exc:
        raise UserInputError(f"{p}: invalid TOML: {exc}") from None
    return parse_library(doc, str(p))
