"""TOML <-> :class:`flagwrap.params.Config`, strictly.

Unknown sections or keys, wrong types and impossible values raise
:class:`~flagwrap.errors.UserInputError` naming the key, before any work starts. Nothing is
evaluated: TOML values are data only.

Units: SI by default. An optional ``[units]`` table rescales inputs, e.g.
``length = "mm"`` (lengths of ``filament`` and ``body``), ``pressure = "MPa"`` (Young's
modulus), ``viscosity = "mPa s"``, ``density = "g/cm3"``, ``torque = "pN nm"`` (the motor's
stall torque), ``bending = "pN um2"`` (the hook's bending and twist moduli). A bacterium is
given in um, pN and Hz (examples/s_putrefaciens.toml).
"""

from __future__ import annotations

import dataclasses
import math
import sys
from pathlib import Path

import numpy as np

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

from flagwrap.errors import UserInputError
from flagwrap.params import (CellBody, Clamp, Config, Contact, Filament, Flagellum, Fluid,
                             Initial, Joint, Motor, Numerics, Phase, Polymorph, TubeWall, Wall)

_SECTIONS = {
    "filament": Filament,
    "fluid": Fluid,
    "body": CellBody,
    "motor": Motor,
    "contact": Contact,
    "numerics": Numerics,
    "clamp": Clamp,
    "initial": Initial,
    "joint": Joint,
    "polymorph": Polymorph,
}
_LENGTH = {"m": 1.0, "mm": 1e-3, "um": 1e-6, "micron": 1e-6, "nm": 1e-9}
_PRESSURE = {"Pa": 1.0, "kPa": 1e3, "MPa": 1e6, "GPa": 1e9}
_VISCOSITY = {"Pa s": 1.0, "mPa s": 1e-3, "cP": 1e-3}
_DENSITY = {"kg/m3": 1.0, "g/cm3": 1e3}
_TORQUE = {"N m": 1.0, "pN nm": 1e-21, "pN um": 1e-18}
_BENDING = {"N m2": 1.0, "pN um2": 1e-24, "pN nm2": 1e-30}
_UNIT_KEYS = ("bending", "density", "length", "pressure", "torque", "viscosity")
_LENGTH_KEYS = {
    "filament": ("length", "helix_radius", "pitch", "cross_section_radius", "hydrodynamic_radius"),
    "body": ("radius", "cylinder_length", "blob_spacing", "blob_radius"),
    "initial": ("perturbation",),
    "joint": ("hook_length",),
}


def _show(key) -> str:
    """A key as it can be printed on one line: plain names as they are, anything else repr'd."""
    return key if isinstance(key, str) and key.isidentifier() else repr(key)


def _fields(cls):
    return {f.name: f for f in dataclasses.fields(cls)}


def _check_types(section: str, cls, table: dict):
    if not isinstance(table, dict):
        raise UserInputError(f"[{section}] must be a table, got {type(table).__name__}")
    known = _fields(cls)
    for key, value in table.items():
        if key not in known:
            raise UserInputError(
                f"unknown key {section}.{_show(key)}; allowed: {', '.join(sorted(known))}"
            )
        if isinstance(value, (dict, list)) and not (section == "motor" and key == "protocol"):
            raise UserInputError(f"{section}.{key} must be a single value, got {type(value).__name__}")
        if isinstance(value, float) and not math.isfinite(value):
            raise UserInputError(f"{section}.{key} must be finite, got {value}")
        # the field's declared kind: a quoted number or a number where a name belongs is
        # refused here, by name, before it reaches arithmetic
        kind = str(known[key].type)
        if kind in ("float", "float | None", "int") and not _is_number(value):
            raise UserInputError(f"{section}.{key} must be a number, got {_show(value)} "
                                 f"({type(value).__name__})")
        if kind == "int" and not isinstance(value, int):
            raise UserInputError(f"{section}.{key} must be an integer, got {value!r}")
        if kind == "str" and not isinstance(value, str):
            raise UserInputError(f"{section}.{key} must be a name (a string), got {value!r}")
        if kind == "bool" and not isinstance(value, bool):
            raise UserInputError(f"{section}.{key} must be true or false, got {_show(value)}")


