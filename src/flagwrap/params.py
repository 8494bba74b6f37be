"""Parameters of a run: frozen dataclasses in SI units, validated on construction.

Every impossible value is rejected in ``__post_init__`` with a :class:`UserInputError`
naming the parameter and its allowed range, before any work starts. Dimensionless numbers
(``M``, ``Re``, the estimate of ``omega/omega_c``) are derived properties, never inputs that
could disagree with the SI values, except that the motor speed may be *given* as ``M``.

Units: lengths [m], moduli [Pa], viscosity [Pa s], density [kg m^-3], frequency [Hz].
"""

from __future__ import annotations

import dataclasses
import functools
import math
from dataclasses import dataclass, field

import numpy as np

from flagwrap import units
from flagwrap.errors import UserInputError, check_finite, check_positive

#: prefactor of the paper's stability line M_c = 0.06 (R/L)^-3 (main text, Fig. 5)
PAPER_MC_PREFACTOR = 0.06
#: validity bounds of the bead model (docs/robustness.md): the filament is slender
#: (L >= 10 a; the paper's helices have L/a ~ 270, flagella ~ 700), and its beads are close
#: enough to act as one body: a chain's drag per length 6 pi eta a / b (no HI) equals a slender
#: filament's ~4 pi eta / (ln(L/a) + 0.5) near b ~ 9 a and is ~10x too small at b = 100 a, the
#: bound (the paper's N = 61 helix has b = 4.4 a; coarse test chains up to ~70 a)
MIN_SLENDERNESS = 10.0
MAX_BOND_OVER_RADIUS = 100.0
HYDRODYNAMIC_MODELS = ("spheres", "tube")
#: the cell body is wider than the filament and not absurdly larger than it:
#: 2 a < R_cell <= 10 L
MAX_BODY_OVER_LENGTH = 10.0
#: most blobs for the direct (dense Cholesky) solve, asked for by ``body.solver = "direct"``
#: (``"auto"`` takes it up to 4000, ``body.solver.AUTO_DIRECT_MAX``) or a free cell's tube:
#: 10000 blobs are a 30000^2 factor, 7.2 GB (priced by the memory check before any work),
#: factorised once in minutes on one core
MAX_BLOBS = 10000
#: most blobs for the Krylov solve (O(n) memory, O(n^2) time per product: 20000 blobs are
#: ~4e8 pair terms per product, seconds)
MAX_BLOBS_KRYLOV = 20000


# the one range check (flagwrap.errors), under the names this module has always used
_finite = check_finite
_positive = check_positive


def _set(obj, name, value):
    object.__setattr__(obj, name, value)


@dataclass(frozen=True)
class Filament:
    """Elastic helical filament (the flagellum or the elastomer helix).

    Give ``length``, ``helix_radius`` and exactly one of ``pitch``, ``pitch_angle_deg`` or
    ``turns``; the others are derived (pitch angle ``psi = atan(2 pi R / P)``, measured from the
    helix axis; ``L = n sqrt((2 pi R)^2 + P^2)``).

    Attributes
    ----------
    length : float
        contour length ``L`` [m].
    helix_radius : float
        ``R`` [m].
    pitch : float
        ``P`` [m].
    cross_section_radius : float
        ``a`` [m]; the bending modulus is ``A = pi E a^4 / 4``.
    youngs_modulus : float
        ``E`` [Pa].
    poisson_ratio : float
        ``nu`` in [-1, 0.5]; ``C = A / (1 + nu)``.
    handedness : {"left", "right"}
        bacterial flagella (normal and coil forms) are left-handed.
    n_beads : int
        number of beads ``N >= 5`` (paper: 61). Bond length ``b = L / (N - 1)``.
    density : float or None
        filament density [kg m^-3]; ``None`` means density-matched (no gravity).
    density_mismatch : float or None
        the density as a fraction of the fluid's, ``(rho - rho_f) / rho_f`` in (-1, inf)
        (``-0.02``: 2 % lighter than the fluid, buoyant); an alternative to ``density``,
        resolved to it by :class:`Config` (which knows ``rho_f``). ``Config.gravity_number``
        is the dimensionless buoyancy ``G`` (docs/gravity.md).
    hydrodynamic_radius : float or None
        bead radius used in the mobility [m]; ``None`` means ``a`` (the paper's choice).
    hydrodynamic_model : {"spheres", "tube"}
        ``"spheres"`` (default, the paper's): RPY spheres of radius ``hydrodynamic_radius``,
        each with the spin drag ``8 pi eta a_h^3``. ``"tube"``: the chain matched to a slender
        tube of radius ``a`` at its spacing (:mod:`flagwrap.hydrodynamics.tube`: bead radius
        from the normal drag, a tangential self term from the axial drag, spin drag
        ``4 pi eta a^2`` per length); needs ``b >= 2.51 a`` and hydrodynamic interactions,
        and no ``hydrodynamic_radius``. The spheres at ``b ~ 6.5 a`` propel ~40 % too weakly
        (docs/bacterium.md, "The chain matched to a tube").
    stretch_stiffness : float
        bond spring constant in units of ``A / b^3`` (default 1000: axial strain ~ F b^2/(1000 A)).
    shape : {"helix", "straight"}
        the stress-free shape: the helix (default), or a straight rod of length ``L`` down the
        motor axis (Greenhill's and the hook's checks; the helix parameters then still set the
        derived numbers that use ``R``: the body's ``radius_ratio``, ``Re`` and the scaling
        line, so give ``body.radius`` explicitly). Any other rest polyline and twist: the Python
        API, ``RodSystem(config, x0=..., theta0=...)``.
    """

    length: float
    helix_radius: float
    cross_section_radius: float
    youngs_modulus: float
    pitch: float | None = None
    pitch_angle_deg: float | None = None
    turns: float | None = None
    poisson_ratio: float = 0.49
    handedness: str = "left"
    n_beads: int = 61
    density: float | None = None
    hydrodynamic_radius: float | None = None
    stretch_stiffness: float = 1000.0
    hydrodynamic_model: str = "spheres"
    density_mismatch: float | None = None
    shape: str = "helix"

    def __post_init__(self):
        L = _positive("filament.length", self.length, "m")
        R = _positive("filament.helix_radius", self.helix_radius, "m")
        a = _positive("filament.cross_section_radius", self.cross_section_radius, "m")
        _positive("filament.youngs_modulus", self.youngs_modulus, "Pa")
        given = [k for k in ("pitch", "pitch_angle_deg", "turns") if getattr(self, k) is not None]
        if len(given) != 1:
            raise UserInputError(
                "filament: give exactly one of pitch, pitch_angle_deg or turns "
                f"(got {', '.join(given) if given else 'none'})"
            )
        try:
            if given[0] == "pitch":
                P = _positive("filament.pitch", self.pitch, "m")
            elif given[0] == "pitch_angle_deg":
                psi = _finite("filament.pitch_angle_deg", self.pitch_angle_deg)
                if not 0.0 < psi < 90.0:
                    raise UserInputError(f"filament.pitch_angle_deg must be in (0, 90) deg, got {psi}")
                P = 2 * math.pi * R / math.tan(math.radians(psi))
            else:
                n = _positive("filament.turns", self.turns)
                per_turn = L / n
                if per_turn <= 2 * math.pi * R:
                    raise UserInputError(
                        f"filament.turns={n} needs a contour per turn L/n={per_turn:g} m longer than "
                        f"2 pi R={2 * math.pi * R:g} m; allowed: turns < {L / (2 * math.pi * R):g}"
                    )
                P = math.sqrt(per_turn**2 - (2 * math.pi * R) ** 2)
            turns = L / math.hypot(2 * math.pi * R, P)
        except (OverflowError, ZeroDivisionError):
            P = turns = math.nan
        if not (math.isfinite(P) and P > 0 and math.isfinite(turns) and turns > 0):
            raise UserInputError(
                f"filament: length={L:g} m, helix_radius={R:g} m and {given[0]}="
                f"{getattr(self, given[0])!r} give no finite helix (values out of physical range)")
        _set(self, "pitch", P)
        _set(self, "pitch_angle_deg", math.degrees(math.atan2(2 * math.pi * R, P)))
        _set(self, "turns", turns)
        if a >= R:
            raise UserInputError(
                f"filament.cross_section_radius={a:g} m must be < helix_radius={R:g} m"
            )
        if P <= 2 * a:
            raise UserInputError(
                f"filament.pitch={P:g} m must be > 2 * cross_section_radius={2 * a:g} m "
                "(otherwise successive turns overlap)"
            )
        nu = _finite("filament.poisson_ratio", self.poisson_ratio)
        if not -1.0 < nu <= 0.5:
            raise UserInputError(f"filament.poisson_ratio must be in (-1, 0.5], got {nu}")
        if self.shape not in ("helix", "straight"):
            raise UserInputError(f"filament.shape must be 'helix' or 'straight', got {self.shape!r}")
        if self.handedness not in ("left", "right"):
            raise UserInputError(
                f"filament.handedness must be 'left' or 'right', got {self.handedness!r}"
            )
        if isinstance(self.n_beads, bool) or not isinstance(self.n_beads, (int, np.integer)):
            raise UserInputError(f"filament.n_beads must be an integer, got {self.n_beads!r}")
        if not 5 <= self.n_beads <= 200_000:
            raise UserInputError(f"filament.n_beads must be in [5, 200000], got {self.n_beads}")
        if self.density is not None:
            _positive("filament.density", self.density, "kg/m^3")
        if self.density_mismatch is not None:
            if self.density is not None:
                raise UserInputError(
                    f"filament: give density ({self.density!r} kg/m^3) or density_mismatch "
                    f"({self.density_mismatch!r}), not both")
            m = _finite("filament.density_mismatch", self.density_mismatch)
            if not m > -1.0:
                raise UserInputError(
                    f"filament.density_mismatch = (rho - rho_f)/rho_f must be > -1 (-100 %: a "
                    f"filament of zero density), got {m!r}")
        if self.hydrodynamic_radius is not None:
            ah = _positive("filament.hydrodynamic_radius", self.hydrodynamic_radius, "m")
            if ah >= R:
                raise UserInputError(
                    f"filament.hydrodynamic_radius={ah:g} m must be < helix_radius={R:g} m"
                )
            bond = L / (self.n_beads - 1)
            if ah >= bond:
                raise UserInputError(
                    f"filament.hydrodynamic_radius={ah:g} m must be < the bond L/(n_beads - 1) = "
                    f"{bond:g} m: a bead reaching past its neighbour's centre is a lump, not a "
                    "chain (the RPY overlap correction keeps the mobility positive there, not the "
                    "filament's drag)")
        _positive("filament.stretch_stiffness", self.stretch_stiffness, "(units of A/b^3)")
        if self.hydrodynamic_model not in HYDRODYNAMIC_MODELS:
            raise UserInputError(f"filament.hydrodynamic_model must be one of "
                                 f"{', '.join(map(repr, HYDRODYNAMIC_MODELS))}, got "
                                 f"{self.hydrodynamic_model!r}")
        if self.hydrodynamic_model == "tube":
            from flagwrap.hydrodynamics.tube import TUBE_MIN_BOND

            if self.hydrodynamic_radius is not None:
                raise UserInputError(
                    "filament.hydrodynamic_radius cannot be set with hydrodynamic_model = "
                    "'tube' (the tube model derives the bead radius from a and the bond)")
            b = L / (self.n_beads - 1)
            if b < TUBE_MIN_BOND * a:
                nmax = math.floor(L / (TUBE_MIN_BOND * a)) + 1
                raise UserInputError(
                    f"filament.hydrodynamic_model = 'tube' needs a bond L/(n_beads - 1) >= "
                    f"{TUBE_MIN_BOND:.3f} cross_section_radius (the matched beads would overlap), "
                    f"got {b / a:.3g} a: n_beads <= {nmax}, or hydrodynamic_model = 'spheres'")
        if L < MIN_SLENDERNESS * a:
            raise UserInputError(
                f"filament.length={L:g} m is {L / a:.3g} x cross_section_radius={a:g} m; a Kirchhoff "
                f"rod needs a slender filament, length >= {MIN_SLENDERNESS:g} a")
        b = L / (self.n_beads - 1)
        if b > MAX_BOND_OVER_RADIUS * a:
            need = L / (MAX_BOND_OVER_RADIUS * a) + 1
            fix = (f"raise n_beads to >= {math.ceil(need)}" if need <= 200_000 else
                   "no allowed n_beads resolves it: check length and cross_section_radius")
            raise UserInputError(
                f"filament: bond length L/(n_beads - 1) = {b:.3g} m is {b / a:.3g} x "
                f"cross_section_radius={a:g} m, more than {MAX_BOND_OVER_RADIUS:g}: beads that far apart "
                f"are separate spheres, not a filament (their drag per length falls as a/b); {fix}")

    def with_density(self, density: float) -> "Filament":
        """A copy with ``density`` [kg m^-3] and no ``density_mismatch`` (the resolved pitch
        inputs forbid ``dataclasses.replace``; the copy leaves the caller's Filament alone)."""
        import copy

        fil = copy.copy(self)
        _set(fil, "density", _positive("filament.density", density, "kg/m^3"))
        _set(fil, "density_mismatch", None)
        return fil

    # derived -------------------------------------------------------------------------------
    @property
    def bending_modulus(self) -> float:
        """``A = pi E a^4 / 4`` [N m^2]."""
        return units.bending_modulus(self.youngs_modulus, self.cross_section_radius)

    @property
    def twist_modulus(self) -> float:
        """``C = A / (1 + nu)`` [N m^2]."""
        return units.twist_modulus(self.bending_modulus, self.poisson_ratio)

    @property
    def bond_length(self) -> float:
        """``b = L / (N - 1)`` [m]."""
        return self.length / (self.n_beads - 1)

    @property
    def bead_radius(self) -> float:
        """Hydrodynamic bead radius [m] (the tube model's matched ``a_h``)."""
        if self.hydrodynamic_model == "tube":
            return self._tube.bead_radius
        return self.hydrodynamic_radius or self.cross_section_radius

    @property
    def _tube(self):
        from flagwrap.hydrodynamics.tube import tube_chain

        return tube_chain(self.cross_section_radius, self.bond_length)

    @property
    def tube_kappa(self) -> float:
        """The tangential self-mobility factor of the tube model (0 for spheres)."""
        return self._tube.kappa if self.hydrodynamic_model == "tube" else 0.0

    @property
    def bead_spin_drag(self) -> float:
        """Spin drag of one bead over viscosity [m^3]: ``8 pi a_h^3`` (spheres) or the
        tube's ``4 pi a^2 b`` (its drag per length over one bond)."""
        if self.hydrodynamic_model == "tube":
            return 4.0 * math.pi * self.cross_section_radius**2 * self.bond_length
        return 8.0 * math.pi * self.bead_radius**3

    @property
    def curvature0(self) -> float:
        """Spontaneous curvature ``kappa0 = 4 pi^2 R / (P^2 + 4 pi^2 R^2)`` [1/m] (SI)."""
        R, P = self.helix_radius, self.pitch
        return 4 * math.pi**2 * R / (P**2 + 4 * math.pi**2 * R**2)

    @property
    def torsion0(self) -> float:
        """Spontaneous torsion ``tau0 = 2 pi P / (P^2 + 4 pi^2 R^2)`` [1/m], >0 (SI; sign by handedness)."""
        R, P = self.helix_radius, self.pitch
        return 2 * math.pi * P / (P**2 + 4 * math.pi**2 * R**2)


