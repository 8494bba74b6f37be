"""The parts of a system: filaments, each on its own motor at its own anchor.

A :class:`FilamentPart` is one flagellum: its stress-free shape (placed at its anchor), its
joint (clamp or hook), its rest state (per-vertex stiffnesses), its rotational drags and
gravity, and where its beads, bonds and unknowns sit in the system's arrays. The system
(:class:`~flagwrap.system.rod_system.RodSystem`) holds a list of them, concatenates their
beads and bonds (filament ``k`` owns beads ``bead0 .. bead0 + N - 1`` and bonds
``bond0 .. bond0 + N - 2``) and lays out its unknowns as

    y = [x_free (3 n_b, every filament's free beads in order),
         theta_free (n_e, every filament's free bonds in order),
         phi (one motor angle per filament)],

so a single filament's layout is the one the integrators have always read,
``[x_free, theta_free, phi]``. Each part evaluates its own forces with the fused kernel on
its own unknowns ``y[part.ymap]`` (in the kernel's order ``[x, theta, phi]``); the parts
meet through the mobility (one over all free beads) and the interactions (contact).

:class:`Placement` puts the default shape (built at the origin, motor axis ``-z``, the body
above) at an anchor on the body surface with its motor axis along the surface normal
(on the body shape's pole cap: :meth:`flagwrap.body.shapes.BodyShape.pole_cap`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from flagwrap.elasticity.rod import initial_frames, rest_state

#: the default shape's motor axis (out of the body's lowest point, down the body axis)
DEFAULT_AXIS = np.array([0.0, 0.0, -1.0])


@dataclass(frozen=True)
class Placement:
    """A rigid placement ``x -> origin + R x`` of the default shape: its anchor ``origin``
    [L] and rotation ``R`` (3, 3); the motor axis becomes ``R (0, 0, -1)``."""

    origin: tuple = (0.0, 0.0, 0.0)
    rotation: tuple = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))

    @property
    def R(self) -> np.ndarray:
        return np.asarray(self.rotation, float)

    @property
    def axis(self) -> np.ndarray:
        return self.R @ DEFAULT_AXIS

    @property
    def identity(self) -> bool:
        return not np.any(self.origin) and np.array_equal(self.R, np.eye(3))

    def apply(self, x: np.ndarray) -> np.ndarray:
        """The shape ``x`` (n, 3) placed (the identity returns ``x`` itself, bit for bit)."""
        if self.identity:
            return x
        return np.asarray(self.origin, float) + x @ self.R.T

    @classmethod
    def from_axis(cls, origin, axis, spin: float = 0.0) -> "Placement":
        """The placement with anchor ``origin`` and motor axis ``axis`` (any length > 0): the
        default shape turned by ``spin`` [rad] about its own axis, then tilted from ``-z`` to
        ``axis`` about ``-z x axis`` (the shortest rotation)."""
        a = np.asarray(axis, float)
        n = np.linalg.norm(a)
        if not (np.all(np.isfinite(a)) and n > 0):
            raise ValueError(f"Placement: the motor axis must be a finite non-zero vector, got {axis!r}")
        a = a / n
        c, s = math.cos(spin), math.sin(spin)
        Rz = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
        k = np.cross(DEFAULT_AXIS, a)
        sk, ck = np.linalg.norm(k), float(DEFAULT_AXIS @ a)
        if sk < 1e-15:
            T = np.eye(3) if ck > 0 else np.diag([1.0, -1.0, -1.0])
        else:
            k = k / sk
            K = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
            T = np.eye(3) + sk * K + (1.0 - ck) * (K @ K)
        R = T @ Rz
        return cls(tuple(float(v) for v in origin), tuple(tuple(float(v) for v in r) for r in R))


def cap_placement(cap_radius: float, polar: float, azimuth: float, spin: float | None = None
                  ) -> Placement:
    """An anchor on the pole cap of the capped cylinder (body axis ``z``, the cap's lowest
    point at the origin, its centre at ``(0, 0, cap_radius)``): at ``polar`` [rad] from the
    pole and ``azimuth`` [rad] about the body axis, motor axis along the outward normal.
    ``spin`` (default ``azimuth``) turns the shape about its own axis, so that anchors spread
    by azimuth carry copies of one shape turned about the body axis (a symmetric tuft)."""
    from flagwrap.body.shapes import CappedCylinderShape

    origin, n = CappedCylinderShape(cap_radius, 0.0).pole_cap(polar, azimuth)
    return Placement.from_axis(origin, n, azimuth if spin is None else spin)


class FilamentPart:
    """One filament of the system (module docstring), in core units.

    ``x0``, ``theta0``: its stress-free shape, already placed and with the joint's beads
    (``joint``, from :func:`flagwrap.joints.make_joint` on that shape). ``bond``: the
    nominal bond ``b`` [L]; ``twist``, ``stretch``: ``C/A`` and the stretching stiffness
    [A/L^2 per b^3]; ``radius``: the bead's hydrodynamic radius [L]; ``gravity_number``: ``G``
    or None (no buoyancy); ``spin_drag``: a bead's spin drag over viscosity [L^3] (default
    ``8 pi radius^3``, a sphere's; the tube model's ``4 pi a^2 b``).
    """

    def __init__(self, x0, theta0, joint, *, bond: float, twist: float, stretch: float,
                 radius: float, gravity_number=None, name: str = "flagellum",
                 spin_drag: float | None = None):
        self.name = str(name)
        self.x0 = np.asarray(x0, float)
        self.theta0 = np.asarray(theta0, float)
        N = len(self.x0)
        self.N = N
        self.frames0 = initial_frames(self.x0)
        self.joint = joint
        self.rest = joint.rest(rest_state(self.x0, self.frames0, self.theta0, bending=1.0,
                                          twist=twist, stretch=stretch))
        self.nc, self.ec = joint.n_beads, joint.n_edges
        self.nb = N - self.nc  # free beads
        self.ne = N - 1 - self.ec  # free bonds
        # each bead's rotational drag 8 pi eta a^3 is shared by its two bonds (docs/model.md)
        w = np.ones(N - 1)
        w[0] += 0.5
        w[-1] += 0.5
        spin = 8.0 * math.pi * radius**3 if spin_drag is None else float(spin_drag)
        self.rot_drag = spin * w  # geometric; times M gives core drag
        # gravity/buoyancy: force per bead (core units) along +z, G l / L for a bead carrying
        # contour l (half a bond at the ends): units.gravity_number
        self.gravity = np.zeros((N, 3))
        if gravity_number is not None:
            # half of each adjacent bond's nominal length (b, or a hook's short bonds)
            lb = np.where(np.abs(self.rest.l0 - bond) < 1e-9 * bond, bond, self.rest.l0)
            per_bead = np.empty(N)
            per_bead[0], per_bead[-1] = 0.5 * lb[0], 0.5 * lb[-1]
            per_bead[1:-1] = 0.5 * (lb[:-1] + lb[1:])
            self.gravity[:, 2] = gravity_number * per_bead
        # set by the system when it assembles its parts (assign_offsets)
        self.bead0 = self.bond0 = 0
        self.ymap = None
        self.colors = None

    @property
    def beads(self) -> slice:
        """This filament's beads in the system's bead arrays."""
        return slice(self.bead0, self.bead0 + self.N)

    @property
    def bonds(self) -> slice:
        """This filament's bonds in the system's bond arrays."""
        return slice(self.bond0, self.bond0 + self.N - 1)

    @property
    def ny(self) -> int:
        """Its own unknowns ``[x_free, theta_free, phi]``."""
        return 3 * self.nb + self.ne + 1

    def assign_offsets(self, bead0: int, bond0: int, free_bead0: int, free_bond0: int,
                       theta_start: int, phi_index: int, single: bool) -> None:
        """Where its beads, bonds and unknowns sit in the system (module docstring);
        ``single``: the only part, whose unknowns are the system's in the same order."""
        self.bead0, self.bond0 = int(bead0), int(bond0)
        self.ymap = None if single else np.concatenate([
            np.arange(3 * free_bead0, 3 * (free_bead0 + self.nb)),
            np.arange(theta_start + free_bond0, theta_start + free_bond0 + self.ne),
            [phi_index]]).astype(np.int64)

    def kernel_args(self, base, body, has_body: bool):
        """The fused kernel's arguments after ``y`` (:mod:`flagwrap.system.kernels`), the
        reference frames ``base`` being the system's (this part's rows are taken)."""
        r, c, b = self.rest, self.joint, body
        e, v = self.bonds, self.beads
        return (self.nc, self.ec, c.x_ref, c.axis, c.origin, c.theta_ref, c.twist_rate,
                base.t[e], base.d1[e], base.rt[v], r.l0, r.cbend, r.ctwist, r.angle_law,
                r.kbar, r.mbar, r.stretch, has_body, b.radius if has_body else 0.0,
                b.length if has_body else 0.0, b.sigma if has_body else 0.0,
                b.strength if has_body else 0.0, b.c2 if has_body else 0.0, self.gravity)

    def build_colors(self):
        """Groups of its own unknowns whose force stencils are disjoint (5 apart along the
        chain), flattened for :func:`flagwrap.system.kernels.fd_jacobian_coo`."""
        nb, nc, ec, N = self.nb, self.nc, self.ec, self.N
        groups = []

        def stencil_rows(beads, bonds):  # the free unknowns among these beads and bonds
            rows = []
            for m in beads:
                if nc <= m < N:
                    rows += [3 * (m - nc) + c for c in range(3)]
            for j in bonds:
                if ec <= j < N - 1:
                    rows.append(3 * nb + (j - ec))
            return rows

        def bead_rows(k):  # k: bead index; rows affected: beads k-2..k+2, bonds k-2..k+1
            return stencil_rows(range(k - 2, k + 3), range(k - 2, k + 2))

        def edge_rows(j):  # bond j: beads j-1..j+2, bonds j-1..j+1
            return stencil_rows(range(j - 1, j + 3), range(j - 1, j + 2))

        def group(members, column, rows_of):  # one colour: columns and their (row, col) pairs
            cols, rows_l, cols_l = [], [], []
            for k in members:
                col = column(k)
                cols.append(col)
                rr = rows_of(k)
                rows_l += rr
                cols_l += [col] * len(rr)
            if cols:
                groups.append((np.array(cols), np.array(rows_l), np.array(cols_l)))

        for start in range(5):
            for c in range(3):
                group(range(nc + start, N, 5), lambda k, c=c: 3 * (k - nc) + c, bead_rows)
        for start in range(5):
            group(range(ec + start, N - 1, 5), lambda j: 3 * nb + (j - ec), edge_rows)
        g_ptr = np.cumsum([0] + [len(g[0]) for g in groups]).astype(np.int64)
        e_ptr = np.cumsum([0] + [len(g[1]) for g in groups]).astype(np.int64)
        self.colors = (
            g_ptr, np.concatenate([g[0] for g in groups]).astype(np.int64),
            e_ptr, np.concatenate([g[1] for g in groups]).astype(np.int64),
            np.concatenate([g[2] for g in groups]).astype(np.int64),
        )
        return self.colors