def _is_number(v) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool)


def _unit(table: dict, key: str, choices: dict, default: str) -> float:
    name = table.get(key, default)
    if not isinstance(name, str) or name not in choices:
        raise UserInputError(f"units.{key} must be one of {', '.join(choices)}, got {name!r}")
    return choices[name]


def config_from_dict(data: dict, name: str | None = None) -> Config:
    if not isinstance(data, dict):
        raise UserInputError("config must be a TOML table")
    data = dict(data)
    allowed_top = set(_SECTIONS) | {"units", "name", "flagellum", "wall", "tube"}
    for key in data:
        if key not in allowed_top:
            raise UserInputError(f"unknown section or key {key!r}; allowed: {', '.join(sorted(allowed_top))}")
    u = data.pop("units", {}) or {}
    if not isinstance(u, dict):
        raise UserInputError("[units] must be a table")
    for key in u:
        if key not in _UNIT_KEYS:
            raise UserInputError(
                f"unknown key units.{_show(key)}; allowed: {', '.join(_UNIT_KEYS)}")
    lf = _unit(u, "length", _LENGTH, "m")
    pf = _unit(u, "pressure", _PRESSURE, "Pa")
    vf = _unit(u, "viscosity", _VISCOSITY, "Pa s")
    df = _unit(u, "density", _DENSITY, "kg/m3")
    tf = _unit(u, "torque", _TORQUE, "N m")
    bf = _unit(u, "bending", _BENDING, "N m2")
    for req in ("filament", "motor"):
        if req not in data:
            raise UserInputError(f"missing required section [{req}]")
    kwargs = {}
    for section, cls in _SECTIONS.items():
        table = data.get(section, {})
        _check_types(section, cls, table)
        table = dict(table)
        scale = dict.fromkeys(_LENGTH_KEYS.get(section, ()), lf)
        if section == "filament":
            scale.update(youngs_modulus=pf, density=df)
        if section == "fluid":
            scale.update(viscosity=vf, density=df)
        if section == "motor":
            scale.update(stall_torque=tf)
        if section == "joint":
            scale.update(hook_bending_modulus=bf, hook_twist_modulus=bf)
        if section == "polymorph":
            # the barrier is an energy per length, a force: bending / length^2 (pN um2 / um2
            # = pN in bacterial units)
            scale.update(stiffness=bf, barrier=bf / lf**2, maxwell_torque=tf,
                         domain_wall_width=lf)
        for key, factor in scale.items():
            # numbers only: a bool times a factor would become a float and pass validation
            if _is_number(table.get(key)):
                table[key] = table[key] * factor
        if section == "motor" and "protocol" in table:
            table["protocol"] = _phases(table["protocol"], "motor.protocol")
        try:
            kwargs[section] = cls(**table)
        except TypeError as exc:  # missing required fields
            msg = str(exc)
            missing = msg.split("argument")[-1].strip(": ") if "missing" in msg else msg
            raise UserInputError(f"[{section}] is missing required value(s): {missing}") from None
    if "flagellum" in data:
        kwargs["flagella"] = _flagella(data["flagellum"], lf, tf)
    if "wall" in data:
        kwargs["walls"] = _walls(data["wall"], lf)
    if "tube" in data:
        kwargs["tubes"] = _tubes(data["tube"], lf)
    nm = data.get("name", name or "run")
    if not isinstance(nm, str) or not nm:
        raise UserInputError("name must be a non-empty string")
    return Config(name=nm, **kwargs)


def _phases(prot, where: str) -> tuple:
    """A protocol: an array of phase tables -> :class:`~flagwrap.params.Phase` s."""
    if not isinstance(prot, list):
        raise UserInputError(f"{where} must be an array of tables")
    phases = []
    for k, p in enumerate(prot):
        if not isinstance(p, dict):
            raise UserInputError(f"{where}[{k}] must be a table")
        _check_types(f"{where}[{k}]", Phase, p)
        missing = [f for f in ("direction", "turns") if f not in p]
        if missing:
            raise UserInputError(f"{where}[{k}] is missing {', '.join(missing)}")
        phases.append(Phase(**p))
    return tuple(phases)