@dataclass(frozen=True)
class Fluid:
    """Newtonian fluid. Defaults: the paper's glycerin (eta = 1.1 Pa s, rho = 1250 kg/m^3)."""

    viscosity: float = 1.1
    density: float = 1250.0

    def __post_init__(self):
        _positive("fluid.viscosity", self.viscosity, "Pa s")
        d = _finite("fluid.density", self.density)
        if d < 0:
            raise UserInputError(f"fluid.density must be >= 0 kg/m^3, got {d}")


@dataclass(frozen=True)
class CellBody:
    """Rigid cell body: a cylinder of radius ``R_cell`` capped below by a hemisphere.

    Give either ``radius`` [m] or ``radius_ratio = R / R_cell`` (default 0.6, the paper's coil
    helices: SI Fig. S7); both, with a ratio other than the default, is an error.
    ``cylinder_length`` [m] defaults to ``5 R_cell`` (the experiment's 25 cm cylinder of 5 cm
    radius). The fluid passes through the body (paper, Methods); only a
    short-ranged repulsion keeps beads outside. ``enabled = false`` removes it altogether.

    ``surface``: ``"transparent"`` (default, the paper's rig: the fluid passes through the
    body) or ``"no-slip"`` (the rigid multiblob method, :mod:`flagwrap.body.multiblob`: blobs
    of radius ``blob_radius`` about ``blob_spacing`` apart on the surface hold the fluid back;
    needs ``numerics.hydrodynamics = true``). ``motion``: ``"fixed"`` (default, the rig) or
    ``"free"`` (force- and torque-free, a swimming cell: :mod:`flagwrap.system.swimmer`; needs
    a no-slip surface, since a transparent body has no drag, and a motor that turns).
    ``blob_spacing`` [m] defaults to ``R_cell / 3`` and ``blob_radius`` [m] to half the
    spacing (Usabiaga et al. 2016 use blobs about half their spacing; docs/bacterium.md
    measures the convergence in both). ``solver``: how the blob matrix is solved, "direct"
    (Cholesky once, O(n^2) memory), "krylov" (conjugate gradients, O(n) memory) or "auto"
    (direct up to 1500 blobs; :mod:`flagwrap.body.solver`). ``shape``: "capped-cylinder" (the
    paper's, default), "spheroid" (equatorial radius ``R_cell``, total length ``R_cell +
    cylinder_length`` along the axis, lowest point at the clamp), "sphere" (radius
    ``R_cell``) or a shape registered from Python (:mod:`flagwrap.body.shapes`: a class that
    owns its distance, blobs, mesh and pole cap).
    """

    radius: float | None = None
    radius_ratio: float | None = None  # 0.6 when radius is not given either
    cylinder_length: float | None = None
    enabled: bool = True
    surface: str = "transparent"
    motion: str = "fixed"
    blob_spacing: float | None = None
    blob_radius: float | None = None
    solver: str = "auto"
    shape: str = "capped-cylinder"

    DEFAULT_RADIUS_RATIO = 0.6
    #: the built-in shapes (:func:`flagwrap.body.shapes.shape_names` lists those registered)
    SHAPES = ("capped-cylinder", "sphere", "spheroid")
    SURFACES = ("transparent", "no-slip")
    MOTIONS = ("fixed", "free")
    #: keys added after results were stored, left out of result keys at these defaults
    HASH_OMIT_DEFAULTS = {"surface": "transparent", "motion": "fixed", "solver": "auto",
                          "shape": "capped-cylinder"}

    def __post_init__(self):
        if self.radius is not None:
            # the default ratio that __post_init__ filled in yields to a radius (so that
            # dataclasses.replace(CellBody(), radius=...) works); any other ratio is a conflict
            if self.radius_ratio is not None and self.radius_ratio != self.DEFAULT_RADIUS_RATIO:
                raise UserInputError(
                    f"body: give radius ({self.radius!r} m) or radius_ratio ({self.radius_ratio!r}), "
                    "not both")
            _positive("body.radius", self.radius, "m")
            _set(self, "radius_ratio", None)
        elif self.radius_ratio is not None:
            _positive("body.radius_ratio", self.radius_ratio)
        else:
            _set(self, "radius_ratio", self.DEFAULT_RADIUS_RATIO)
        if self.cylinder_length is not None:
            _positive("body.cylinder_length", self.cylinder_length, "m")
        if not isinstance(self.enabled, bool):
            raise UserInputError(f"body.enabled must be true or false, got {self.enabled!r}")
        from flagwrap.body.shapes import shape_names

        if self.shape not in shape_names():
            raise UserInputError(f"body.shape must be one of {', '.join(shape_names())}, got "
                                 f"{self.shape!r} (a shape of your own: "
                                 "flagwrap.body.shapes.register_shape)")
        if self.shape == "sphere" and self.cylinder_length is not None:
            raise UserInputError("body.cylinder_length does not apply to body.shape = 'sphere' "
                                 "(its length is its diameter)")
        if self.surface not in self.SURFACES:
            raise UserInputError(f"body.surface must be one of {', '.join(self.SURFACES)}, "
                                 f"got {self.surface!r}")
        if self.motion not in self.MOTIONS:
            raise UserInputError(f"body.motion must be one of {', '.join(self.MOTIONS)}, "
                                 f"got {self.motion!r}")
        from flagwrap.body.solver import KINDS

        if self.solver not in KINDS:
            raise UserInputError(f"body.solver must be one of {', '.join(KINDS)}, got {self.solver!r}")
        for key in ("blob_spacing", "blob_radius"):
            if getattr(self, key) is not None:
                _positive(f"body.{key}", getattr(self, key), "m")
        if self.surface == "no-slip" and not self.enabled:
            raise UserInputError("body.surface = 'no-slip' needs body.enabled = true")
        if self.motion == "free" and self.surface != "no-slip":
            raise UserInputError("body.motion = 'free' needs body.surface = 'no-slip': a "
                                 "transparent body has no drag, so nothing would set its motion")

    @property
    def no_slip(self) -> bool:
        return self.enabled and self.surface == "no-slip"

    @property
    def free(self) -> bool:
        return self.enabled and self.motion == "free"

    def resolved_blob_spacing(self, helix_radius: float) -> float:
        if self.blob_spacing is not None:
            return self.blob_spacing
        return self.resolved_radius(helix_radius) / 3.0

    def resolved_blob_radius(self, helix_radius: float) -> float:
        if self.blob_radius is not None:
            return self.blob_radius
        return 0.5 * self.resolved_blob_spacing(helix_radius)

    def resolved_radius(self, helix_radius: float) -> float:
        return self.radius if self.radius is not None else helix_radius / self.radius_ratio

    def resolved_length(self, helix_radius: float) -> float:
        """The body's length above its cap's centre height ``H``: the cylinder's, or for a
        spheroid its total length less ``R_cell`` (a sphere: ``R_cell``)."""
        if self.shape == "sphere":
            return self.resolved_radius(helix_radius)
        if self.cylinder_length is not None:
            return self.cylinder_length
        return 5.0 * self.resolved_radius(helix_radius)


