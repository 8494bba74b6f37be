"""Sweep specification: a TOML file -> a list of dimensionless cases -> SI configs.

A sweep file names the cases by the dimensionless numbers of the paper's Fig. 5:

* geometry: two of ``psi_deg`` (pitch angle psi [deg]), ``turns`` (helical turns n) and
  ``r_over_l`` (R/L); the third follows from ``sin psi = 2 pi n R / L`` (a helix of arclength L
  with n turns of radius R). ``r_over_rcell`` = R / R_cell (default 0.6, the paper's).
* speed: ``machin`` (M = eta omega L^4 / A) or ``omega_ratio_scaling`` = omega / omega_c with
  omega_c from the paper's scaling line, ``M = omega_ratio_scaling * 0.06 (R/L)^-3``.
* ``hi``: hydrodynamic interactions on/off.
* ``density_mismatch``: the filament's ``(rho - rho_f) / rho_f`` (default: density-matched,
  no gravity); ``-0.02`` is 2 % lighter than the fluid, buoyant. With the fixed L below the
  gravity number ``G = (rho_f - rho) g pi a^2 L^3 / A`` is the same for every geometry at a
  given mismatch: ``G = -929.8 x mismatch`` (docs/gravity.md).
* ``hook_stiffness``: a lumped hook (:class:`~flagwrap.params.Joint`) instead of the clamp,
  given as ``k_h = A_h L / (A l_h)``, its bending spring in units of ``A/L`` (the clamp's
  vertex has ``L/b = N - 1``; bacterial hooks ~0.4-4, docs/hook.md), with ``l_h = 0.01 L``
  unless ``[base] joint.hook_length`` says otherwise (default: the clamp, keys unchanged).

Every case becomes an SI :class:`~flagwrap.params.Config` with the paper's material
(a = 1.5 mm, E = 1.5 MPa, nu = 0.49, eta = 1.1 Pa s) and a **fixed** arclength L = 0.4 m, so
that a/L = 1.5/400 for every case (the Fig. 4(a) helix). In the model only M and the geometry
ratios (psi, n, R/L, R/R_cell, a/L, N) matter; a/L enters through the bead size (hydrodynamic
radius, contact range) and is held at the paper's value rather than varied with R/L.

File layout::

    name = "fig5-quick"           # output folder out/sweeps/<name> (default: file stem)
    mode = "grid"                 # "grid" (every case) or "boundary" (M_c per geometry)

    [run]                         # test-run protocol (hashed into every case key)
    ccw_turns = 5.0               # CCW turns before the switch
    cw_turns = 10.0               # K CW turns
    stop_after = 2.0              # stop 2 turns after buckling is detected (false: full run)

    [base]                        # overrides of the config sections (SI), e.g.
    filament = { n_beads = 31 }
    numerics = { tol = 1e-4 }

    [grid]                        # cartesian product of the lists (scalars allowed)
    psi_deg = [33.0, 70.0]
    turns = [2.0, 3.0]
    omega_ratio_scaling = [0.5, 2.0, 8.0]
    hi = [true]

    [[cases]]                     # explicit extra cases (same keys, scalars)
    psi_deg = 70.0
    turns = 2.0
    machin = 600.0

    [boundary]                    # mode = "boundary" only (analysis.critical.CriticalSearch)
    rtol = 0.1
    guess_ratio = 2.0             # first M = guess_ratio * 0.06 (R/L)^-3
    factor = 2.0
    max_runs = 10
"""

from __future__ import annotations

import copy
import hashlib
import itertools
import json
import math
from dataclasses import dataclass, field
from pathlib import Path

from flagwrap.errors import UserInputError

PAPER_PREFACTOR = 0.06
#: the fixed arclength [m] of every sweep case (a/L = 1.5/400, the Fig. 4(a) helix)
LENGTH = 0.4