def build_parts(config, placements=None, x0=None, theta0=None, joint=None) -> list:
    """The config's filaments as :class:`FilamentPart` s (core units), nothing else built
    (no mobility, no body): one per ``placements`` entry (default: the ``[[flagellum]]``
    tables, or one at the pole). ``x0``, ``theta0``, ``joint``: one filament's own shape and
    joint instead of the config's (:class:`~flagwrap.system.rod_system.RodSystem`'s
    arguments)."""
    from flagwrap.geometry.helix import filament_positions
    from flagwrap.joints import make_joint

    fil = config.filament
    L = fil.length
    if placements is None:  # the config's [[flagellum]] tables, or one at the pole
        placements = placements_from_config(config) or [Placement()]
    placements = list(placements)
    if not placements:
        raise ValueError("build_parts: placements must hold at least one filament")
    if len(placements) > 1 and (x0 is not None or joint is not None):
        raise ValueError("build_parts: a given x0 or joint is for one filament, not several")
    b = fil.bond_length / L
    parts = []
    for k, place in enumerate(placements):
        xk = filament_positions(fil, config.clamp) / L if x0 is None else np.asarray(x0, float)
        thk = np.zeros(len(xk) - 1) if theta0 is None else np.asarray(theta0, float)
        xk = place.apply(xk)
        jk = joint
        if jk is None:  # the joint may add beads (a resolved hook): it returns the shape
            jk, xk, thk = make_joint(config, xk, thk, axis=tuple(place.axis), origin=place.origin)
        parts.append(FilamentPart(
            xk, thk, jk, bond=b, twist=fil.twist_modulus / fil.bending_modulus,
            stretch=fil.stretch_stiffness / b**3, radius=fil.bead_radius / L,
            spin_drag=(fil.bead_spin_drag / L**3 if fil.hydrodynamic_model == "tube" else None),
            gravity_number=config.gravity_number if fil.density is not None else None,
            name=f"flagellum{k}"))
    return parts