@dataclass(frozen=True)
class Phase:
    """One phase of the motor protocol: ``turns`` turns in ``direction`` at ``speed`` x omega.

    ``direction`` is seen from the free end of the filament, as in the paper: "ccw" is the
    swimming direction of a bacterium, "cw" the reversal that triggers wrapping.
    """

    direction: str
    turns: float
    speed: float = 1.0

    def __post_init__(self):
        if self.direction not in ("ccw", "cw", "stop"):
            raise UserInputError(
                f"motor.protocol direction must be 'ccw', 'cw' or 'stop', got {self.direction!r}"
            )
        _positive("motor.protocol turns", self.turns)
        _positive("motor.protocol speed", self.speed)


def paper_protocol(ccw_turns: float = 10.0, cw_turns: float = 10.0) -> tuple[Phase, ...]:
    """The paper's protocol: 10 CCW turns to equilibrate, then CW at the same speed."""
    return (Phase("ccw", ccw_turns), Phase("cw", cw_turns))


@dataclass(frozen=True)
class Motor:
    """Motor speed and protocol.

    Give the reference speed (the CW phase's) as ``frequency`` [Hz] or as the Machin number
    ``machin`` = eta omega L^4 / A. ``protocol`` is a sequence of :class:`Phase`; ``duration``
    of a ``stop`` phase is given in reference turns.
    """

    frequency: float | None = None
    machin: float | None = None
    protocol: tuple[Phase, ...] = field(default_factory=paper_protocol)
    kind: str = "speed"
    stall_torque: float | None = None
    zero_load_speed: float | None = None

    #: ``kind``: what the motor prescribes (:mod:`flagwrap.motor.drive`). "speed" (default):
    #: the rate, relative to the body, phase by phase. "torque": the torque ``stall_torque``
    #: [N m], in each phase's direction. "torque-speed": the linear curve
    #: ``tau = stall_torque (1 - rate / (2 pi zero_load_speed))`` [N m, Hz] (the bacterial
    #: motor's, from stall to zero load: docs/bacterium.md). For the torque kinds a phase's
    #: ``turns`` counts reference periods ``2 pi / omega`` of time, and its speed must be 1.
    KINDS = ("speed", "torque", "torque-speed")
    HASH_OMIT_DEFAULTS = {"kind": "speed"}

    def __post_init__(self):
        if (self.frequency is None) == (self.machin is None):
            raise UserInputError("motor: give exactly one of frequency (Hz) or machin (M)")
        if self.frequency is not None:
            _positive("motor.frequency", self.frequency, "Hz")
        else:
            _positive("motor.machin", self.machin)
        prot = tuple(p if isinstance(p, Phase) else Phase(**p) for p in self.protocol)
        if not prot:
            raise UserInputError("motor.protocol must have at least one phase")
        _set(self, "protocol", prot)
        if self.kind not in self.KINDS:
            raise UserInputError(f"motor.kind must be one of {', '.join(self.KINDS)}, got {self.kind!r}")
        if self.kind == "speed":
            for key in ("stall_torque", "zero_load_speed"):
                if getattr(self, key) is not None:
                    raise UserInputError(f"motor.{key} needs motor.kind = 'torque' or "
                                         "'torque-speed' (a speed motor prescribes its rate)")
            return
        if self.stall_torque is None:
            raise UserInputError(f"motor.kind = {self.kind!r} needs motor.stall_torque [N m] > 0")
        _positive("motor.stall_torque", self.stall_torque, "N m")
        if self.kind == "torque-speed":
            if self.zero_load_speed is None:
                raise UserInputError("motor.kind = 'torque-speed' needs motor.zero_load_speed [Hz] > 0")
            _positive("motor.zero_load_speed", self.zero_load_speed, "Hz")
        elif self.zero_load_speed is not None:
            raise UserInputError("motor.zero_load_speed needs motor.kind = 'torque-speed'")
        for p in prot:
            if p.direction != "stop" and p.speed != 1.0:
                raise UserInputError(f"motor.protocol speed = {p.speed:g}: a {self.kind} motor "
                                     "sets its own speed; leave the phases' speed at 1")


@dataclass(frozen=True)
class Clamp:
    """Shape of the rod next to the vertically clamped driving end (not printed in the paper).

    ``lead = "kink"`` (default): the clamped first bond points straight down the body axis
    ("vertically clamped", paper Discussion) and from bead 1 on the filament is the uniform
    stress-free helix, whose axis is therefore parallel to the body axis at distance ``R`` (a
    uniform helix held by its end on the axis cannot be centred on it without an extra lead).
    The angle ``psi`` between the clamped bond and the helix is part of the stress-free shape.
    Turning the clamp makes the helix whirl about the body axis, as in the paper's stable runs.

    ``lead = "ramp"``: the helix axis is the body axis; from the vertical clamped bond the helix
    radius ramps smoothly from 0 to ``R`` over ``lead_turns`` helical turns
    (``r = R (1 - cos(pi phi / phi_r)) / 2``). The centreline and its tangent are continuous.

    ``lead = "connector"``: the kink lead's helix moved by ``R`` onto the body axis (the helix
    centred on the motor axis, as a free-swimmer calculation with a rigid helix has it) and
    reached from the anchor by a rigid radial arm of length ``R`` in the anchor plane, then the
    clamped bond parallel to the axis. The arm and the clamped bond are held by the motor: no
    drag, no elastic energy (hydrodynamically inactive). The filament proper and its number of
    active beads are the kink lead's; the arm adds ``ceil(R/b)`` held beads.

    All initial shapes are stress-free. docs/model.md measures how results move between them.
    """

    lead: str = "kink"
    lead_turns: float = 0.5

    LEADS = ("kink", "ramp", "connector")

    def __post_init__(self):
        if self.lead not in self.LEADS:
            raise UserInputError(f"clamp.lead must be one of {', '.join(map(repr, self.LEADS))}, "
                                 f"got {self.lead!r}")
        lt = _finite("clamp.lead_turns", self.lead_turns)
        if not 0.0 < lt <= 5.0:
            raise UserInputError(f"clamp.lead_turns must be in (0, 5], got {lt}")