#: the paper's material and the package's default numerics, SI (the Fig. 4(a) example)
BASE_CONFIG = {
    "filament": {"length": LENGTH, "cross_section_radius": 0.0015, "youngs_modulus": 1.5e6,
                 "poisson_ratio": 0.49, "handedness": "left", "n_beads": 61,
                 "stretch_stiffness": 1000.0},
    "fluid": {"viscosity": 1.1, "density": 1250.0},
    "body": {"radius_ratio": 0.6, "enabled": True},
    "clamp": {"lead": "kink", "lead_turns": 0.5},
    "contact": {"range": 1.0, "strength": 1.0, "potential": "wca-c2"},
    "numerics": {"integrator": "ros34pw2", "hydrodynamics": True, "dt": 1e-3, "tol": 1e-5,
                 "dt_min": 1e-12, "save_every": 0.05, "max_steps": 50_000_000, "threads": 1},
}

GEOMETRY_KEYS = ("psi_deg", "turns", "r_over_l")
SPEED_KEYS = ("machin", "omega_ratio_scaling")
CASE_KEYS = GEOMETRY_KEYS + ("r_over_rcell",) + SPEED_KEYS + ("hi", "density_mismatch",
                                                              "hook_stiffness")
#: hook length of the ``hook_stiffness`` key, as a fraction of L (the paper: l_H/L ~ 1e-2)
HOOK_LENGTH_RATIO = 0.01
RUN_DEFAULTS = {"ccw_turns": 5.0, "cw_turns": 10.0, "stop_after": 2.0}
#: the most cases one sweep file may expand to (checked before the grid is expanded)
MAX_CASES = 100_000
BOUNDARY_DEFAULTS = {"rtol": 0.1, "guess_ratio": 2.0, "factor": 2.0, "max_runs": 10}


def resolve_geometry(psi_deg=None, turns=None, r_over_l=None) -> tuple[float, float, float]:
    """Complete ``(psi [deg], n, R/L)`` from two of them via ``sin psi = 2 pi n R/L``.

    Raises
    ------
    UserInputError
        not exactly two given (or three inconsistent ones), or values out of range.
    """
    given = {k: v for k, v in (("psi_deg", psi_deg), ("turns", turns), ("r_over_l", r_over_l))
             if v is not None}
    for k, v in given.items():
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not (math.isfinite(v) and v > 0):
            raise UserInputError(f"sweep case: {k} must be a finite number > 0, got {v!r}")
    if len(given) < 2:
        raise UserInputError("sweep case: give two of psi_deg, turns, r_over_l "
                             f"(got {', '.join(given) or 'none'})")
    if psi_deg is not None and not psi_deg < 90:
        raise UserInputError(f"sweep case: psi_deg must be in (0, 90), got {psi_deg}")
    if r_over_l is None:
        r_over_l = math.sin(math.radians(psi_deg)) / (2 * math.pi * turns)
    elif turns is None:
        turns = math.sin(math.radians(psi_deg)) / (2 * math.pi * r_over_l)
    else:
        s = 2 * math.pi * turns * r_over_l
        if not s < 1:
            raise UserInputError(f"sweep case: 2 pi n R/L = {s:.4g} must be < 1 (turns={turns}, "
                                 f"r_over_l={r_over_l})")
        psi = math.degrees(math.asin(s))
        if psi_deg is not None and abs(psi - psi_deg) > 1e-6 * psi_deg:
            raise UserInputError(f"sweep case: psi_deg={psi_deg}, turns={turns}, r_over_l={r_over_l} "
                                 f"are inconsistent (sin psi = 2 pi n R/L gives psi = {psi:.6g})")
        psi_deg = psi
    return float(psi_deg), float(turns), float(r_over_l)


def scaling_machin(r_over_l: float, prefactor: float = PAPER_PREFACTOR) -> float:
    """The paper's scaling line ``M_c = 0.06 (R/L)^-3`` (main text, Fig. 5)."""
    return prefactor * r_over_l ** -3


def _merge(base: dict, over: dict) -> dict:
    out = copy.deepcopy(base)
    for k, v in over.items():
        if isinstance(v, dict) and isinstance(out.get(k), dict):
            out[k] = _merge(out[k], v)
        else:
            out[k] = copy.deepcopy(v)
    return out