def placements_from_config(config) -> list | None:
    """One :class:`Placement` per ``[[flagellum]]`` table (core units), or None (no table:
    one flagellum at the pole, the identity)."""
    if not config.flagella:
        return None
    L = config.filament.length
    out = []
    for f in config.flagella:
        spin = None if f.spin_deg is None else math.radians(f.spin_deg)
        if f.anchor is None:  # on the shape's pole cap
            from flagwrap.body.shapes import config_shape

            az = math.radians(f.azimuth_deg or 0.0)
            origin, n = config_shape(config).pole_cap(math.radians(f.polar_deg or 0.0), az)
            out.append(Placement.from_axis(origin, n, az if spin is None else spin))
        else:
            out.append(Placement.from_axis(np.asarray(f.anchor, float) / L, f.axis, spin or 0.0))
    return out


def check_flagella(config) -> None:
    """Refuse ``[[flagellum]]`` tables that cannot be built (one line naming the table and
    key, before any work): a cap anchor without a spherical pole cap, an anchor off the body
    surface or an axis into the body, anchors closer than a filament's diameter, filaments
    whose stress-free shapes cross, a turning frame with several flagella or one off the
    body axis."""
    from flagwrap.errors import UserInputError
    from flagwrap.geometry.helix import filament_positions
    from flagwrap.observables.contact import body_distance

    from flagwrap.body.shapes import config_shape

    fil, body = config.filament, config.body
    L, a = fil.length, fil.cross_section_radius
    shape = config_shape(config, unit=1.0) if body.enabled else None  # metres
    for k, f in enumerate(config.flagella):
        where = f"flagellum[{k}]"
        if f.anchor is None:
            if shape is None:
                raise UserInputError(
                    f"{where}.polar_deg places the flagellum on the body's pole cap: it needs "
                    f"body.enabled = true; give {where}.anchor and axis instead")
            try:
                shape.pole_cap(0.0, 0.0)
            except UserInputError:
                raise UserInputError(
                    f"{where}.polar_deg places the flagellum on a spherical pole cap, which "
                    f"body.shape = {body.shape!r} does not have; give {where}.anchor and axis "
                    "instead") from None
        if f.anchor is not None and shape is not None:
            p = np.asarray(f.anchor, float)
            d = float(shape.distance(p))
            if abs(d) > 0.1 * a:
                raise UserInputError(
                    f"{where}.anchor = {list(f.anchor)} m is {d:.3g} m from the body surface; it "
                    f"must lie on it (within 0.1 a = {0.1 * a:.3g} m)")
            if not float(shape.normal(p) @ np.asarray(f.axis, float)) > 0.0:
                raise UserInputError(f"{where}.axis = {list(f.axis)} points into the body; the "
                                     "motor axis must point out of it")
    from flagwrap.motor.protocol import Schedule

    t_ref = Schedule(config.motor.protocol).t_end
    for k, f in enumerate(config.flagella):
        try:
            law = f.motor(config.motor)
        except UserInputError as exc:
            raise UserInputError(str(exc).replace("flagellum", f"flagellum[{k}]", 1)) from None
        if law.kind != "speed" and config.numerics.frame != "lab":
            raise UserInputError(f"flagellum[{k}].kind = {law.kind!r}: numerics.frame = "
                                 f"{config.numerics.frame!r} needs speed motors")
        if f.protocol is None:
            continue
        t_k = Schedule(f.protocol).t_end
        if abs(t_k - t_ref) > 1e-9 * t_ref:
            raise UserInputError(
                f"flagellum[{k}].protocol lasts {t_k / (2 * math.pi):.6g} reference turns, "
                f"motor.protocol {t_ref / (2 * math.pi):.6g}: a flagellum's protocol must "
                "last as long as the run's (sum of turns / speed)")
        if law.kind != "speed":
            for p in f.protocol:
                if p.direction != "stop" and p.speed != 1.0:
                    raise UserInputError(
                        f"flagellum[{k}].protocol speed = {p.speed:g}: a {law.kind} "
                        "motor sets its own speed; leave the phases' speed at 1")
    if len(config.flagella) > 1 and config.numerics.frame != "lab":
        raise UserInputError(f"numerics.frame = {config.numerics.frame!r} needs one flagellum on "
                             f"the motor axis; this config has {len(config.flagella)} "
                             "[[flagellum]] tables: use numerics.frame = 'lab'")
    places = placements_from_config(config)
    if config.numerics.frame != "lab":  # one flagellum: its motor must turn about the body axis
        o, ax = np.asarray(places[0].origin, float), places[0].axis
        if math.hypot(o[0], o[1]) > 1e-12 or math.hypot(ax[0], ax[1]) > 1e-12:
            raise UserInputError(
                f"numerics.frame = {config.numerics.frame!r} needs the motor on the body axis; "
                f"flagellum[0] sits {math.hypot(o[0], o[1]) * L:.3g} m off it with its axis "
                f"{math.degrees(math.acos(min(1.0, abs(ax[2])))):.3g} deg from it: use "
                "numerics.frame = 'lab'")
    shape = filament_positions(fil, config.clamp) / L
    shapes = [pl.apply(shape) for pl in places]
    for k in range(len(shapes)):
        for m in range(k):
            gap = np.linalg.norm(shapes[k][0] - shapes[m][0]) * L
            if gap < 2 * a:
                raise UserInputError(
                    f"flagellum[{k}] and flagellum[{m}] are anchored {gap:.3g} m apart, less "
                    f"than the filament's diameter 2 a = {2 * a:.3g} m: move one")
            d = _min_segment_distance(shapes[k], shapes[m]) * L
            if d < 2 * a:
                raise UserInputError(
                    f"flagellum[{k}] and flagellum[{m}] cross at the start: their stress-free "
                    f"shapes come {d:.3g} m close, less than 2 a = {2 * a:.3g} m (spread the "
                    "anchors: polar_deg, azimuth_deg, or turn one: spin_deg)")