@dataclass(frozen=True)
class Joint:
    """The joint between the motor and the filament (issue 15; docs/hook.md).

    ``kind = "clamp"`` (default): the paper's rig. The motor holds the first bond rigidly; the
    vertex where the filament leaves it bends with the filament's own stiffness ``A / b``.

    ``kind = "hook"``: the flagellar hook, a short elastic joint of length ``hook_length``
    ``l_h`` [m], bending stiffness ``hook_bending_modulus`` ``A_h`` [N m^2] and twist stiffness
    ``hook_twist_modulus`` ``C_h`` [N m^2]. ``hook_segments = 0`` (default) lumps it into one
    vertex between the motor axis and the first free bond, a bending spring ``A_h / l_h``
    and a twist spring ``C_h / l_h`` (right for a hook much shorter than a bond: ``l_h/L ~ 1e-2``
    against ``b/L = 1/60``); ``hook_segments = n >= 2`` resolves it as ``n`` bonds of length
    ``l_h / n`` inserted between the motor's bond and the filament (which keeps its own beads).
    ``hook_twist_modulus`` unset: ``C_h`` = the filament's ``C``, a torque-transmitting hook
    (``C_h / l_h >= C / b``). The universal-joint limit is ``A_h -> 0`` (a small positive value:
    zero stiffness is refused as a typo). Bacterial values and their sources: docs/hook.md.
    """

    kind: str = "clamp"
    hook_length: float | None = None
    hook_bending_modulus: float | None = None
    hook_twist_modulus: float | None = None
    hook_segments: int = 0
    #: largest hook stiffness relative to the filament's, ``A_h L / (A l_h)`` (and ``C_h``'s)
    MAX_STIFFNESS = 1e6

    KINDS = ("clamp", "hook")
    MAX_SEGMENTS = 50

    def __post_init__(self):
        if self.kind not in self.KINDS:
            raise UserInputError(f"joint.kind must be one of {', '.join(self.KINDS)}, got {self.kind!r}")
        hook_keys = ("hook_length", "hook_bending_modulus", "hook_twist_modulus")
        if self.kind == "clamp":
            given = [k for k in hook_keys if getattr(self, k) is not None]
            if given or self.hook_segments:
                raise UserInputError(f"joint.{(given or ['hook_segments'])[0]} needs joint.kind = 'hook' "
                                     "(the clamp has no hook parameters)")
            return
        for k, unit in (("hook_length", "m"), ("hook_bending_modulus", "N m^2")):
            if getattr(self, k) is None:
                raise UserInputError(f"joint.{k} is required with joint.kind = 'hook' ({unit}; "
                                     "bacterial values in docs/hook.md)")
        _positive("joint.hook_length", self.hook_length, "m")
        _positive("joint.hook_bending_modulus", self.hook_bending_modulus,
                  "N m^2 (for the universal-joint limit give a small value, e.g. 1e-30)")
        if self.hook_twist_modulus is not None:
            _positive("joint.hook_twist_modulus", self.hook_twist_modulus, "N m^2")
        n = self.hook_segments
        if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or not (
                n == 0 or 2 <= n <= self.MAX_SEGMENTS):
            raise UserInputError(f"joint.hook_segments must be 0 (lumped) or an integer in "
                                 f"[2, {self.MAX_SEGMENTS}] (resolved), got {n!r}")

    @property
    def is_default(self) -> bool:
        return self == Joint()


def _set_vectors(obj, where: str, keys) -> None:
    """Each of ``obj``'s fields ``keys`` checked as 3 finite numbers and stored as a tuple."""
    for key in keys:
        v = getattr(obj, key)
        if not (isinstance(v, (list, tuple)) and len(v) == 3):
            raise UserInputError(f"{where}.{key} must be 3 numbers [x, y, z], got {v!r}")
        _set(obj, key, tuple(_finite(f"{where}.{key}", c) for c in v))


@dataclass(frozen=True)
class Wall:
    """A no-slip plane wall (``[[wall]]``, issue 32; docs/confinement.md): the plane through
    ``point`` [m, length unit] with ``normal`` pointing into the fluid (any length but zero).
    With hydrodynamics it screens the flow (the Rotne-Prager-Blake mobility,
    :mod:`flagwrap.hydrodynamics.wall`); always it repels the filament's beads with the body's
    contact law (``[contact]`` range, strength, potential) on their distance to the plane."""

    point: tuple = (0.0, 0.0, 0.0)
    normal: tuple = (0.0, 0.0, 1.0)

    def __post_init__(self, where: str = "wall"):
        _set_vectors(self, where, ("point", "normal"))
        if not math.hypot(*self.normal) > 0.0:
            raise UserInputError(f"{where}.normal must not be zero (it points into the fluid)")

    @property
    def unit_normal(self) -> np.ndarray:
        n = np.asarray(self.normal, float)
        return n / np.linalg.norm(n)


@dataclass(frozen=True)
class TubeWall:
    """A no-slip circular tube (``[[tube]]``, issue 32; docs/confinement.md, "Tubes"): radius
    ``radius`` and length ``length`` [m, length unit] about the axis through ``center`` along
    ``axis``, with an optional cosine constriction (``constriction_radius``,
    ``constriction_length``, ``constriction_center`` along the axis from ``center``), ends
    open or ``closed`` by discs. Discretised by blobs ``blob_spacing`` apart (default a tenth
    of the narrowest radius) of radius ``BLOB_RADIUS_RATIO`` times the spacing
    (:mod:`flagwrap.confinement.tube`); its beads meet it with the body's contact law."""

    radius: float = 1.0
    length: float = 1.0
    center: tuple = (0.0, 0.0, 0.0)
    axis: tuple = (0.0, 0.0, 1.0)
    constriction_radius: float | None = None
    constriction_length: float = 0.0
    constriction_center: float = 0.0
    closed: bool = False
    blob_spacing: float | None = None

    def __post_init__(self, where: str = "tube"):
        _set_vectors(self, where, ("center", "axis"))
        if not isinstance(self.closed, bool):
            raise UserInputError(f"{where}.closed must be true or false, got {self.closed!r}")
        if self.blob_spacing is not None:
            bs = _finite(f"{where}.blob_spacing", self.blob_spacing)
            if not bs > 0:
                raise UserInputError(f"{where}.blob_spacing must be > 0, got {bs!r}")
        self.geometry(1.0)  # radius, length, axis, constriction: checked by the geometry

    def geometry(self, unit: float):
        """The :class:`flagwrap.confinement.tube.Tube` in lengths of ``unit`` [m]."""
        from flagwrap.confinement.tube import Tube

        rc = self.constriction_radius
        return Tube(radius=self.radius / unit, length=self.length / unit,
                    center=tuple(c / unit for c in self.center), axis=self.axis,
                    constriction_radius=None if rc is None else rc / unit,
                    constriction_length=self.constriction_length / unit,
                    constriction_center=self.constriction_center / unit, closed=self.closed)

    @property
    def resolved_blob_spacing(self) -> float:
        if self.blob_spacing is not None:
            return float(self.blob_spacing)
        return 0.1 * (self.radius if self.constriction_radius is None
                      else self.constriction_radius)


@dataclass(frozen=True)
class Flagellum:
    """Where one flagellum sits on the cell body (issue 28; ``[[flagellum]]`` tables, one per
    flagellum; docs/bundle.md). Every flagellum is a copy of ``[filament]`` on its own
    ``[joint]`` and motor; no table is one flagellum at the pole, as before.

    Either on the pole cap of a "capped-cylinder" or "sphere" body: ``polar_deg`` [deg] from
    the pole (0 = the pole, the single flagellum's place; < 90, on the cap) and
    ``azimuth_deg`` [deg] about the body axis; the motor axis along the outward normal. Or
    anywhere (any body, or none): ``anchor`` [m, length unit], the point on the body surface
    where the motor holds the filament, and ``axis``, the motor axis (pointing out of the
    body). ``spin_deg`` [deg] turns the filament's shape about its motor axis (default: the
    azimuth, so that anchors spread by azimuth carry copies of one shape turned about the
    body axis: a symmetric tuft).

    ``protocol``: this flagellum's motor schedule, phases as ``motor.protocol``'s (default:
    ``motor.protocol``, which every motor without its own follows). It must last as long as
    ``motor.protocol`` (the run's length and the phases of its swimming summary), e.g. one
    motor reversing two turns after the others, or staying CCW while they reverse
    (docs/bundle.md).

    ``kind`` (with ``stall_torque`` [N m] and ``zero_load_speed`` [Hz] as ``[motor]``'s):
    this flagellum's motor law (default: ``motor.kind`` and its torques), e.g. one
    torque-limited motor among speed motors.
    """

    polar_deg: float | None = None
    azimuth_deg: float | None = None
    spin_deg: float | None = None
    anchor: tuple | None = None
    axis: tuple | None = None
    protocol: tuple | None = None
    kind: str | None = None
    stall_torque: float | None = None
    zero_load_speed: float | None = None

    def motor(self, motor: "Motor") -> "Motor":
        """This flagellum's motor: ``motor`` with this table's law (validated as
        ``[motor]``'s, the problem named ``flagellum.key``)."""
        if self.kind is None:
            if self.stall_torque is not None or self.zero_load_speed is not None:
                raise UserInputError("flagellum.stall_torque and zero_load_speed need "
                                     "flagellum.kind (the law they parametrise)")
            return motor
        try:
            return dataclasses.replace(motor, kind=self.kind, stall_torque=self.stall_torque,
                                       zero_load_speed=self.zero_load_speed)
        except UserInputError as exc:
            raise UserInputError(str(exc).replace("motor.", "flagellum.")) from None

    def __post_init__(self, where: str = "flagellum"):
        on_cap = self.polar_deg is not None or self.azimuth_deg is not None
        if on_cap and (self.anchor is not None or self.axis is not None):
            raise UserInputError(f"{where}: give polar_deg/azimuth_deg (on the pole cap) or "
                                 "anchor/axis (anywhere), not both")
        if not on_cap and (self.anchor is None or self.axis is None):
            missing = "anchor" if self.anchor is None else "axis"
            raise UserInputError(f"{where}.{missing} is missing: give polar_deg (and "
                                 "azimuth_deg) on the pole cap, or anchor and axis")
        if on_cap:
            polar = _finite(f"{where}.polar_deg", 0.0 if self.polar_deg is None else self.polar_deg)
            if not 0.0 <= polar < 90.0:
                raise UserInputError(f"{where}.polar_deg must be in [0, 90) deg (on the pole "
                                     f"cap), got {self.polar_deg!r}")
            _finite(f"{where}.azimuth_deg", 0.0 if self.azimuth_deg is None else self.azimuth_deg)
        else:
            for key in ("anchor", "axis"):
                v = getattr(self, key)
                if not (isinstance(v, (list, tuple)) and len(v) == 3):
                    raise UserInputError(f"{where}.{key} must be 3 numbers [x, y, z], got {v!r}")
                _set(self, key, tuple(_finite(f"{where}.{key}", c) for c in v))
            if not any(self.axis):
                raise UserInputError(f"{where}.axis must not be zero")
        if self.spin_deg is not None:
            _finite(f"{where}.spin_deg", self.spin_deg)
        if self.protocol is not None:
            if not isinstance(self.protocol, (list, tuple)) or not self.protocol:
                raise UserInputError(f"{where}.protocol must be a non-empty array of phases, "
                                     f"got {self.protocol!r}")
            _set(self, "protocol", tuple(p if isinstance(p, Phase) else Phase(**p)
                                         for p in self.protocol))