@dataclass(frozen=True)
class Case:
    """One point of the diagram: geometry, speed, HI, and the run protocol.

    Attributes
    ----------
    psi_deg, turns, r_over_l, r_over_rcell : float
        pitch angle [deg], helical turns n, R/L, R/R_cell.
    machin : float
        M = eta omega L^4 / A.
    hi : bool
        hydrodynamic interactions on.
    density_mismatch : float or None
        ``(rho - rho_f) / rho_f`` of the filament; None: density-matched (no gravity).
    hook_stiffness : float or None
        ``k_h = A_h L / (A l_h)`` of a lumped hook; None: the clamp.
    run : dict
        ``ccw_turns``, ``cw_turns``, ``stop_after`` (None = full run).
    base : dict
        config overrides (SI sections), JSON-able.
    """

    psi_deg: float
    turns: float
    r_over_l: float
    r_over_rcell: float
    machin: float
    hi: bool
    run: dict = field(default_factory=lambda: dict(RUN_DEFAULTS))
    base: dict = field(default_factory=dict)
    runner: str | None = None
    density_mismatch: float | None = None
    hook_stiffness: float | None = None

    @property
    def machin_scaling(self) -> float:
        return scaling_machin(self.r_over_l)

    @property
    def omega_ratio_scaling(self) -> float:
        """``M / (0.06 (R/L)^-3)``: omega / omega_c of the paper's scaling line."""
        return self.machin / self.machin_scaling

    def geometry(self) -> dict:
        """The case without its speed (the key of a boundary search)."""
        g = {"psi_deg": self.psi_deg, "turns": self.turns, "r_over_l": self.r_over_l,
             "r_over_rcell": self.r_over_rcell, "hi": self.hi}
        if self.density_mismatch is not None:  # absent: the keys of density-matched sweeps stay
            g["density_mismatch"] = self.density_mismatch
        if self.hook_stiffness is not None:  # absent: the keys of clamped sweeps stay
            g["hook_stiffness"] = self.hook_stiffness
        return g

    def with_machin(self, machin: float) -> "Case":
        import dataclasses

        return dataclasses.replace(self, machin=float(machin))

    def config_dict(self) -> dict:
        """The full SI config (nested dict for :func:`flagwrap.io.config.config_from_dict`)."""
        d = _merge(BASE_CONFIG, self.base)
        fil = d["filament"]
        L = float(fil.get("length", LENGTH))
        fil["helix_radius"] = self.r_over_l * L
        for k in ("pitch", "pitch_angle_deg", "turns"):
            fil.pop(k, None)
        fil["turns"] = self.turns
        d["body"] = {k: v for k, v in d["body"].items() if k != "radius"}
        d["body"]["radius_ratio"] = self.r_over_rcell
        d["numerics"]["hydrodynamics"] = bool(self.hi)
        if self.density_mismatch is not None:
            fil.pop("density", None)
            fil["density_mismatch"] = float(self.density_mismatch)
        if self.hook_stiffness is not None:
            from flagwrap import units

            j = dict(d.get("joint") or {})
            lh = float(j.get("hook_length", HOOK_LENGTH_RATIO * L))
            A = units.bending_modulus(float(fil["youngs_modulus"]), float(fil["cross_section_radius"]))
            j.update(kind="hook", hook_length=lh,
                     hook_bending_modulus=float(self.hook_stiffness) * A * lh / L)
            d["joint"] = j
        d["motor"] = {"machin": self.machin, "protocol": [
            {"direction": "ccw", "turns": float(self.run["ccw_turns"])},
            {"direction": "cw", "turns": float(self.run["cw_turns"])}]}
        d["name"] = f"psi{self.psi_deg:.3g}_n{self.turns:.3g}_M{self.machin:.5g}" + (
            "" if self.density_mismatch is None else f"_dm{self.density_mismatch:+.4g}") + (
            "" if self.hook_stiffness is None else f"_kh{self.hook_stiffness:.4g}")
        return d

    def config(self):
        """The SI :class:`~flagwrap.params.Config` of the case."""
        from flagwrap.io.config import config_from_dict

        return config_from_dict(self.config_dict())

    def hash_payload(self) -> dict:
        """What the key hashes: the config as resolved (``Config.to_dict``), the protocol
        options that are not part of the config, and the package version."""
        from flagwrap import __version__

        cfg = self.config().replace(name="run")
        from flagwrap.analysis.critical import RUNNER_REVISION

        payload = {"config": cfg.to_dict(for_hash=True), "stop_after": self.run.get("stop_after"),
                   "version": __version__, "runner_revision": RUNNER_REVISION}
        if self.runner is not None:  # a non-default case function makes other results
            payload["runner"] = self.runner
        return payload

    @property
    def key(self) -> str:
        """First 16 hex digits of SHA-256 over the sorted JSON of :meth:`hash_payload`."""
        text = json.dumps(self.hash_payload(), sort_keys=True, separators=(",", ":"))
        return hashlib.sha256(text.encode()).hexdigest()[:16]

    def to_dict(self) -> dict:
        """JSON-able description (the row's parameter columns)."""
        return {"psi_deg": self.psi_deg, "turns": self.turns, "r_over_l": self.r_over_l,
                "r_over_l_cubed": self.r_over_l ** 3, "r_over_rcell": self.r_over_rcell,
                "machin": self.machin, "machin_scaling": self.machin_scaling,
                "omega_ratio_scaling": self.omega_ratio_scaling, "hi": bool(self.hi),
                "n_beads": int(_merge(BASE_CONFIG, self.base)["filament"]["n_beads"]),
                "ccw_turns": float(self.run["ccw_turns"]), "cw_turns": float(self.run["cw_turns"]),
                "stop_after": self.run.get("stop_after"),
                "density_mismatch": 0.0 if self.density_mismatch is None else float(self.density_mismatch),
                "gravity_number": self.gravity_number,
                "hook_stiffness": None if self.hook_stiffness is None else float(self.hook_stiffness)}

    @property
    def gravity_number(self) -> float:
        """``G = (rho_f - rho) g pi a^2 L^3 / A`` of the case's config (0: density-matched)."""
        return self.config().gravity_number if self.density_mismatch is not None else 0.0


