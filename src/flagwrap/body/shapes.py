"""Body shapes: the geometry of a rigid cell body, one class per shape.

A shape owns everything about the body that depends on its form, so that the rest of the
code asks it instead of switching on a name:

* ``signed_distance(x) -> (d, n)``: each point's signed distance to the surface (negative
  inside) and its gradient (the outward unit normal on the surface). The body contact
  (:class:`flagwrap.body.cell_body.BodyContact`), the start check, the anchor check of
  ``[[flagellum]]`` tables and the analysis (:func:`flagwrap.observables.contact.
  body_distance`) read it.
* ``blob_shell(spacing, blob_radius) -> (n, 3)``: the blob centres of a no-slip surface
  (:mod:`flagwrap.body.multiblob`), about ``spacing`` apart on the shell
  :data:`~flagwrap.body.multiblob.BLOB_INSET` blob radii inside the surface (the blob body's
  hydrodynamic surface is then the shape's own).
* ``surface_mesh(n_around, n_profile) -> (vertices, triangles)``: a closed triangle mesh with
  outward normals for snapshots, movies and VTK.
* ``pole_cap(polar, azimuth) -> (anchor, normal)``: where ``[[flagellum]] polar_deg`` puts
  an anchor; only shapes with a spherical pole cap at the origin have one.
* ``axisymmetric``: the shape is a body of revolution about ``z`` (the turning frame needs it).
* ``kernel``: ``(code, radius, length)`` when the fused numba force kernel
  (:func:`flagwrap.body._kernels.body_distance`) knows the shape; ``None`` for any other,
  whose contact then runs through ``signed_distance`` (vectorised, one call per force
  evaluation: :class:`~flagwrap.body.cell_body.ShapeContact`).

Every shape is built from two lengths in one unit (core units in the simulator, metres in
the drawings): ``radius`` (``R_cell``) and ``length`` (``body.cylinder_length``, or what the
shape makes of it), its lowest point (where a single flagellum sits) at the origin and its
axis along ``+z``. ``body.shape = "name"`` in a config picks a class from the registry;
:func:`register_shape` adds one from outside the package (tests/unit/test_body_shapes.py
defines a shape in the test file and swims a cell of it).
"""

from __future__ import annotations

import math

import numpy as np

from flagwrap.errors import UserInputError


class BodyShape:
    """The interface (module docstring); subclasses implement ``signed_distance`` and, for a
    no-slip surface or a drawing, ``blob_shell`` and ``surface_mesh``."""

    name = "shape"
    axisymmetric = False
    kernel = None

    def __init__(self, radius: float, length: float):
        self.radius = float(radius)
        self.length = float(length)

    def signed_distance(self, x):  # pragma: no cover - the interface
        raise NotImplementedError

    def blob_shell(self, spacing: float, blob_radius: float) -> np.ndarray:
        raise UserInputError(f"body.shape = {self.name!r} has no blob surface: it cannot be "
                             "body.surface = 'no-slip'")

    def surface_mesh(self, n_around: int = 48, n_profile: int = 18):
        """``None``: the drawings leave the body out."""
        return None

    def pole_cap(self, polar: float, azimuth: float):
        raise UserInputError(
            f"[[flagellum]] polar_deg places a flagellum on a spherical pole cap, which "
            f"body.shape = {self.name!r} does not have: give the table's anchor and axis")

    def distance(self, x) -> np.ndarray:
        """Signed distances only, any leading shape ``(..., 3) -> (...)``."""
        x = np.asarray(x, float)
        flat = np.ascontiguousarray(x.reshape(-1, 3))
        return self.signed_distance(flat)[0].reshape(x.shape[:-1])

    def normal(self, p) -> np.ndarray:
        """The outward unit normal at the surface point ``p`` (3,)."""
        n = self.signed_distance(np.asarray(p, float).reshape(1, 3))[1][0]
        return n / np.linalg.norm(n)

    def __repr__(self) -> str:
        return f"{type(self).__name__}(radius={self.radius:g}, length={self.length:g})"


def _kernel_distance(x, code: int, radius: float, length: float):
    from flagwrap.body import _kernels as K

    x = np.ascontiguousarray(x, dtype=np.float64)
    d = np.empty(len(x))
    n = np.empty((len(x), 3))
    K.distances(x, radius, length, code, d, n)
    return d, n


def _revolution_mesh(prof_r, prof_z, n_around: int):
    """Closed triangle mesh of the surface of revolution of the profile ``(r, z)`` (from the
    bottom pole, ``r = 0``, to the top, ``r = 0``), counter-clockwise seen from outside."""
    phi = 2 * np.pi * np.arange(n_around) / n_around
    verts = [np.array([[0.0, 0.0, prof_z[0]]])]
    index = [np.zeros(n_around, dtype=int)]
    nxt = 1
    for r, z in zip(prof_r[1:-1], prof_z[1:-1]):
        verts.append(np.column_stack([r * np.cos(phi), r * np.sin(phi), np.full(n_around, z)]))
        index.append(nxt + np.arange(n_around))
        nxt += n_around
    verts.append(np.array([[0.0, 0.0, prof_z[-1]]]))
    index.append(np.full(n_around, nxt))
    k = np.arange(n_around)
    k1 = (k + 1) % n_around
    tris = []
    for j in range(len(index) - 1):
        lo, hi = index[j], index[j + 1]
        # going up the profile the outward normal points out and down, then out, then up:
        # (lo_k, lo_k1, hi_k1) and (lo_k, hi_k1, hi_k) are counter-clockwise seen from outside
        if j > 0:
            tris.append(np.column_stack([lo[k], lo[k1], hi[k1]]))
        if j < len(index) - 2:
            tris.append(np.column_stack([lo[k], hi[k1], hi[k]]))
    return np.concatenate(verts), np.concatenate(tris)