def check_connector(config) -> None:
    """Refuse ``clamp.lead = "connector"`` where it cannot be built (one line naming the key):
    a straight filament (no helix to centre), or an arm that enters the body (a motor axis
    tilted from the surface normal puts the arm's plane through it)."""
    from flagwrap.body.shapes import config_shape
    from flagwrap.errors import UserInputError
    from flagwrap.geometry.helix import filament_positions, held_beads

    fil = config.filament
    if fil.shape == "straight":
        raise UserInputError("clamp.lead = 'connector' centres a helix on the motor axis; "
                             "filament.shape = 'straight' has none (use lead = 'kink')")
    if not config.body.enabled:
        return
    L, a = fil.length, fil.cross_section_radius
    shape = config_shape(config, unit=1.0)  # metres
    held = filament_positions(fil, config.clamp)[:held_beads(fil, config.clamp)] / L
    for k, pl in enumerate(placements_from_config(config) or [Placement()]):
        d = float(np.min(shape.distance(pl.apply(held) * L)))
        if d < -0.1 * a:
            where = f"flagellum[{k}]" if config.flagella else "the motor"
            raise UserInputError(
                f"clamp.lead = 'connector': the arm of {where} (length R = "
                f"{fil.helix_radius:.3g} m, square to the motor axis) enters the body by "
                f"{-d:.3g} m; turn the motor axis along the surface normal or use lead = 'kink'")


