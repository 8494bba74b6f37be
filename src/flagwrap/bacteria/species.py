"""Flagellar-wrapping bacteria placed on the stability diagram (SI, "Parameter values of ...").

For each species: the bundle of ``n`` flagella is one filament of bending stiffness
``A = B_n = n B_1``, ``B_1 = pi E a^4 / 4`` (SI), with ``E = 4.5e8 Pa``, ``a = 10 nm``;
``M = eta omega L^4 / A`` with ``omega = 2 pi f`` (main text) and the geometric coordinate
``(R/L)^3`` of Fig. 5. The point is unstable (buckles) when ``M > M_c = c (R/L)^-3`` with
``c = 0.06`` (main text), i.e. when ``M / M_c > 1``.

The data live in ``flagwrap/data/bacteria.toml``; every value carries its source and a status
(``seed``, ``derived``, ``assumption`` or ``gap``). Users add species with their own TOML file
of the same schema (:func:`load_species_file`). Argument and field names carry their units
(``radius_um``, ``viscosity_pa_s``); computed quantities are SI.
"""

from __future__ import annotations

import math
import sys
from collections.abc import Mapping
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from typing import Any

from flagwrap.errors import UserInputError
from flagwrap.theory.scaling import M_C_PREFACTOR, critical_machin_number, machin_number
from flagwrap.units import MICRON, NM, PN_UM2

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    import tomli as tomllib

__all__ = [
    "STATUSES",
    "Provenance",
    "Species",
    "default_species",
    "load_species_file",
    "parse_species",
    "format_table",
]

#: allowed provenance statuses
STATUSES = ("seed", "derived", "assumption", "gap")

_NUMERIC = (
    "radius_um",
    "pitch_um",
    "length_um",
    "frequency_hz",
    "viscosity_pa_s",
    "n_flagella",
    "youngs_modulus_pa",
    "filament_radius_nm",
)


@dataclass(frozen=True)
class Provenance:
    """Where a parameter value comes from.

    Attributes
    ----------
    status : str
        one of ``seed`` (printed in the paper), ``derived``, ``assumption``, ``gap`` (no value).
    source : str
        the place in the seed or the cited reference.
    note : str
        why an assumption was made or how a value was derived.
    """

    status: str
    source: str = ""
    note: str = ""

    def __post_init__(self) -> None:
        if self.status not in STATUSES:
            raise UserInputError(f"provenance status must be one of {STATUSES}, got {self.status!r}")