@dataclass(frozen=True)
class SweepSpec:
    """A parsed sweep file: name, mode, cases (grid) or geometries (boundary), options."""

    name: str
    mode: str
    cases: tuple
    run: dict
    base: dict
    boundary: dict
    runner: str | None = None

    def geometries(self) -> list[Case]:
        """Distinct geometries (first case of each), in order (boundary mode)."""
        seen, out = set(), []
        for c in self.cases:
            g = json.dumps(c.geometry(), sort_keys=True)
            if g not in seen:
                seen.add(g)
                out.append(c)
        return out


def _expand(table: dict, where: str) -> list[dict]:
    for k in table:
        if k not in CASE_KEYS:
            raise UserInputError(f"{where}: unknown key {k!r}; allowed: {', '.join(CASE_KEYS)}")
    lists = {k: (v if isinstance(v, list) else [v]) for k, v in table.items()}
    for k, v in lists.items():
        if not v:
            raise UserInputError(f"{where}.{k} is an empty list")
    keys = list(lists)
    n = math.prod(len(v) for v in lists.values())
    if n > MAX_CASES:
        raise UserInputError(f"{where}: {' x '.join(str(len(lists[k])) for k in keys)} = {n} cases, "
                             f"more than {MAX_CASES} (at ~1 min per case that is "
                             f"{n / (60 * 24 * 2):.3g} days on 2 cores); split "
                             "the sweep or use mode = \"boundary\"")
    return [dict(zip(keys, combo)) for combo in itertools.product(*(lists[k] for k in keys))]