def _start_distances(config, distance):
    """``(name, d)`` for each flagellum: its name in messages and the smallest ``distance``
    (a function of core-unit positions, in ``L``) of its starting beads, in metres."""
    from flagwrap.geometry.helix import filament_positions

    fil = config.filament
    shape = filament_positions(fil, config.clamp) / fil.length
    for k, pl in enumerate(placements_from_config(config) or [Placement()]):
        where = f"flagellum[{k}]" if config.flagella else "the filament"
        yield where, float(np.min(distance(pl.apply(shape)))) * fil.length


def check_walls(config) -> None:
    """Refuse ``[[wall]]`` tables that cannot be run (one line naming the key, before any
    work): more than one wall, a free-swimming body beside one with the Krylov blob solver,
    the turning frame of a held body or the rig beside a wall not square to the body axis
    (its symmetry is broken; a free cell's turning frame places the wall at every state), a
    filament that starts within its radius of the wall or behind it, a body across it."""
    from flagwrap.errors import UserInputError

    walls = config.walls
    if len(walls) > 1:
        raise UserInputError(f"{len(walls)} [[wall]] tables: one wall is supported (the "
                             "Rotne-Prager-Blake mobility is a single plane's)")
    w = walls[0]
    if config.body.free and config.body.solver == "krylov":  # refactorised per pose: direct
        raise UserInputError("[[wall]] beside a free body needs body.solver = 'direct' or "
                             "'auto' (the blob matrix is refactorised at every pose)")
    from flagwrap.hydrodynamics.wall import config_wall

    plane = config_wall(config)  # core units
    if config.numerics.frame != "lab" and not plane.square_to_z and not config.body.free:
        raise UserInputError(f"[[wall]] with numerics.frame = {config.numerics.frame!r}: a "
                             "wall tilted from the plane z = const breaks the turning frame's "
                             "symmetry; use numerics.frame = 'lab' (or wall.normal = [0, 0, +-1])")
    fil = config.filament
    L, a = fil.length, fil.cross_section_radius
    for where, h in _start_distances(config, plane.heights):
        if h < a:
            raise UserInputError(
                f"wall[0].point = {list(w.point)} m: {where} starts {h:.3g} m from the wall "
                f"(on the side its normal points to), less than its radius a = {a:.3g} m: move "
                "the wall or turn its normal")
    if config.body.enabled:
        from flagwrap.body.multiblob import cell_body_blobs

        blobs, _ = cell_body_blobs(config)
        h = float(np.min(plane.heights(blobs))) * L
        if h < 0.0:
            raise UserInputError(f"wall[0].point = {list(w.point)} m: the cell body crosses the "
                                 f"wall ({-h:.3g} m behind it): move the wall or turn its normal")