@dataclass(frozen=True)
class Contact:
    """Short-ranged repulsion between beads and the cell body (WCA form).

    ``range`` is the cut-off gap in units of the cross-section radius ``a`` (the potential acts
    when the bead centre is closer than ``a * (1 + range)`` to the body surface); ``strength``
    is the energy scale in units of ``A / b``. ``potential``: "wca-c2" (default) is WCA with
    its curvature at the cut-off subtracted, so the force has a continuous derivative there;
    "wca" is the plain WCA law, whose stiffness jumps at the cut-off. The jump made the
    error-controlled stepper reject every other step while beads slid over the body (Fig. 5
    case psi 45, n 2, M 5388, 5 + 7 turns, ``python studies/contact_law.py``: 20080 steps +
    11066 rejections, 53 s, against 6032 + 152, 12 s with "wca-c2"; free ends within
    1.5e-5 L; docs/model.md).

    ``self_contact = true`` adds the same law between non-neighbouring *segments* of the
    filament (:mod:`flagwrap.interactions.self_contact`), so that folded or wrapped parts
    cannot pass through each other; ``self_range`` (units of ``a``: the repulsion starts
    ``self_range a`` before the surfaces touch) and ``self_strength`` (units of ``A/b``) default
    to ``range`` and ``strength``. Off by default: the paper's rig has none, and results stored
    before it existed keep their keys.
    """

    range: float = 1.0
    strength: float = 1.0
    potential: str = "wca-c2"
    self_contact: bool = False
    self_range: float | None = None
    self_strength: float | None = None

    def __post_init__(self):
        _positive("contact.range", self.range, "(units of a)")
        _positive("contact.strength", self.strength, "(units of A/b)")
        if self.potential not in ("wca-c2", "wca"):
            raise UserInputError(f"contact.potential must be 'wca-c2' or 'wca', got {self.potential!r}")
        if not isinstance(self.self_contact, (bool, np.bool_)):
            raise UserInputError(f"contact.self_contact must be true or false, got {self.self_contact!r}")
        for k in ("self_range", "self_strength"):
            if getattr(self, k) is not None:
                if not self.self_contact:
                    raise UserInputError(f"contact.{k} needs contact.self_contact = true")
                _positive(f"contact.{k}", getattr(self, k), "(units of a)" if k == "self_range" else "(units of A/b)")

    @property
    def resolved_self_range(self) -> float:
        return self.range if self.self_range is None else float(self.self_range)

    @property
    def resolved_self_strength(self) -> float:
        return self.strength if self.self_strength is None else float(self.self_strength)


@dataclass(frozen=True)
class Numerics:
    """How to integrate.

    Attributes
    ----------
    integrator : {"ros34pw2", "ros2", "euler"}
        "ros34pw2" (default): adaptive, L-stable, 3rd-order Rosenbrock W-method (Rang &
        Angermann 2005); "ros2": adaptive, L-stable, 2nd-order (Verwer et al. 1999);
        "euler": the paper-style explicit Euler reference (fixed ``dt``). Long chains
        (N ~ 1000) where ~1e-3 L suffices: "ros2" is 2.4-6.8x faster at equal accuracy,
        because it steps over a fast soft twist mode that ROS34PW2 resolves; check it against
        a tighter run (docs/numerics.md, "Long chains: what sets the step").
    hydrodynamics : bool
        long-range Rotne-Prager-Yamakawa interactions on (True) or self mobility only.
    dt : float
        first (adaptive schemes) or fixed (euler) step, in motor turns ``T``.
    tol : float
        local error tolerance per step (positions in units of L; twist angles allowed 10x).
        With ros34pw2 the default 1e-5 keeps the free end within ~1e-3 L and the motor torque
        within ~0.5 % of a converged solution over a turn; loose tolerances are visibly wrong
        (ros2 at 1e-3 triggers a spurious CCW instability; see docs/numerics.md).
    threads : int
        BLAS threads for the dense linear algebra of one run, and numba threads of the direct
        RPY product above 256 beads (1 is fastest at N ~ 60 and lets sweeps run one case per
        core).
    mobility_backend : {"auto", "direct", "fmm", "jax"}
        how the RPY product ``Mob F`` is computed (:mod:`flagwrap.hydrodynamics.mobility`):
        "direct" numba O(N^2) sum, "fmm" FMM3D (needs ``fmm3dpy``), "jax" JAX direct sum
        (needs ``jax``; GPU when present). "auto": direct, or jax when jax sees a GPU and
        N >= 1250. All agree to 1e-10 (fmm: to ``mobility_tol``).
    mobility_tol : float
        requested relative precision of the FMM backend.
    max_wall_time : float
        wall-clock budget of one run in seconds (0: none). A run that exceeds it stops with
        status "failed", a message naming this option, and every frame computed so far (a
        sweep records the case as failed; ``flagwrap sweep --retry-failed`` reruns it).
    linear_solver : {"auto", "dense", "near", "krylov", "banded", "sparse"}
        solver of the Rosenbrock stage equations (:mod:`flagwrap.integrators.linear`): exact
        dense LU, banded LU of the near-field ``W`` (a W-method approximation, O(N)), GCR
        (matrix-free, banded near-field preconditioner, recycled across stages, operator
        products in float32 from 256 beads with the direct backend and one thread; to rtol
        1e-3 and 0.1 x the step tolerance per unknown), or exact banded / sparse LU (HI off only). "auto":
        banded with HI off; with HI dense up to 400 unknowns (N ~ 100), GCR above (measured
        crossover).
    dt_min : float
        smallest step [turns] before the run is declared stuck.
    save_every : float
        output interval [turns].
    max_steps : int
        hard cap on the number of steps.
    frame : {"lab", "rotating"}
        the frame the equations are stepped in (:mod:`flagwrap.system.rotating`). "lab"
        (default, the reference): the clamp turns. "rotating": the frame turns with the motor,
        so a steadily whirling helix stands still and the step grows to the output interval
        (docs/stability.md measures the speed-up and the accuracy). Run files are in the lab
        frame either way. It needs a system symmetric about the motor axis (every system
        flagwrap builds today is).
    """

    integrator: str = "ros34pw2"
    hydrodynamics: bool = True
    dt: float = 1e-3
    tol: float = 1e-5
    dt_min: float = 1e-12
    save_every: float = 0.05
    max_steps: int = 50_000_000
    threads: int = 1
    mobility_backend: str = "auto"
    mobility_tol: float = 1e-10
    linear_solver: str = "auto"
    max_wall_time: float = 0.0
    frame: str = "lab"

    # options left out of result keys at their defaults (Config.to_dict(for_hash)): added
    # after results were stored, their defaults are what those results used
    HASH_OMIT_DEFAULTS = {"mobility_backend": "auto", "mobility_tol": 1e-10, "linear_solver": "auto",
                          "max_wall_time": 0.0, "frame": "lab"}

    def __post_init__(self):
        from flagwrap.hydrodynamics.mobility import BACKENDS, backend_missing

        if self.mobility_backend not in BACKENDS:
            raise UserInputError(f"numerics.mobility_backend must be one of {', '.join(BACKENDS)}, "
                                 f"got {self.mobility_backend!r}")
        why = backend_missing(self.mobility_backend)
        if why:
            raise UserInputError(f"numerics.mobility_backend = {self.mobility_backend!r} {why}")
        tol_m = _positive("numerics.mobility_tol", self.mobility_tol)
        if tol_m > 1e-2:
            raise UserInputError(f"numerics.mobility_tol must be in (0, 1e-2], got {tol_m}")
        if isinstance(self.max_wall_time, bool) or not isinstance(self.max_wall_time, (int, float)) \
                or not math.isfinite(self.max_wall_time) or self.max_wall_time < 0:
            raise UserInputError(f"numerics.max_wall_time must be a number of seconds >= 0 "
                                 f"(0: no limit), got {self.max_wall_time!r}")
        solvers = ("auto", "dense", "near", "krylov", "banded", "sparse")
        if self.linear_solver not in solvers:
            raise UserInputError(f"numerics.linear_solver must be one of {', '.join(solvers)}, "
                                 f"got {self.linear_solver!r}")
        if self.linear_solver in ("banded", "sparse") and self.hydrodynamics:
            raise UserInputError(f"numerics.linear_solver = {self.linear_solver!r} needs "
                                 "numerics.hydrodynamics = false (it is exact only for a local "
                                 "mobility); use 'auto'")
        if self.frame not in ("lab", "rotating"):
            raise UserInputError(f"numerics.frame must be 'lab' or 'rotating', got {self.frame!r}")
        if self.integrator not in ("ros34pw2", "ros2", "euler"):
            raise UserInputError(
                "numerics.integrator must be 'ros34pw2', 'ros2' or 'euler', "
                f"got {self.integrator!r}"
            )
        if not isinstance(self.hydrodynamics, bool):
            raise UserInputError(
                f"numerics.hydrodynamics must be true or false, got {self.hydrodynamics!r}"
            )
        dt = _positive("numerics.dt", self.dt, "turns")
        if dt > 0.5:
            raise UserInputError(f"numerics.dt must be <= 0.5 turns, got {dt}")
        tol = _positive("numerics.tol", self.tol)
        if tol > 0.1:
            raise UserInputError(f"numerics.tol must be in (0, 0.1], got {tol}")
        _positive("numerics.dt_min", self.dt_min, "turns")
        _positive("numerics.save_every", self.save_every, "turns")
        if isinstance(self.max_steps, bool) or not isinstance(self.max_steps, (int, np.integer)):
            raise UserInputError(f"numerics.max_steps must be an integer, got {self.max_steps!r}")
        if self.max_steps < 1:
            raise UserInputError(f"numerics.max_steps must be >= 1, got {self.max_steps}")
        if isinstance(self.threads, bool) or not isinstance(self.threads, (int, np.integer)) \
                or not 1 <= self.threads <= 256:
            raise UserInputError(f"numerics.threads must be an integer in [1, 256], got {self.threads!r}")