@dataclass(frozen=True)
class Species:
    """One bacterial flagellum (or bundle) as a point of the stability diagram.

    Attributes
    ----------
    key, name, form : str
        identifier, species name, filament form (``coil`` or ``normal``).
    radius_um : float
        helix radius ``R`` [um], > 0.
    length_um : float
        filament arclength ``L`` [um], > 0.
    frequency_hz : float
        motor rotation frequency ``f`` [Hz], > 0.
    viscosity_pa_s : float
        medium viscosity ``eta`` [Pa s], > 0.
    n_flagella : int
        flagella in the bundle, >= 1.
    youngs_modulus_pa : float
        ``E`` [Pa], > 0 (SI: 4.5e8).
    filament_radius_nm : float
        ``a`` [nm], > 0 (SI: 10).
    pitch_um : float or None
        helix pitch ``P`` [um] (not needed for ``M`` or ``(R/L)^3``); ``None`` = not known.
    paper_side : str or None
        ``stable``/``unstable`` as stated by the paper, for comparison.
    provenance : mapping of str to Provenance
        per-parameter source and status.
    """

    key: str
    name: str
    form: str
    radius_um: float
    length_um: float
    frequency_hz: float
    viscosity_pa_s: float
    n_flagella: int
    youngs_modulus_pa: float = 4.5e8
    filament_radius_nm: float = 10.0
    pitch_um: float | None = None
    paper_side: str | None = None
    provenance: Mapping[str, Provenance] = field(default_factory=dict, compare=False, hash=False)

    def __post_init__(self) -> None:
        for name in ("radius_um", "length_um", "frequency_hz", "viscosity_pa_s", "youngs_modulus_pa", "filament_radius_nm"):
            v = getattr(self, name)
            if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
                raise UserInputError(f"species {self.key!r}: {name} must be a finite number > 0, got {v!r}")
        if self.pitch_um is not None and not (math.isfinite(self.pitch_um) and self.pitch_um > 0):
            raise UserInputError(f"species {self.key!r}: pitch_um must be > 0 or absent, got {self.pitch_um!r}")
        if not (isinstance(self.n_flagella, int) and self.n_flagella >= 1):
            raise UserInputError(f"species {self.key!r}: n_flagella must be an integer >= 1, got {self.n_flagella!r}")
        if self.paper_side not in (None, "stable", "unstable"):
            raise UserInputError(f"species {self.key!r}: paper_side must be 'stable' or 'unstable', got {self.paper_side!r}")

    # --- derived quantities (SI) ---------------------------------------------------------
    @property
    def bending_stiffness(self) -> float:
        """``A = n pi E a^4 / 4`` [N m^2] (SI: ``B_n = n B_1``)."""
        a = self.filament_radius_nm * NM
        return self.n_flagella * math.pi * self.youngs_modulus_pa * a**4 / 4.0

    @property
    def bending_stiffness_pn_um2(self) -> float:
        """``A`` in pN um^2."""
        return self.bending_stiffness / PN_UM2

    @property
    def omega(self) -> float:
        """``2 pi f`` [rad/s]."""
        return 2.0 * math.pi * self.frequency_hz

    @property
    def machin(self) -> float:
        """``M = eta omega L^4 / A`` (main text), dimensionless."""
        return machin_number(self.viscosity_pa_s, self.omega, self.length_um * MICRON, self.bending_stiffness)

    @property
    def radius_over_length_cubed(self) -> float:
        """``(R/L)^3``, the abscissa of Fig. 5."""
        return (self.radius_um / self.length_um) ** 3

    @property
    def pitch_angle_deg(self) -> float | None:
        """``atan(2 pi R / P)`` [deg] from the axis, if the pitch is known."""
        if self.pitch_um is None:
            return None
        return math.degrees(math.atan2(2 * math.pi * self.radius_um, self.pitch_um))

    def critical_machin(self, prefactor: float = M_C_PREFACTOR) -> float:
        """``M_c = c (R/L)^-3`` (main text)."""
        return critical_machin_number(self.radius_um / self.length_um, prefactor)

    def instability_ratio(self, prefactor: float = M_C_PREFACTOR) -> float:
        """``M / M_c``; > 1 means the extended helix buckles."""
        return self.machin / self.critical_machin(prefactor)

    def side(self, prefactor: float = M_C_PREFACTOR) -> str:
        """``unstable`` if ``M > M_c`` else ``stable``."""
        return "unstable" if self.instability_ratio(prefactor) > 1.0 else "stable"

    def crossing_inputs(self, prefactor: float = M_C_PREFACTOR) -> dict[str, float]:
        """Value each single input would need for ``M = M_c`` (the others kept).

        Keys: ``viscosity_pa_s``, ``frequency_hz``, ``n_flagella`` (real-valued), ``length_um``,
        ``radius_um``, ``prefactor``. ``M`` scales as ``eta f L^4 / n`` and ``M_c`` as ``(L/R)^3``.
        """
        r = self.instability_ratio(prefactor)
        return {
            "viscosity_pa_s": self.viscosity_pa_s / r,
            "frequency_hz": self.frequency_hz / r,
            "n_flagella": self.n_flagella * r,
            "length_um": self.length_um / r,  # M/M_c ~ L^4 / L^3 = L
            "radius_um": self.radius_um / r ** (1.0 / 3.0),
            "prefactor": prefactor * r,
        }


def _value(entry: Any, field_name: str, key: str) -> tuple[Any, Provenance]:
    if isinstance(entry, dict):
        prov = Provenance(
            status=str(entry.get("status", "seed")),
            source=str(entry.get("source", "")),
            note=str(entry.get("note", "")),
        )
        if prov.status == "gap":
            if "value" in entry:
                raise UserInputError(f"species {key!r}: {field_name} has status 'gap' but a value")
            return None, prov
        if "value" not in entry:
            raise UserInputError(f"species {key!r}: {field_name} needs a 'value' (or status = 'gap')")
        return entry["value"], prov
    return entry, Provenance(status="seed", source="user file")