def check_start_state(config, system, y, info) -> None:
    """Refuse a run that starts from a given state (``Simulation.run(y0=...)``) with a bead's
    or a free body's blob's centre on or behind the config's wall or tube: one line naming
    ``y0``, before any step. The config's own checks (:func:`check_walls`,
    :func:`check_tubes`) place the boundary against the config's rest shape, which such a
    run does not start from. ``info``: the forces at ``y``."""
    from flagwrap.errors import UserInputError

    if config.walls:
        from flagwrap.hydrodynamics.wall import config_wall

        distance, what = config_wall(config).heights, "wall[0]"
    elif config.tubes:
        distance, what = config_tube(config).gap, "tube[0]"
    else:
        return
    L = config.filament.length
    d = distance(np.asarray(system.record_view(y, info).x))
    i = int(np.argmin(d))
    # the centre in front of the wall: a state the run reached may sit closer than ``a``
    # (a contact law whose sigma is below ``a``), but behind it the law pushes nothing
    if not d[i] > 0.0:
        raise UserInputError(f"y0: bead {i}'s centre starts {-d[i] * L:.3g} m behind "
                             f"{what}'s wall (or on it): start the run from a state clear of "
                             "the boundary")
    if getattr(system, "blobs", None) is not None and hasattr(system, "pose"):
        X, R = system.pose(y)
        db = distance(X + system.blobs @ R.T)  # the blobs' centres, as the config's checks
        if not db.min() > 0.0:
            raise UserInputError(f"y0: the cell body crosses {what}'s wall (a blob "
                                 f"{-db.min() * L:.3g} m behind it) at the state the run "
                                 "starts from: start the run from a state clear of the "
                                 "boundary")