def _make_case(p: dict, run: dict, base: dict, mode: str, where: str, runner=None) -> Case:
    psi, n, rl = resolve_geometry(p.get("psi_deg"), p.get("turns"), p.get("r_over_l"))
    rr = p.get("r_over_rcell", 0.6)
    if isinstance(rr, bool) or not isinstance(rr, (int, float)) or not (math.isfinite(rr) and rr > 0):
        raise UserInputError(f"{where}: r_over_rcell must be a finite number > 0, got {rr!r}")
    hi = p.get("hi", True)
    if not isinstance(hi, bool):
        raise UserInputError(f"{where}: hi must be true or false, got {hi!r}")
    speeds = [k for k in SPEED_KEYS if k in p]
    if mode == "boundary" and speeds:
        raise UserInputError(f"{where}: boundary mode searches M itself; remove {speeds[0]} "
                             "(the first M tried is [boundary] guess_ratio x the scaling line)")
    if mode == "grid" and len(speeds) != 1:
        raise UserInputError(f"{where}: give exactly one of machin, omega_ratio_scaling per case")
    if speeds:
        v = p[speeds[0]]
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not (math.isfinite(v) and v > 0):
            raise UserInputError(f"{where}: {speeds[0]} must be a finite number > 0, got {v!r}")
        machin = float(v) if speeds[0] == "machin" else float(v) * scaling_machin(rl)
    else:
        machin = scaling_machin(rl)
    dm = p.get("density_mismatch")
    if dm is not None:
        if isinstance(dm, bool) or not isinstance(dm, (int, float)) or not (math.isfinite(dm) and dm > -1):
            raise UserInputError(f"{where}: density_mismatch = (rho - rho_f)/rho_f must be a finite "
                                 f"number > -1 (-100 %: zero density), got {dm!r}")
        dm = float(dm)
        clash = [k for k in ("density", "density_mismatch") if k in (base.get("filament") or {})]
        if clash:
            raise UserInputError(f"sweep: [base] filament.{clash[0]} and the case key "
                                 "density_mismatch both set the filament density; keep one")
    kh = p.get("hook_stiffness")
    if kh is not None:
        if isinstance(kh, bool) or not isinstance(kh, (int, float)) or not (math.isfinite(kh) and kh > 0):
            raise UserInputError(f"{where}: hook_stiffness = A_h L/(A l_h) must be a finite number "
                                 f"> 0 (the clamp's vertex has N - 1), got {kh!r}")
        kh = float(kh)
        jb = base.get("joint") or {}
        clash = [k for k in ("kind", "hook_bending_modulus") if k in jb]
        if clash:
            raise UserInputError(f"sweep: [base] joint.{clash[0]} and the case key hook_stiffness "
                                 "both set the hook; keep one (joint.hook_length may stay)")
    return Case(psi, n, rl, float(rr), machin, hi, dict(run), copy.deepcopy(base), runner, dm, kh)


def _table(data: dict, key: str) -> dict:
    v = data.get(key)
    if v is None:
        return {}
    if not isinstance(v, dict):
        raise UserInputError(f"sweep: [{key}] must be a table, got {type(v).__name__}")
    return v


def _number(v, where: str, allowed: str, ok) -> float:
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) or not ok(v):
        raise UserInputError(f"sweep: {where} must be {allowed}, got {v!r}")
    return float(v)


#: config values every case sets itself, with the sweep key that sets them
CASE_SET = {("motor", None): "machin / omega_ratio_scaling and [run] ccw_turns / cw_turns",
            ("name", None): "the sweep's name",
            ("filament", "helix_radius"): "psi_deg / turns / r_over_l",
            ("filament", "pitch"): "psi_deg / turns / r_over_l",
            ("filament", "pitch_angle_deg"): "psi_deg / turns / r_over_l",
            ("filament", "turns"): "psi_deg / turns / r_over_l",
            ("body", "radius"): "r_over_rcell",
            ("body", "radius_ratio"): "r_over_rcell",
            ("numerics", "hydrodynamics"): "hi"}


def _check_base(base: dict) -> None:
    """[base] holds config sections; what a case sets itself may not be overridden there
    (it would be ignored): the message names the sweep key to use."""
    for section, table in base.items():
        if (section, None) in CASE_SET:
            raise UserInputError(f"sweep: [base] {section} is set by each case; use "
                                 f"{CASE_SET[(section, None)]}")
        if not isinstance(table, dict):
            raise UserInputError(f"sweep: [base] {section} must be a table, got {type(table).__name__}")
        for key in table:
            if (section, key) in CASE_SET:
                raise UserInputError(f"sweep: [base] {section}.{key} is set by each case; use "
                                     f"{CASE_SET[(section, key)]}")