class CappedCylinderShape(BodyShape):
    """The paper's cell body: a cylinder of radius ``radius`` and length ``length`` closed
    below by a hemisphere (centre ``(0, 0, radius)``) and above by a flat disc."""

    name = "capped-cylinder"
    axisymmetric = True

    @property
    def kernel(self):
        return (0, self.radius, self.length)

    def signed_distance(self, x):
        return _kernel_distance(x, 0, self.radius, self.length)

    def blob_shell(self, spacing, blob_radius):
        from flagwrap.body.multiblob import inset_capped_cylinder_blobs

        return inset_capped_cylinder_blobs(self.radius, self.length, spacing, blob_radius)

    def surface_mesh(self, n_around=48, n_profile=18):
        n_cap = max(2, (2 * n_profile) // 3)
        n_cyl = max(1, n_profile - n_cap)
        R, H = self.radius, self.length
        a = np.linspace(0.0, np.pi / 2, n_cap + 1)  # polar angle from the bottom pole
        zc = np.linspace(R, R + H, n_cyl + 1)[1:]
        prof_r = np.concatenate([R * np.sin(a), np.full(len(zc), R), [0.0]])
        prof_z = np.concatenate([R - R * np.cos(a), zc, [R + H]])
        return _revolution_mesh(prof_r, prof_z, n_around)

    def pole_cap(self, polar, azimuth):
        n = np.array([math.sin(polar) * math.cos(azimuth), math.sin(polar) * math.sin(azimuth),
                      -math.cos(polar)])
        return np.array([0.0, 0.0, self.radius]) + self.radius * n, n


class SpheroidShape(BodyShape):
    """The spheroid of equatorial radius ``radius`` and total length ``radius + length``
    along ``z``, lowest point at the origin (its distance to first order:
    :func:`flagwrap.body._kernels.spheroid_distance`); blobs on rings of equal arc length."""

    name = "spheroid"
    axisymmetric = True

    @property
    def kernel(self):
        return (1, self.radius, self.length)

    @property
    def semi_axes(self) -> tuple[float, float]:
        return self.radius, 0.5 * (self.radius + self.length)

    def signed_distance(self, x):
        return _kernel_distance(x, 1, self.radius, self.length)

    def blob_shell(self, spacing, blob_radius):
        from flagwrap.body.multiblob import BLOB_INSET, spheroid_ring_blobs

        a, c = self.semi_axes
        d = BLOB_INSET * blob_radius  # the inset shell keeps the centre
        return spheroid_ring_blobs(a - d, c - d, spacing) + np.array([0.0, 0.0, d])

    def surface_mesh(self, n_around=48, n_profile=18):
        a, c = self.semi_axes
        t = np.linspace(0.0, np.pi, 2 * n_profile + 1)
        prof_r, prof_z = a * np.sin(t), c * (1.0 - np.cos(t))
        prof_r[-1] = 0.0
        return _revolution_mesh(prof_r, prof_z, n_around)


class SphereShape(SpheroidShape):
    """The sphere of radius ``radius`` (``length`` is its radius again), lowest point at the
    origin; its whole surface is a pole cap."""

    name = "sphere"

    def __init__(self, radius, length=None):
        super().__init__(radius, radius)

    pole_cap = CappedCylinderShape.pole_cap


_REGISTRY: dict[str, type] = {}


def register_shape(name: str, cls) -> None:
    """Make ``body.shape = name`` build ``cls(radius, length)`` (module docstring). A name
    already taken by another class is refused."""
    name = str(name)
    if not name or _REGISTRY.get(name, cls) is not cls:
        raise ValueError(f"body shape {name!r} is already registered as {_REGISTRY[name]!r}")
    if not callable(getattr(cls, "signed_distance", None)):
        raise TypeError(f"body shape {name!r}: {cls!r} has no signed_distance")
    _REGISTRY[name] = cls


def shape_names() -> tuple[str, ...]:
    return tuple(_REGISTRY)


def make_shape(name: str, radius: float, length: float) -> BodyShape:
    """The shape ``name`` of ``radius`` and ``length`` (any one length unit)."""
    try:
        cls = _REGISTRY[name]
    except KeyError:
        raise UserInputError(f"body.shape must be one of {', '.join(_REGISTRY)}, got {name!r} "
                             "(a shape of your own: flagwrap.body.shapes.register_shape)") from None
    return cls(radius, length)


def config_shape(config, unit: float | None = None) -> BodyShape:
    """``config``'s body shape with lengths in ``unit`` [m] (default: the filament's length,
    the core unit)."""
    b, fil = config.body, config.filament
    unit = fil.length if unit is None else float(unit)
    R = fil.helix_radius
    return make_shape(b.shape, b.resolved_radius(R) / unit, b.resolved_length(R) / unit)


for _cls in (CappedCylinderShape, SpheroidShape, SphereShape):
    register_shape(_cls.name, _cls)