def _flagella(tables, lf: float, tf: float = 1.0) -> tuple:
    """``[[flagellum]]`` tables -> :class:`~flagwrap.params.Flagellum` s (``anchor`` in the
    length unit ``lf``, ``stall_torque`` in the torque unit ``tf``); a problem names the
    table, ``flagellum[k].key``."""
    if not isinstance(tables, list) or not all(isinstance(t, dict) for t in tables):
        raise UserInputError("flagellum must be an array of tables: [[flagellum]] per flagellum")
    if not tables:
        raise UserInputError("flagellum = []: zero flagella; give at least one [[flagellum]] "
                             "table, or none for one flagellum at the pole")
    known = _fields(Flagellum)
    out = []
    for k, t in enumerate(tables):
        where = f"flagellum[{k}]"
        for key, value in t.items():
            if key not in known:
                raise UserInputError(f"unknown key {where}.{_show(key)}; allowed: "
                                     f"{', '.join(sorted(known))}")
            if key == "protocol":
                continue
            if isinstance(value, dict) or (isinstance(value, list) and key not in ("anchor", "axis")):
                raise UserInputError(f"{where}.{key} must be a single value")
        t = dict(t)
        if "protocol" in t:
            t["protocol"] = _phases(t["protocol"], f"{where}.protocol")
        if isinstance(t.get("anchor"), list) and all(_is_number(c) for c in t["anchor"]):
            t["anchor"] = [c * lf for c in t["anchor"]]
        if _is_number(t.get("stall_torque")):
            t["stall_torque"] = t["stall_torque"] * tf
        try:
            out.append(Flagellum(**t))
        except UserInputError as exc:
            raise UserInputError(str(exc).replace("flagellum", where, 1)) from None
    return tuple(out)


def _boundary_tables(tables, cls, name: str, scale) -> tuple:
    """``[[name]]`` tables -> ``cls`` instances: unknown keys refused, ``scale(t)`` converts a
    table's lengths in place, a problem names the table, ``name[k].key``."""
    if not isinstance(tables, list) or not all(isinstance(t, dict) for t in tables):
        raise UserInputError(f"{name} must be an array of tables: [[{name}]] per {name}")
    known = _fields(cls)
    out = []
    for k, t in enumerate(tables):
        where = f"{name}[{k}]"
        for key in t:
            if key not in known:
                raise UserInputError(f"unknown key {where}.{_show(key)}; allowed: "
                                     f"{', '.join(sorted(known))}")
        t = dict(t)
        scale(t)
        try:
            out.append(cls(**t))
        except UserInputError as exc:
            raise UserInputError(str(exc).replace(name, where, 1)) from None
    return tuple(out)


def _scale_vector(t: dict, key: str, lf: float) -> None:
    if isinstance(t.get(key), list) and all(_is_number(c) for c in t[key]):
        t[key] = [c * lf for c in t[key]]


def _walls(tables, lf: float) -> tuple:
    """``[[wall]]`` tables -> :class:`~flagwrap.params.Wall` s (``point`` in the length unit
    ``lf``)."""
    return _boundary_tables(tables, Wall, "wall", lambda t: _scale_vector(t, "point", lf))


#: [[tube]] keys that are lengths (in the [units] length unit)
_TUBE_LENGTHS = ("radius", "length", "constriction_radius", "constriction_length",
                 "constriction_center", "blob_spacing")


def _tubes(tables, lf: float) -> tuple:
    """``[[tube]]`` tables -> :class:`~flagwrap.params.TubeWall` s (lengths and ``center`` in
    the length unit ``lf``)."""
    def scale(t):
        for key in _TUBE_LENGTHS:
            if _is_number(t.get(key)):
                t[key] = t[key] * lf
        _scale_vector(t, "center", lf)

    return _boundary_tables(tables, TubeWall, "tube", scale)