def config_tube(config):
    """The config's ``[[tube]]`` (one; :func:`check_tubes`) as a
    :class:`flagwrap.confinement.tube.Tube` in core units (lengths in ``L``), or None."""
    if not config.tubes:
        return None
    return config.tubes[0].geometry(config.filament.length)


def tube_blobs(config) -> tuple[np.ndarray, np.ndarray]:
    """The blobs (n, 3) and radii (n,) of the config's tube in core units."""
    from flagwrap.confinement.tube import BLOB_RADIUS_RATIO

    L = config.filament.length
    h = config.tubes[0].resolved_blob_spacing / L
    blobs = config_tube(config).blob_shell(h, BLOB_RADIUS_RATIO * h)
    return blobs, np.full(len(blobs), BLOB_RADIUS_RATIO * h)


def check_tubes(config) -> None:
    """Refuse ``[[tube]]`` tables that cannot be run (one line naming the key, before any
    work): more than one tube, a tube with a wall, a free body in a tube with the Krylov blob
    solver (its blob matrix is refactorised at every pose), the turning frame of the rig or a
    held body (a blob tube is not symmetric about the motor axis; a free cell's turning frame
    places the tube at every state), blobs too sparse for the tube, a body as wide as the tube (a constriction
    narrower than the body is allowed: whether the cell passes is the question), a filament or
    body that starts across the tube's wall."""
    from flagwrap.errors import UserInputError

    if len(config.tubes) > 1:
        raise UserInputError(f"{len(config.tubes)} [[tube]] tables: one tube is supported")
    if config.walls:
        raise UserInputError("[[tube]] with [[wall]]: one boundary at a time is supported; "
                             "drop one")
    if config.body.free and config.body.solver == "krylov":
        raise UserInputError("[[tube]] around a free body needs body.solver = 'direct' or "
                             "'auto' (the body's blob matrix is refactorised at every pose)")
    if config.numerics.frame != "lab" and not config.body.free:
        raise UserInputError(f"[[tube]] with numerics.frame = {config.numerics.frame!r}: a "
                             "tube of blobs is not symmetric about the motor axis; use "
                             "numerics.frame = 'lab'")
    t, L = config.tubes[0], config.filament.length
    tube = config_tube(config)
    if t.resolved_blob_spacing >= tube.narrowest * L:
        raise UserInputError(f"tube[0].blob_spacing = {t.resolved_blob_spacing:g} m must be "
                             f"below the tube's narrowest radius {tube.narrowest * L:g} m")
    _check_tube_blob_count(config, tube)
    fil = config.filament
    a = fil.cross_section_radius
    for where, g in _start_distances(config, tube.gap):
        if not g > a:
            raise UserInputError(
                f"tube[0]: {where} starts {g:.3g} m from the tube's wall (inside), less than "
                f"its radius a = {a:.3g} m, or outside the tube: move the tube (tube.center) "
                "or widen it (tube.radius)")
    if config.body.enabled:
        from flagwrap.body.multiblob import cell_body_blobs

        rb = config.body.resolved_radius(fil.helix_radius)
        if rb >= tube.radius * L:  # a constriction narrower than the body is a question
            raise UserInputError(f"tube[0].radius = {tube.radius * L:g} m: the cell body "
                                 f"(radius {rb:g} m) is as wide or wider; widen the tube")
        blobs, _ = cell_body_blobs(config)
        if not np.min(tube.gap(blobs)) > 0.0:
            raise UserInputError("tube[0]: the cell body crosses the tube's wall or lies "
                                 "outside the tube: move the tube (tube.center) or widen it "
                                 "(tube.radius)")