@dataclass(frozen=True)
class Initial:
    """The initial state: the stress-free rest shape, optionally perturbed (issue 15).

    ``perturbation`` [m]: the largest displacement of a bead from the rest shape (0: start at
    rest, the default). ``mode = "random"``: a smooth random displacement field, the sum of the
    first four sine modes along the contour in each direction with normal random amplitudes
    from ``seed``; ``"lateral"``: along x. Both grow as ``(s/L)^2`` from the clamp, so the
    clamped beads stay put and the rod leaves the clamp smoothly. A seed perturbation breaks the
    symmetry a buckling instability would otherwise wait on round-off to break.
    """

    perturbation: float = 0.0
    mode: str = "random"
    seed: int = 0

    MODES = ("random", "lateral")

    def __post_init__(self):
        v = _finite("initial.perturbation", self.perturbation)
        if v < 0:
            raise UserInputError(f"initial.perturbation must be >= 0 m, got {v!r}")
        if self.mode not in self.MODES:
            raise UserInputError(f"initial.mode must be one of {', '.join(self.MODES)}, got {self.mode!r}")
        if isinstance(self.seed, bool) or not isinstance(self.seed, (int, np.integer)) or not 0 <= self.seed < 2**63:
            raise UserInputError(f"initial.seed must be an integer in [0, 2^63), got {self.seed!r}")

    @property
    def is_default(self) -> bool:
        return self == Initial()


@functools.lru_cache(maxsize=1)
def _polymorph_library():
    """The packaged polymorph library, parsed once per process."""
    from flagwrap.elasticity.polymorph_library import default_library

    return default_library()


@dataclass(frozen=True)
class Polymorph:
    """A polymorphic filament (docs/polymorph.md): an order parameter ``phi`` per bead,
    ``-1`` the library's polymorph ``polymorph_a``, ``+1`` ``polymorph_b``, with the energy
    (P3) ``sum_i v_i W (1 - phi_i^2)^2 / 4 + sum_j K / (2 l_j) (phi_{j+1} - phi_j)^2`` and the
    first-order kinetics ``dphi_i/dt = -(Gamma / v_i) dE/dphi_i`` (continuum:
    ``phi_t = -Gamma (W f'(phi) - K phi_ss)``).

    ``barrier`` ``W`` [N] (energy per length), ``stiffness`` ``K`` [N m^2] (``units.bending``
    applies), both required when enabled; ``rate`` ``Gamma`` [1/(N s)], not published: default
    (None) ``Gamma = 5 omega / W``, a uniform well relaxing (rate ``2 Gamma W``) ten times per
    radian of the reference motor turn, allowed ``(0, 1e6)`` times that; ``initial``: ``"a"``,
    ``"b"`` (uniform) or ``"wall"`` (the tanh wall (P4) from A at the motor to B at the free
    end, centred at ``wall_position`` of the contour). ``maxwell_torque`` ``N_M`` [N m]: the
    twist moment (right-handed positive about the tangent, the rod's convention) at which the
    two polymorphs are equally stable (P7); default 0 (no intrinsic energy difference: none
    is published), any finite value: at zero load the wells differ by ``N_M Delta`` per
    length (``Delta``: B's rest twist density minus A's).

    ``transition``: a transition of the library (from ``polymorph_a``'s form to
    ``polymorph_b``'s; another organism's is allowed, as a stand-in) instead of ``barrier``, ``stiffness`` and ``maxwell_torque``: its two
    torques read as the spinodals of (P6) and ``domain_wall_width`` ``w`` [m] (or the
    library's) give ``N_M``, ``W``, ``K`` (:meth:`PolymorphModel.from_thresholds`, with the
    rod's own ``Delta``). The library quotes Hotani's signs (``from -> to`` at a negative
    torque); the rod's convention is the opposite (a right-handed twist moment favours the
    right-handed form), so the torques enter with their signs flipped (docs/polymorph.md,
    "Sign").
    """

    enabled: bool = False
    polymorph_a: str = "ecoli_normal"
    polymorph_b: str = "ecoli_semicoiled"
    barrier: float | None = None
    stiffness: float | None = None
    rate: float | None = None
    initial: str = "a"
    wall_position: float = 0.5
    maxwell_torque: float = 0.0
    transition: str | None = None
    domain_wall_width: float | None = None

    INITIAL = ("a", "b", "wall")
    #: most ``rate`` may exceed its default by (a stiff but finite kinetics)
    MAX_RATE_FACTOR = 1e6

    def __post_init__(self):
        if not isinstance(self.enabled, bool):
            raise UserInputError(f"polymorph.enabled must be true or false, got {self.enabled!r}")
        lib = _polymorph_library()
        for key in ("polymorph_a", "polymorph_b"):
            name = getattr(self, key)
            try:
                lib.polymorph(name).curvature_torsion_per_um()
            except UserInputError as exc:
                raise UserInputError(f"polymorph.{key}: {exc}") from None
        for key in ("barrier", "stiffness", "rate"):
            v = getattr(self, key)
            if v is not None:
                _positive(f"polymorph.{key}", v, {"barrier": "N", "stiffness": "N m^2",
                                                   "rate": "1/(N s)"}[key])
        if self.domain_wall_width is not None:
            _positive("polymorph.domain_wall_width", self.domain_wall_width, "m")
        if self.transition is not None:
            self._check_transition(lib)
        elif self.domain_wall_width is not None:
            raise UserInputError("polymorph.domain_wall_width goes with polymorph.transition; "
                                 "without one the wall is sqrt(2 stiffness / barrier)")
        if self.enabled and self.transition is None:
            for key, unit in (("barrier", "N"), ("stiffness", "N m^2")):
                if getattr(self, key) is None:
                    raise UserInputError(f"polymorph.{key} is required when polymorph.enabled "
                                         f"= true (a value in (0, inf) {unit}), or name a "
                                         "polymorph.transition of the library")
        if self.initial not in self.INITIAL:
            raise UserInputError(f"polymorph.initial must be one of {', '.join(self.INITIAL)}, "
                                 f"got {self.initial!r}")
        _finite("polymorph.maxwell_torque", self.maxwell_torque)
        v = _finite("polymorph.wall_position", self.wall_position)
        if not 0.0 < v < 1.0:
            raise UserInputError(f"polymorph.wall_position must be in (0, 1) (a fraction of "
                                 f"the contour), got {self.wall_position!r}")

    def _check_transition(self, lib) -> None:
        if not isinstance(self.transition, str):
            raise UserInputError(f"polymorph.transition must be a name, got {self.transition!r}")
        try:
            t = lib.transition(self.transition)
        except UserInputError as exc:
            raise UserInputError(f"polymorph.transition: {exc}") from None
        # the forms must match; the organism may differ (a stand-in, said in the docs)
        forms = (lib.polymorph(t.from_key).form, lib.polymorph(t.to_key).form)
        mine = (lib.polymorph(self.polymorph_a).form, lib.polymorph(self.polymorph_b).form)
        if forms != mine:
            raise UserInputError(
                f"polymorph.transition {t.key!r} goes from the {forms[0]} to the {forms[1]} "
                f"form, but polymorph_a, polymorph_b are {mine[0]} and {mine[1]}")
        given = [k for k in ("barrier", "stiffness") if getattr(self, k) is not None]
        given += ["maxwell_torque"] if self.maxwell_torque != 0.0 else []
        if given:
            raise UserInputError(f"polymorph.transition gives the landscape: drop "
                                 f"{', '.join('polymorph.' + k for k in given)} (or the transition)")
        for name in ("torque_forward_pn_um", "torque_back_pn_um"):
            if getattr(t, name).value is None:
                raise UserInputError(f"polymorph.transition {t.key!r}: {name} is a gap in the "
                                     "library; give barrier, stiffness and maxwell_torque instead")
        if self.domain_wall_width is None and t.wall_width_um.value is None:
            raise UserInputError(
                f"polymorph.domain_wall_width is required with polymorph.transition = "
                f"{t.key!r}: the library has no wall width (a gap: {t.wall_width_um.source}); "
                "give one in [the bead spacing, inf) m")

    @property
    def is_default(self) -> bool:
        return self == Polymorph()

    def wall_width(self) -> float:
        """``w`` [m] of the tanh wall (P4): ``sqrt(2 K / W)``, or with a ``transition`` its
        ``domain_wall_width`` (else the library's)."""
        if self.transition is not None:
            if self.domain_wall_width is not None:
                return float(self.domain_wall_width)
            return _polymorph_library().transition(self.transition).wall_width_um.value * 1e-6
        return math.sqrt(2.0 * self.stiffness / self.barrier)

    def landscape(self, scales, delta: float) -> tuple[float, float, float, float]:
        """``(W, K, Gamma, N_M)`` in core units for a filament whose ``Delta`` (B's rest twist
        density minus A's) is ``delta`` [1/L]: the given values, or those of the
        ``transition`` (class docstring; :meth:`PolymorphModel.from_thresholds`)."""
        if self.transition is None:
            W, K, G = self.core(scales)
            return W, K, G, self.core_maxwell_torque(scales)
        from flagwrap.elasticity.polymorph import PolymorphModel

        t = _polymorph_library().transition(self.transition)
        to_core = 1e-18 / scales.torque  # pN um -> A/L
        try:
            m = PolymorphModel.from_thresholds(-t.torque_forward_pn_um.value * to_core,
                                               -t.torque_back_pn_um.value * to_core, delta,
                                               self.wall_width() / scales.length)
        except UserInputError as exc:
            raise UserInputError(f"polymorph.transition {t.key!r} on this filament: {exc}") from None
        W, K = m.barrier, m.stiffness
        G = 5.0 / W if self.rate is None else self.rate * scales.force / scales.omega
        return W, K, G, m.maxwell_torque

    def core_maxwell_torque(self, scales) -> float:
        """``N_M`` in core units ``[A/L]``."""
        return self.maxwell_torque / scales.torque

    def core(self, scales) -> tuple[float, float, float]:
        """``(W, K, Gamma)`` in core units, given ``barrier`` and ``stiffness`` (``W`` per ``A/L^2``, ``K`` per ``A``, ``Gamma`` per
        ``L^2 / (A T)``); the default rate ``Gamma = 5 / W`` (core)."""
        W = self.barrier / scales.force
        K = self.stiffness / scales.bending
        G = 5.0 / W if self.rate is None else self.rate * scales.force / scales.omega
        return W, K, G