def spec_from_dict(data: dict, name: str = "sweep") -> SweepSpec:
    """Parse a sweep table (see the module docstring); every problem is a UserInputError."""
    allowed = {"name", "mode", "run", "base", "grid", "cases", "boundary", "runner"}
    for k in data:
        if k not in allowed:
            raise UserInputError(f"sweep: unknown key {k!r}; allowed: {', '.join(sorted(allowed))}")
    name = data.get("name", name)
    import re

    # the name is a folder under --out: one path component, never "." or ".."
    if not (isinstance(name, str) and re.fullmatch(r"[A-Za-z0-9_][A-Za-z0-9._-]*", name)
            and name not in (".", "..")):
        raise UserInputError(f"sweep: name must be letters, digits, '.', '_' or '-' (one folder "
                             f"name under --out, not starting with '.' or '-'), got {name!r}")
    mode = data.get("mode", "grid")
    if mode not in ("grid", "boundary"):
        raise UserInputError(f"sweep: mode must be 'grid' or 'boundary', got {mode!r}")
    run = dict(RUN_DEFAULTS)
    for k, v in _table(data, "run").items():
        if k not in RUN_DEFAULTS:
            raise UserInputError(f"sweep: unknown key run.{k}; allowed: {', '.join(RUN_DEFAULTS)}")
        run[k] = v
    if run["stop_after"] is False:
        run["stop_after"] = None
    for k in ("ccw_turns", "cw_turns"):
        run[k] = _number(run[k], f"run.{k}", "a finite number > 0", lambda v: v > 0)
    if run["stop_after"] is not None:
        run["stop_after"] = _number(run["stop_after"], "run.stop_after",
                                    "a finite number of turns > 0, or false", lambda v: v > 0)
    base = _table(data, "base")
    _check_base(base)
    boundary = dict(BOUNDARY_DEFAULTS)
    for k, v in _table(data, "boundary").items():
        if k not in BOUNDARY_DEFAULTS:
            raise UserInputError(f"sweep: unknown key boundary.{k}; allowed: {', '.join(BOUNDARY_DEFAULTS)}")
        boundary[k] = v
    for k, allowed, ok in (("rtol", "in (0, 1)", lambda v: 0 < v < 1),
                           ("guess_ratio", "> 0", lambda v: v > 0),
                           ("factor", "> 1", lambda v: v > 1),
                           ("max_runs", "an integer >= 2", lambda v: v >= 2 and v == int(v))):
        boundary[k] = _number(boundary[k], f"boundary.{k}", allowed, ok)
    boundary["max_runs"] = int(boundary["max_runs"])
    params = []
    if "grid" in data:
        params += _expand(data["grid"], "sweep grid")
    for i, c in enumerate(data.get("cases") or []):
        if not isinstance(c, dict):
            raise UserInputError(f"sweep: cases[{i}] must be a table")
        params += _expand(c, f"sweep cases[{i}]")
    if not params:
        raise UserInputError("sweep: no cases (give [grid] and/or [[cases]])")
    runner = data.get("runner")
    if runner is not None:  # a registered name, carried as its "module:function" target
        from flagwrap.sweep.case import runner_target

        runner = runner_target(runner)
    cases, seen = [], set()
    for i, p in enumerate(params):
        c = _make_case(p, run, base, mode, f"sweep case {i}", runner)
        k = json.dumps([c.geometry(), c.machin], sort_keys=True)
        if k not in seen:
            seen.add(k)
            cases.append(c)
    cases[0].config()  # reject a bad [base] before anything runs
    return SweepSpec(name, mode, tuple(cases), run, base, boundary, runner)


def builtin_specs() -> dict:
    """The sweep files shipped with the package (``flagwrap/data/sweeps``, also
    ``examples/sweeps`` in a checkout): name -> path."""
    folder = Path(__file__).resolve().parents[1] / "data" / "sweeps"
    return {p.stem: p for p in sorted(folder.glob("*.toml"))}


def load_spec(path) -> SweepSpec:
    """Read a sweep TOML file (:func:`spec_from_dict`); the default name is the file stem. A
    bare name of a shipped sweep (``fig5-quick``, :func:`builtin_specs`) works from any folder."""
    try:
        import tomllib
    except ModuleNotFoundError:  # pragma: no cover
        import tomli as tomllib
    path = Path(path)
    if not path.is_file():
        builtin = builtin_specs().get(str(path).removesuffix(".toml"))
        if builtin is None or len(path.parts) > 1:
            raise UserInputError(f"sweep file not found: {path} (built-in sweeps: "
                                 f"{', '.join(sorted(builtin_specs()))})")
        path = builtin
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except tomllib.TOMLDecodeError as exc:
        raise UserInputError(f"malformed TOML in {path}: {exc}") from None
    except UnicodeDecodeError:
        raise UserInputError(f"{path} is not a UTF-8 text file") from None
    return spec_from_dict(data, name=path.stem)