def _check_tube_blob_count(config, tube) -> None:
    """Refuse a tube whose blobs, with the body's, are more than its blob solver takes
    (``MAX_BLOBS`` dense, ``MAX_BLOBS_KRYLOV`` by conjugate gradients), from the shell's
    estimated count, before any blob is placed."""
    from flagwrap.confinement.tube import BLOB_RADIUS_RATIO
    from flagwrap.errors import UserInputError
    from flagwrap.params import MAX_BLOBS, MAX_BLOBS_KRYLOV

    L = config.filament.length
    h = config.tubes[0].resolved_blob_spacing
    n = tube.estimated_blobs(h / L, BLOB_RADIUS_RATIO * h / L)
    # a free body's tube is factorised on its own (flagwrap.body.boundaries), a held body's
    # with the body's blobs
    joint = config.body.no_slip and not config.body.free
    if joint:
        from flagwrap.body.multiblob import cell_body_blobs

        n += len(cell_body_blobs(config)[0])
    direct = config.body.solver == "direct" or config.body.free
    most = MAX_BLOBS if direct else MAX_BLOBS_KRYLOV
    if n > most:
        raise UserInputError(
            f"tube[0].blob_spacing = {h:g} m puts ~{n} blobs on the tube"
            + (" and the body" if joint else "")
            + f", more than the {'direct' if direct else 'Krylov'} blob solve takes ({most}); "
            f"use a spacing >= {h * math.sqrt(n / most):.3g} m"
            + (" or body.solver = 'krylov'" if direct and not config.body.free else ""))


def _min_segment_distance(x, z) -> float:
    """The smallest distance between a segment of chain ``x`` and one of chain ``z``."""
    from flagwrap.interactions.self_contact import segment_closest

    best = np.inf
    # bounding-sphere prefilter, then the exact segment distance
    cx, hx = 0.5 * (x[1:] + x[:-1]), 0.5 * np.linalg.norm(np.diff(x, axis=0), axis=1)
    cz, hz = 0.5 * (z[1:] + z[:-1]), 0.5 * np.linalg.norm(np.diff(z, axis=0), axis=1)
    lower = np.linalg.norm(cx[:, None] - cz[None], axis=2) - hx[:, None] - hz[None]
    for i, j in np.argwhere(lower < max(np.min(lower), 0.0) + 4 * hx.max()):
        s, t, dx, dy, dz = segment_closest(x[i], x[i + 1], z[j], z[j + 1])
        best = min(best, float(np.sqrt(dx * dx + dy * dy + dz * dz)))
    return best