def parse_species(document: Mapping[str, Any], origin: str = "<toml>") -> list[Species]:
    """Build :class:`Species` from a parsed TOML document (``[defaults]`` + ``[[species]]``).

    Each parameter is a number or a table ``{value, status, source, note}``.
    """
    defaults = document.get("defaults", {})
    if not isinstance(defaults, Mapping):
        raise UserInputError(f"{origin}: [defaults] must be a table")
    defaults = dict(defaults)
    entries = document.get("species")
    if not isinstance(entries, list) or not entries:
        raise UserInputError(f"{origin}: needs at least one [[species]] table")
    out = []
    for k, raw in enumerate(entries):
        if not isinstance(raw, Mapping):
            raise UserInputError(f"{origin}: species[{k}] must be a table ([[species]]), got "
                                 f"{raw!r}")
        key = str(raw.get("key", "")).strip()
        if not key:
            raise UserInputError(f"{origin}: every [[species]] needs a non-empty 'key'")
        kwargs: dict[str, Any] = {
            "key": key,
            "name": str(raw.get("name", key)),
            "form": str(raw.get("form", "coil")),
            "paper_side": raw.get("paper_side"),
        }
        prov: dict[str, Provenance] = {}
        for fname in _NUMERIC:
            if fname in raw:
                entry = raw[fname]
            elif fname in defaults:
                entry = defaults[fname]
            elif fname == "pitch_um":
                continue
            elif fname in ("youngs_modulus_pa", "filament_radius_nm"):
                continue
            else:
                raise UserInputError(f"{origin}: species {key!r} lacks {fname!r}")
            value, p = _value(entry, fname, key)
            prov[fname] = p
            if value is None:
                if fname != "pitch_um":
                    raise UserInputError(f"{origin}: species {key!r}: {fname} is a gap but is required")
                continue
            if fname == "n_flagella":
                if isinstance(value, bool) or not isinstance(value, int):
                    raise UserInputError(f"{origin}: species {key!r}: n_flagella must be an integer, got {value!r}")
            elif isinstance(value, bool) or not isinstance(value, (int, float)):
                raise UserInputError(f"{origin}: species {key!r}: {fname} must be a number, got {value!r}")
            else:
                value = float(value)
                if not math.isfinite(value) or abs(value) > 1e12:
                    raise UserInputError(f"{origin}: species {key!r}: {fname} = {value!r} is "
                                         "not a physical value (finite, below 1e12 in its unit)")
            kwargs[fname] = value
        out.append(Species(**kwargs, provenance=prov))
    keys = [s.key for s in out]
    dup = {k for k in keys if keys.count(k) > 1}
    if dup:
        raise UserInputError(f"{origin}: duplicate species keys {sorted(dup)}")
    return out


def default_species() -> list[Species]:
    """The seed's bacteria from the packaged ``flagwrap/data/bacteria.toml``."""
    text = resources.files("flagwrap").joinpath("data/bacteria.toml").read_text(encoding="utf-8")
    return parse_species(tomllib.loads(text), "flagwrap/data/bacteria.toml")


def load_species_file(path: str | Path) -> list[Species]:
    """Species from a user TOML file of the packaged schema; ``[defaults]`` may be omitted
    (then ``E = 4.5e8 Pa`` and ``a = 10 nm``, the SI's values)."""
    p = Path(path)
    try:
        doc = tomllib.loads(p.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise UserInputError(f"species file not found: {p}") from None
    except IsADirectoryError:
        raise UserInputError(f"--file {p} is a directory, not a species TOML file") from None
    except UnicodeDecodeError:
        raise UserInputError(f"--file {p} is not a UTF-8 text file (a species TOML)") from None
    except OSError as exc:
        raise UserInputError(f"--file {p} cannot be read: {exc.strerror or exc}") from None
    except tomllib.TOMLDecodeError as exc:
        raise UserInputError(f"{p}: invalid TOML: {exc}") from None
    return parse_species(doc, str(p))


def format_table(species: list[Species], prefactor: float = M_C_PREFACTOR) -> str:
    """Plain-text table of the diagram coordinates; a ``*`` marks values resting on an
    assumption (status ``assumption``), ``!`` a computed side that disagrees with the paper."""
    header = (
        f"{'species':<34} {'form':<6} {'n':>2} {'R um':>6} {'L um':>5} {'f Hz':>5} {'eta mPa s':>9} "
        f"{'A pN um2':>8} {'M':>8} {'(R/L)^3':>9} {'M_c':>8} {'M/M_c':>7} {'side':<8} {'paper':<8}"
    )
    lines = [header, "-" * len(header)]

    def mark(s: Species, f: str) -> str:
        p = s.provenance.get(f)
        return "*" if p is not None and p.status == "assumption" else " "

    for s in species:
        side = s.side(prefactor)
        flag = "!" if s.paper_side is not None and s.paper_side != side else ""
        lines.append(
            f"{s.name[:34]:<34} {s.form:<6} {s.n_flagella:>1}{mark(s, 'n_flagella')}"
            f" {s.radius_um:>5.3g}{mark(s, 'radius_um')} {s.length_um:>5.3g} {s.frequency_hz:>4.3g}{mark(s, 'frequency_hz')}"
            f" {s.viscosity_pa_s * 1e3:>8.3g}{mark(s, 'viscosity_pa_s')} {s.bending_stiffness_pn_um2:>8.3g}"
            f" {s.machin:>8.4g} {s.radius_over_length_cubed:>9.3e} {s.critical_machin(prefactor):>8.4g}"
            f" {s.instability_ratio(prefactor):>7.3g} {side:<8} {(s.paper_side or '-') + flag:<8}"
        )
    lines.append(f"M = eta (2 pi f) L^4 / A, A = n pi E a^4/4; M_c = {prefactor:g} (R/L)^-3.")
    lines.append("* = assumption (not printed in the paper for this species); ! = disagrees with the paper.")
    return "\n".join(lines)