@dataclass(frozen=True)
class Config:
    """Everything that defines one run."""

    filament: Filament
    motor: Motor
    fluid: Fluid = field(default_factory=Fluid)
    body: CellBody = field(default_factory=CellBody)
    contact: Contact = field(default_factory=Contact)
    numerics: Numerics = field(default_factory=Numerics)
    clamp: Clamp = field(default_factory=Clamp)
    initial: Initial = field(default_factory=Initial)
    joint: Joint = field(default_factory=Joint)
    #: the polymorphic state (``[polymorph]``); default: off, the fixed-shape rod
    polymorph: Polymorph = field(default_factory=Polymorph)
    #: one per flagellum (``[[flagellum]]``); empty: one flagellum at the pole
    flagella: tuple = ()
    #: no-slip plane walls (``[[wall]]``); empty: free space
    walls: tuple = ()
    #: no-slip tubes (``[[tube]]``); empty: none
    tubes: tuple = ()
    name: str = "run"

    def __post_init__(self):
        for attr, cls in (
            ("filament", Filament),
            ("motor", Motor),
            ("fluid", Fluid),
            ("body", CellBody),
            ("contact", Contact),
            ("numerics", Numerics),
            ("clamp", Clamp),
            ("initial", Initial),
            ("joint", Joint),
            ("polymorph", Polymorph),
        ):
            if not isinstance(getattr(self, attr), cls):
                raise UserInputError(f"config.{attr} must be a {cls.__name__}")
        _set(self, "flagella", tuple(self.flagella))
        for k, f in enumerate(self.flagella):
            if not isinstance(f, Flagellum):
                raise UserInputError(f"config.flagella[{k}] must be a Flagellum")
        _set(self, "walls", tuple(self.walls))
        for k, w in enumerate(self.walls):
            if not isinstance(w, Wall):
                raise UserInputError(f"config.walls[{k}] must be a Wall")
        _set(self, "tubes", tuple(self.tubes))
        for k, t in enumerate(self.tubes):
            if not isinstance(t, TubeWall):
                raise UserInputError(f"config.tubes[{k}] must be a TubeWall")
        fil = self.filament
        if fil.density_mismatch is not None:
            # resolved to a density here, where the fluid's is known (as pitch-like inputs
            # are resolved to the pitch): the stored config holds the density only
            rho = self.fluid.density * (1.0 + float(fil.density_mismatch))
            if not rho > 0:
                raise UserInputError(
                    f"filament.density_mismatch={fil.density_mismatch!r} with fluid.density="
                    f"{self.fluid.density!r} kg/m^3 gives no positive filament density; give "
                    "filament.density instead")
            fil = fil.with_density(rho)
            _set(self, "filament", fil)
        if self.body.enabled:
            rc = self.body.resolved_radius(fil.helix_radius)
            a = fil.cross_section_radius
            if not 2 * a < rc <= MAX_BODY_OVER_LENGTH * fil.length:
                how = ("body.radius" if self.body.radius is not None else
                       f"body.radius_ratio = {self.body.radius_ratio:g} (R / R_cell)")
                raise UserInputError(
                    f"{how} gives a cell body of radius {rc:.3g} m; it must be wider than the "
                    f"filament (> 2 a = {2 * a:.3g} m) and at most {MAX_BODY_OVER_LENGTH:g} L = "
                    f"{MAX_BODY_OVER_LENGTH * fil.length:.3g} m (or set body.enabled = false)")
        if self.polymorph.enabled:
            self._check_polymorph()
        if self.flagella:
            from flagwrap.system.parts import check_flagella

            check_flagella(self)
        if not self.initial.perturbation <= 0.5 * fil.length:
            raise UserInputError(
                f"initial.perturbation (--perturb) = {self.initial.perturbation:g} m must be at "
                f"most half the "
                f"filament (0.5 L = {0.5 * fil.length:g} m): it is a seed displacement, meant small")
        if self.clamp.lead == "connector":
            from flagwrap.system.parts import check_connector

            check_connector(self)
        if self.walls:
            from flagwrap.system.parts import check_walls

            check_walls(self)
        if self.tubes:
            from flagwrap.system.parts import check_tubes

            check_tubes(self)
        if fil.hydrodynamic_model == "tube" and not self.numerics.hydrodynamics:
            raise UserInputError("filament.hydrodynamic_model = 'tube' needs numerics."
                                 "hydrodynamics = true (it is matched with the chain's "
                                 "interactions); without them use 'spheres'")
        if self.body.no_slip or self.body.free:
            self._check_surface_body()
        if self.motor.kind != "speed":
            if self.numerics.linear_solver not in ("auto", "dense"):
                raise UserInputError(
                    f"numerics.linear_solver = {self.numerics.linear_solver!r} cannot take a "
                    f"motor.kind = {self.motor.kind!r} motor (its row couples the whole W): use "
                    "'auto' or 'dense'")
            if self.numerics.frame != "lab" and not self.body.free:
                raise UserInputError(f"numerics.frame = 'rotating' needs motor.kind = 'speed' "
                                     f"(a {self.motor.kind} motor's rate is not known ahead) "
                                     "except on a free cell (body.motion = 'free')")
        # beads that are not contour neighbours must not overlap in the stress-free helix
        from flagwrap.geometry.helix import min_nonlocal_distance

        dmin = min_nonlocal_distance(fil, self.clamp)
        if dmin < 2 * fil.cross_section_radius:
            raise UserInputError(
                f"initial helix self-overlaps: two non-neighbouring beads are {dmin:g} m apart, "
                f"less than 2 a = {2 * fil.cross_section_radius:g} m (increase pitch or reduce a)"
            )
        if self.joint.kind == "hook" and not self.joint.hook_length < fil.length:
            raise UserInputError(f"joint.hook_length = {self.joint.hook_length:g} m must be shorter "
                                 f"than the filament (filament.length = {fil.length:g} m)")
        if self.joint.kind == "hook":
            # a hook stiffer than ~1e6 x the filament over its length is a clamp, and its
            # spring's time scale leaves no step the integrator can take (1e308 N m^2 ran and
            # failed at its first step with a singular matrix)
            for key in ("hook_bending_modulus", "hook_twist_modulus"):
                v = getattr(self.joint, key)
                if v is None:
                    continue
                k = v * fil.length / (fil.bending_modulus * self.joint.hook_length)
                if not k <= Joint.MAX_STIFFNESS:
                    raise UserInputError(
                        f"joint.{key} = {v:g} N m^2 gives a hook {k:.3g} x stiffer than the filament "
                        f"({key} L / (A hook_length)); allowed: up to {Joint.MAX_STIFFNESS:g}, i.e. "
                        f"{key} <= {Joint.MAX_STIFFNESS * fil.bending_modulus * self.joint.hook_length / fil.length:.3g} "
                        "N m^2 (a stiffer hook is the clamp: drop [joint])")
        if self.contact.self_contact:
            from flagwrap.interactions.self_contact import max_self_range

            rmax = max_self_range(self)
            if not self.contact.resolved_self_range < rmax:
                raise UserInputError(
                    f"contact.self_range = {self.contact.resolved_self_range:g} (units of a) puts "
                    "the stress-free filament in contact with itself (non-neighbouring segments "
                    f"closer than its cut-off a (2 + self_range)); allowed: self_range < {rmax:.3g}")
        # derived scales must be finite and positive (extreme inputs can overflow or underflow)
        derived = {}
        for what in ("bending_modulus", "twist_modulus", "omega", "machin", "reynolds"):
            try:
                v = getattr(fil, what) if what.endswith("modulus") else getattr(self, what)
            except (OverflowError, ZeroDivisionError):
                v = math.nan
            derived[what] = v
            if not math.isfinite(v) or v < 0 or (v == 0 and what != "reynolds"):
                raise UserInputError(
                    f"derived {what} = {v!r} is not a finite positive number "
                    f"({', '.join(f'{k} = {x:g}' for k, x in derived.items())}): the inputs "
                    "(filament.youngs_modulus, cross_section_radius, length, fluid.viscosity, "
                    "motor.machin/frequency) are out of physical range")

    def _check_surface_body(self):
        """A no-slip or free body: its blob surface, the hydrodynamics it needs, the motor."""
        from flagwrap.body.multiblob import cell_body_blobs, check_spacing

        b, R = self.body, self.filament.helix_radius
        if not self.numerics.hydrodynamics:
            raise UserInputError("body.surface = 'no-slip' needs numerics.hydrodynamics = true "
                                 "(without hydrodynamic interactions a surface screens nothing)")
        rc, sp = b.resolved_radius(R), b.resolved_blob_spacing(R)
        if not sp < rc:
            raise UserInputError(f"body.blob_spacing = {sp:g} m must be smaller than the body "
                                 f"radius {rc:g} m")
        from flagwrap.body.shapes import config_shape
        from flagwrap.body.solver import AUTO_DIRECT_MAX

        # the count from the surface's area first: building ~1e14 blobs would not end
        mesh = config_shape(self, unit=1.0).surface_mesh()
        if mesh is not None:
            v, tri = mesh
            area = 0.5 * float(np.linalg.norm(np.cross(v[tri[:, 1]] - v[tri[:, 0]],
                                                       v[tri[:, 2]] - v[tri[:, 0]]), axis=1).sum())
            estimate = area / (sp * sp)
            if estimate > 4 * MAX_BLOBS_KRYLOV:
                raise UserInputError(
                    f"body.blob_spacing = {sp:g} m would put ~{estimate:.2g} blobs on the body "
                    f"(area {area:.3g} m^2), more than any solve takes ({MAX_BLOBS_KRYLOV}); use "
                    f"a spacing >= {sp * math.sqrt(estimate / MAX_BLOBS_KRYLOV):.3g} m")
        blobs, _ = cell_body_blobs(self)

        direct = b.solver == "direct" or (b.solver == "auto" and len(blobs) <= AUTO_DIRECT_MAX)
        most = MAX_BLOBS if direct else MAX_BLOBS_KRYLOV
        if len(blobs) > most:
            raise UserInputError(
                f"body.blob_spacing = {sp:g} m puts {len(blobs)} blobs on the body, more than "
                f"{most} (the {'direct' if direct else 'Krylov'} solve's limit); use a spacing >= "
                f"{sp * math.sqrt(len(blobs) / most):.3g} m"
                + (" or body.solver = 'krylov'" if direct else ""))
        check_spacing(blobs * self.filament.length, b.resolved_blob_radius(R),
                      what="body.blob_radius [m]")
        if self.numerics.frame != "lab" and not b.free:
            raise UserInputError("numerics.frame = 'rotating' needs a body symmetric about the "
                                 "motor axis; a held blob surface is not: use numerics.frame = "
                                 "'lab'")
        if b.free:
            if self.numerics.linear_solver not in ("auto", "dense", "krylov"):
                raise UserInputError(
                    f"numerics.linear_solver = {self.numerics.linear_solver!r} with body.motion = "
                    "'free': a free cell's stage solver is 'dense' (the default, 'auto') or "
                    "'krylov'")
            if all(p.direction == "stop" for p in self.motor.protocol):
                raise UserInputError("body.motion = 'free' needs a motor that turns: every phase "
                                     "of motor.protocol is 'stop'")
            if self.filament.density is not None and self.filament.density != self.fluid.density:
                raise UserInputError(
                    "body.motion = 'free' with a filament of density "
                    f"{self.filament.density:g} kg/m^3 != fluid.density {self.fluid.density:g}: "
                    "gravity on a swimming cell is not modelled yet; give no filament.density")

    # derived dimensionless numbers -------------------------------------------------------------
    @property
    def omega(self) -> float:
        """Reference motor angular speed [rad/s]."""
        if self.motor.frequency is not None:
            return 2 * math.pi * self.motor.frequency
        fil = self.filament
        return self.motor.machin * fil.bending_modulus / (self.fluid.viscosity * fil.length**4)

    @property
    def scales(self) -> units.Scales:
        return units.Scales(
            length=self.filament.length,
            omega=self.omega,
            bending=self.filament.bending_modulus,
            viscosity=self.fluid.viscosity,
        )

    @property
    def machin(self) -> float:
        """``M = eta omega L^4 / A``."""
        return self.scales.machin

    @property
    def reynolds(self) -> float:
        """``Re = rho R^2 omega / eta``."""
        return units.reynolds_number(
            self.fluid.density, self.filament.helix_radius, self.omega, self.fluid.viscosity
        )

    @property
    def density_mismatch(self) -> float:
        """``(rho - rho_f) / rho_f`` of the filament (0 when density-matched or
        ``fluid.density = 0``)."""
        rho = self.filament.density
        if rho is None or self.fluid.density == 0:
            return 0.0
        return (rho - self.fluid.density) / self.fluid.density

    @property
    def gravity_number(self) -> float:
        """``G = (rho_f - rho) g pi a^2 L^3 / A`` (:func:`flagwrap.units.gravity_number`):
        > 0 buoyant (compresses the hanging filament), 0 density-matched."""
        fil = self.filament
        if fil.density is None:
            return 0.0
        return units.gravity_number(self.fluid.density - fil.density, fil.cross_section_radius,
                                    fil.length, fil.bending_modulus)

    @property
    def machin_critical_scaling(self) -> float:
        """Scaling estimate ``M_c = 0.06 (R/L)^-3`` of the paper's Fig. 5 (not a simulation result)."""
        return PAPER_MC_PREFACTOR * (self.filament.helix_radius / self.filament.length) ** -3

    @property
    def omega_ratio_scaling(self) -> float:
        """``omega / omega_c`` estimated from the scaling line, ``M / M_c``."""
        return self.machin / self.machin_critical_scaling

    def replace(self, **changes) -> "Config":
        return dataclasses.replace(self, **changes)

    def _check_polymorph(self) -> None:
        """Refuse a ``[polymorph]`` this version cannot run (one line naming the key): its
        wall narrower than a bond (unresolved, docs/polymorph.md), or a filament of the other
        hand than ``polymorph_a``."""
        from flagwrap.elasticity.polymorph import check_wall_resolution

        pm, fil = self.polymorph, self.filament
        check_wall_resolution(pm.wall_width(), fil.bond_length,
                              "polymorph.domain_wall_width [m]" if pm.transition is not None
                              else "polymorph wall width sqrt(2 stiffness / barrier) [m]")
        hand_a = _polymorph_library().polymorph(pm.polymorph_a).handedness.value
        if fil.shape == "helix" and fil.handedness != hand_a:
            # B's hand is taken relative to the filament's (polymorph_geometry): a filament
            # of the other hand would turn the switch around
            raise UserInputError(
                f"filament.handedness = {fil.handedness!r} but polymorph.polymorph_a = "
                f"{pm.polymorph_a!r} is {hand_a}-handed: the configured filament is polymorph A")

    def to_dict(self, for_hash: bool = False) -> dict:
        """Plain nested dict (JSON/TOML-able); ``None`` values are dropped.

        ``for_hash``: also drop the numerics options added after results were first stored
        (``Numerics.HASH_OMIT_DEFAULTS``) when they hold their defaults, so run/sweep keys
        of existing results stay valid when a new option appears.
        """

        def clean(obj):
            if dataclasses.is_dataclass(obj):
                return {k: clean(v) for k, v in dataclasses.asdict(obj).items() if v is not None}
            if isinstance(obj, dict):
                return {k: clean(v) for k, v in obj.items() if v is not None}
            if isinstance(obj, (list, tuple)):
                return [clean(v) for v in obj]
            return obj

        d = clean(self)
        if self.polymorph.is_default:  # off: the config reads and hashes as before
            d.pop("polymorph", None)
        # one table per flagellum, as the TOML has them ([[flagellum]]); none: the default
        fl = d.pop("flagella", [])
        if fl:
            d["flagellum"] = fl
        walls = d.pop("walls", [])
        if walls:
            d["wall"] = walls
        tubes = d.pop("tubes", [])
        if tubes:
            d["tube"] = tubes
        # pitch-like inputs are all stored after resolution; keep only pitch (canonical)
        d["filament"].pop("pitch_angle_deg", None)
        d["filament"].pop("turns", None)
        if for_hash:
            # added after results were stored: their defaults keep the keys
            if self.filament.shape == "helix":
                d["filament"].pop("shape", None)
            if self.initial.is_default:
                d.pop("initial", None)
            if self.joint.is_default:
                d.pop("joint", None)
            if not self.contact.self_contact:
                d["contact"].pop("self_contact", None)

            for section, cls in (("numerics", Numerics), ("body", CellBody), ("motor", Motor)):
                for k, v in cls.HASH_OMIT_DEFAULTS.items():
                    if d[section].get(k) == v:
                        d[section].pop(k)
        return d