def load_config_or_case(name) -> Config:
    """A TOML file if ``name`` is one, else the built-in case of that name
    (:data:`flagwrap.cases.CASES`), so that every command and the API take both; neither is
    one line naming both."""
    from flagwrap.cases import CASES, get_case

    path = Path(name)
    if path.is_file() or str(name) not in CASES:
        if not path.is_file():
            if path.suffix == ".toml" and path.stem in CASES:  # examples/hook.toml outside a checkout
                raise UserInputError(f"config file not found: {path}; the built-in case "
                                     f"{path.stem!r} is the shipped copy of examples/{path.name}: "
                                     f"give {path.stem} instead")
            raise UserInputError(f"config file not found: {path} (a built-in case instead: "
                                 f"{', '.join(sorted(CASES))}; `flagwrap run --list-cases`)")
        return load_config(path)
    return get_case(str(name))


def load_config(path) -> Config:
    """Read a TOML config file; every problem is a one-line :class:`UserInputError`."""
    path = Path(path)
    if not path.is_file():
        raise UserInputError(f"config file not found: {path}")
    try:
        with open(path, "rb") as fh:
            data = tomllib.load(fh)
    except tomllib.TOMLDecodeError as exc:
        raise UserInputError(f"malformed TOML in {path}: {exc}") from None
    except UnicodeDecodeError:
        raise UserInputError(f"{path} is not a UTF-8 text file") from None
    return config_from_dict(data, name=path.stem)


_TOML_ESCAPES = {"\\": "\\\\", '"': '\\"', "\b": "\\b", "\t": "\\t", "\n": "\\n",
                 "\f": "\\f", "\r": "\\r"}


def _toml_value(v) -> str:
    if isinstance(v, (bool, np.bool_)):
        return "true" if v else "false"
    # numpy's scalars (a float64 is a float) print as "np.float64(...)", which TOML cannot read
    if isinstance(v, (int, np.integer)):
        return repr(int(v))
    if isinstance(v, (float, np.floating)):
        return repr(float(v))
    if isinstance(v, str):
        # a TOML basic string: backslash, quote and every control character escaped
        return '"' + "".join(_TOML_ESCAPES.get(ch) or (f"\\u{ord(ch):04x}" if ord(ch) < 0x20
                                                          or ord(ch) == 0x7F else ch)
                             for ch in v) + '"'
    raise TypeError(type(v))


def _toml_protocol(phases) -> str:
    items = ", ".join("{ " + ", ".join(f"{pk} = {_toml_value(pv)}" for pk, pv in p.items()) + " }"
                      for p in phases)
    return f"protocol = [{items}]"


def config_to_toml(cfg: Config, for_hash: bool = False) -> str:
    """Serialise a config (SI units) to TOML text that :func:`load_config` reads back.

    ``for_hash``: the text result keys are computed from (see ``Config.to_dict``)."""
    d = cfg.to_dict(for_hash=for_hash)
    lines = [f"name = {_toml_value(d.pop('name'))}", ""]
    for section in ("filament", "fluid", "body", "motor", "clamp", "contact", "numerics", "initial",
                    "joint", "polymorph"):
        if section in ("initial", "joint", "polymorph") and section not in d:
            continue  # omitted from the hashed text while it holds its defaults
        table = d.get(section, {})
        lines.append(f"[{section}]")
        for k, v in table.items():
            if k == "protocol":
                lines.append(_toml_protocol(v))
            else:
                lines.append(f"{k} = {_toml_value(v)}")
        lines.append("")
    for table in d.get("wall", []):
        lines.append("[[wall]]")
        for k, v in table.items():
            lines.append(f"{k} = [{', '.join(_toml_value(c) for c in v)}]")
        lines.append("")
    for table in d.get("tube", []):
        lines.append("[[tube]]")
        for k, v in table.items():
            if isinstance(v, (list, tuple)):
                lines.append(f"{k} = [{', '.join(_toml_value(c) for c in v)}]")
            else:
                lines.append(f"{k} = {_toml_value(v)}")
        lines.append("")
    for table in d.get("flagellum", []):
        lines.append("[[flagellum]]")
        for k, v in table.items():
            if k == "protocol":
                lines.append(_toml_protocol(v))
            elif isinstance(v, (list, tuple)):
                lines.append(f"{k} = [{', '.join(_toml_value(c) for c in v)}]")
            else:
                lines.append(f"{k} = {_toml_value(v)}")
        lines.append("")
    return "\n".join(lines)
