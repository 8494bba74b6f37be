"""Headless 3D rendering of the filament (a shaded tube) beside the cell body, two cameras.

The experiment films the helix with two cameras at right angles whose optical axes are
horizontal (paper, SI "Tracking"): camera C1 on the +x axis looking toward -x, camera C2 on the
+y axis looking toward -y. :data:`CAMERAS` reproduces them as orthographic views (the cameras
stand far from the tank, ``D_i >> a``): for C1 the image's horizontal axis is +y, for C2 it is
-x, and +z is up in both.

How the picture is made (and why not ``mplot3d``)
------------------------------------------------
matplotlib's 3D axes sort whole collections, not polygons, so a tube that wraps *around* the
cell body cannot be drawn in front of the body on one side and behind it on the other. Here
the scene is rendered by hand into an ordinary 2D axes:

1. the filament becomes a tube of its real cross-section radius ``a``: the centreline is
   resampled by a cubic spline in arclength (``subdivide`` points per bond) and swept with a
   ring of ``sides`` vertices carried by parallel transport (no twist of the mesh), plus two
   end discs;
2. the cell body (hemispherical cap of radius ``R_cell`` centred at ``(0, 0, R_cell)``,
   cylinder up to ``z = R_cell + H``, top disc) is a triangle mesh of revolution
   (:func:`body_surface`, shared with the ParaView export);
3. faces turned away from the camera are culled; the others get Lambert shading
   ``I = k_a + k_d max(0, n.l)`` with a light from the camera side, up and to the left;
4. all faces of the tube and of the (semi-transparent) body are sorted back to front by the
   depth of their centroids (painter's algorithm) and drawn as one ``PolyCollection``, so the
   alpha blending of the body is composited in the right order.

Centroid sorting is exact for the tube against itself at these resolutions and, against the
body, errs only where a body triangle and a tube segment overlap in depth by less than the
body's chord error ``R_cell (1 - cos(pi/n_around))`` (about 0.1 mm for the defaults): there
the tube may show a faint tint of the body colour. Everything uses the Agg backend: no display
is needed.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Camera:
    """An orthographic camera with a horizontal optical axis.

    Attributes
    ----------
    name : str
        Label shown on the panels ("C1", "C2").
    toward : (3,) array
        Unit vector from the scene toward the camera [1].
    right : (3,) array
        Unit vector of the image's horizontal axis [1] (``up`` is +z).
    """

    name: str
    toward: tuple
    right: tuple

    def project(self, p: np.ndarray):
        """Image coordinates ``(u, v)`` [m] and depth toward the camera [m] of points ``p`` (..., 3)."""
        p = np.asarray(p, float)
        return p @ np.asarray(self.right), p[..., 2], p @ np.asarray(self.toward)


#: The two cameras of the experiment: C1 at (D1, 0, 0), C2 at (0, D2, 0) (paper, SI Eq. S1).
CAMERAS = (
    Camera("C1 (along -x)", (1.0, 0.0, 0.0), (0.0, 1.0, 0.0)),
    Camera("C2 (along -y)", (0.0, 1.0, 0.0), (-1.0, 0.0, 0.0)),
)


@dataclass(frozen=True)
class Scene:
    """Static geometry of one run: what the renderer needs besides the bead positions.

    Attributes
    ----------
    tube_radius : float
        Filament cross-section radius ``a`` [m].
    body_radius, body_length : float
        ``R_cell`` and the cylinder length ``H`` [m]; ``body_radius = 0`` means no body.
    length : float
        Filament contour length ``L`` [m] (sets the default framing).
    filaments : tuple of (start, stop)
        Each flagellum's beads in ``x`` (empty: one filament, all the beads); every one is
        drawn as its own tube.
    """

    tube_radius: float
    body_radius: float
    body_length: float
    length: float
    body_shape: str = "capped-cylinder"
    filaments: tuple = ()

    def chains(self, n_beads: int) -> list:
        """The bead slices of the tubes to draw for ``n_beads`` beads."""
        return [slice(a, b) for a, b in self.filaments] or [slice(0, n_beads)]

    @property
    def has_body(self) -> bool:
        return self.body_radius > 0


def scene_of(ds) -> Scene:
    """The :class:`Scene` of a run dataset (from its stored config)."""
    from flagwrap.io.runfile import config_of

    cfg = config_of(ds)
    R = cfg.filament.helix_radius
    if cfg.body.enabled:
        Rc, H = cfg.body.resolved_radius(R), cfg.body.resolved_length(R)
    else:
        Rc, H = 0.0, 0.0
    from flagwrap.io.runfile import filament_slices

    sl = filament_slices(ds)
    return Scene(float(cfg.filament.cross_section_radius), float(Rc), float(H),
                 float(ds.attrs["length"]), cfg.body.shape,
                 tuple((s.start, s.stop) for s in sl) if len(sl) > 1 else ())


def boundary_lines(config, camera: Camera, n: int = 200) -> list:
    """The config's wall or tube as the camera sees it, polylines ``(u, v)`` [m] to draw
    behind the filament: a tube's two silhouette lines, ``R(s)`` either side of its axis
    along ``toward x axis`` (exact for a straight tube, the profile's radius for a
    constriction), or the circle of its radius seen end-on; a wall's edge when the camera
    looks along its plane (a wall seen face-on has no edge in the view: nothing). Empty
    without a boundary."""
    right, toward = np.asarray(camera.right, float), np.asarray(camera.toward, float)

    def image(p):
        return np.stack([p @ right, p[..., 2]])

    if config.tubes:
        t = config.tubes[0].geometry(1.0)
        a, c = np.asarray(t.axis), np.asarray(t.center)
        q = np.cross(toward, a)
        if np.linalg.norm(q) < 1e-9:  # seen end-on: its wall is a circle
            e1, e2 = right, np.array([0.0, 0.0, 1.0])
            ang = np.linspace(0.0, 2 * np.pi, n)
            return [image(c + t.radius * (np.cos(ang)[:, None] * e1 + np.sin(ang)[:, None] * e2))]
        q /= np.linalg.norm(q)
        ss = np.linspace(-0.5 * t.length, 0.5 * t.length, n)
        R, _, _ = t.profile(ss)
        mid = c + ss[:, None] * a
        return [image(mid + sign * R[:, None] * q) for sign in (1.0, -1.0)]
    if config.walls:
        w = config.walls[0]
        nrm, p = w.unit_normal, np.asarray(w.point, float)
        d = np.cross(nrm, toward)
        if abs(nrm @ toward) > 1e-9 or np.linalg.norm(d) < 1e-12:
            return []
        d /= np.linalg.norm(d)
        span = 100.0 * config.filament.length
        return [image(p + np.outer([-span, span], d))]
    return []


def draw_boundary(ax, config, camera: Camera) -> None:
    """:func:`boundary_lines` into ``ax``, grey and behind the filament."""
    for u, v in boundary_lines(config, camera):
        ax.plot(u, v, color="0.55", lw=0.8, zorder=0)


def body_poses(ds):
    """A free swimmer's body poses per saved frame, ``(X (F, 3) [m], R (F, 3, 3))`` (body to
    lab), or ``None`` for a fixed body (at the origin, axis +z)."""
    if "body_position" not in ds.variables:
        return None
    from flagwrap.observables.swimming import quaternion_matrices

    return ds["body_position"].values, quaternion_matrices(ds["body_orientation"].values)


def body_outline(scene, poses) -> np.ndarray:
    """Points (F * 10, 3) [m] that bound the moving body in every frame (for the view
    limits): its pole and top on the axis, and the rim at the cap's equator and at the top,
    a radius out along both cross directions."""
    X, R = poses
    Rc, top = scene.body_radius, scene.body_radius + scene.body_length
    rim = [[sx * Rc, sy * Rc, z] for z in (Rc, top) for sx, sy in ((1, 0), (-1, 0), (0, 1), (0, -1))]
    local = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, top]] + rim)
    return (np.einsum("fij,kj->fki", R, local) + X[:, None, :]).reshape(-1, 3)


# --------------------------------------------------------------------------------------------
# meshes (pure functions of arrays)


def resample_centerline(x: np.ndarray, subdivide: int = 3) -> np.ndarray:
    """Centreline through the beads ``x`` (N, 3) [m], resampled ``subdivide`` times per bond.

    A cubic spline in cumulative chord length (not-a-knot ends) passes through every bead, so
    the tube is smooth between beads; ``subdivide = 1`` returns the beads themselves.
    Returns ((N-1) * subdivide + 1, 3) [m].
    """
    x = np.asarray(x, float)
    if subdivide <= 1 or len(x) < 4:
        return x.copy()
    from scipy.interpolate import CubicSpline

    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(x, axis=0), axis=1))])
    keep = np.concatenate([[True], np.diff(s) > 0])  # guard against coincident beads
    s, x = s[keep], x[keep]
    fine = np.concatenate([np.linspace(s[i], s[i + 1], subdivide, endpoint=False)
                           for i in range(len(s) - 1)] + [s[-1:]])
    return CubicSpline(s, x, axis=0)(fine)


def tube_rings(c: np.ndarray, radius: float, sides: int = 12):
    """Rings of a tube of radius ``radius`` [m] swept along the polyline ``c`` (M, 3) [m].

    The ring frame is carried along by parallel transport (projection of the previous normal
    onto the plane normal to the vertex tangent), so the mesh itself does not twist.

    Returns
    -------
    rings : (M, sides, 3) vertex positions [m]
    normals : (M, sides, 3) outward unit normals
    tangents : (M, 3) unit vertex tangents
    """
    c = np.asarray(c, float)
    e = np.diff(c, axis=0)
    e /= np.linalg.norm(e, axis=1)[:, None]
    t = np.empty_like(c)
    t[0], t[-1] = e[0], e[-1]
    t[1:-1] = e[:-1] + e[1:]
    nrm = np.linalg.norm(t[1:-1], axis=1)
    t[1:-1] = np.where(nrm[:, None] > 1e-12, t[1:-1] / np.maximum(nrm, 1e-12)[:, None], e[1:])
    u = np.empty_like(c)
    a = np.array([1.0, 0.0, 0.0]) if abs(t[0, 0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    prev = a - (a @ t[0]) * t[0]
    for i in range(len(c)):
        w = prev - (prev @ t[i]) * t[i]
        n = np.linalg.norm(w)
        if n < 1e-9:  # tangent flipped onto the old normal: pick any perpendicular
            w = np.cross(t[i], [0.0, 0.0, 1.0] if abs(t[i, 2]) < 0.9 else [1.0, 0.0, 0.0])
            n = np.linalg.norm(w)
        u[i] = prev = w / n
    v = np.cross(t, u)
    phi = 2 * np.pi * np.arange(sides) / sides
    normals = (np.cos(phi)[None, :, None] * u[:, None, :]
               + np.sin(phi)[None, :, None] * v[:, None, :])
    return c[:, None, :] + radius * normals, normals, t


def tube_faces(x: np.ndarray, radius: float, sides: int = 12, subdivide: int = 3):
    """Quads and end discs of the filament tube.

    Parameters
    ----------
    x : (N, 3) bead positions [m]
    radius : tube radius [m] (the filament's cross-section radius)

    Returns
    -------
    quads : (Q, 4, 3) vertices [m], counter-clockwise seen from outside
    quad_normals : (Q, 3) outward unit normals
    caps : (2, sides, 3) end-disc polygons [m]; cap_normals : (2, 3)
    """
    c = resample_centerline(x, subdivide)
    rings, normals, t = tube_rings(c, radius, sides)
    k = np.arange(sides)
    k1 = (k + 1) % sides
    quads = np.stack([rings[:-1, k], rings[:-1, k1], rings[1:, k1], rings[1:, k]], axis=2)
    qn = normals[:-1, k] + normals[:-1, k1] + normals[1:, k1] + normals[1:, k]
    qn /= np.linalg.norm(qn, axis=-1, keepdims=True)
    caps = np.stack([rings[0][::-1], rings[-1]])
    cap_normals = np.stack([-t[0], t[-1]])
    return quads.reshape(-1, 4, 3), qn.reshape(-1, 3), caps, cap_normals


def body_surface(radius: float, length: float, n_around: int = 48, n_cap: int = 12,
                 n_cyl: int = 6, shape="capped-cylinder"):
    """Closed triangle mesh of the cell body (:meth:`flagwrap.body.shapes.BodyShape.
    surface_mesh`; ``n_cap + n_cyl`` divisions along its profile).

    Parameters
    ----------
    radius, length : ``R_cell`` and cylinder length ``H`` [m]
    n_around, n_cap, n_cyl : divisions in azimuth, in the cap's polar angle, along the cylinder
    shape : a ``body.shape`` name, or a shape object in metres

    Returns
    -------
    vertices : (V, 3) [m]
    triangles : (F, 3) int, counter-clockwise seen from outside (outward normals); ``None``
        for a shape without a mesh
    """
    from flagwrap.body.shapes import make_shape

    if isinstance(shape, str):
        shape = make_shape(shape, radius, length)
    mesh = shape.surface_mesh(n_around, n_cap + n_cyl)
    return (None, None) if mesh is None else mesh


def _face_normals(poly: np.ndarray) -> np.ndarray:
    n = np.cross(poly[:, 1] - poly[:, 0], poly[:, 2] - poly[:, 0])
    return n / np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-300)


# --------------------------------------------------------------------------------------------
# drawing

TUBE_RGB = np.array([0.20, 0.40, 0.75])
#: the tubes of several flagella (the first is the single filament's colour)
TUBE_PALETTE = (TUBE_RGB, np.array([0.80, 0.35, 0.15]), np.array([0.20, 0.60, 0.30]),
                np.array([0.55, 0.30, 0.65]), np.array([0.75, 0.60, 0.10]))
#: a polymorphic filament (``polymorph_order``): polymorph A (phi = -1) in the tube's blue,
#: B (phi = +1) in orange, mixed linearly between
POLYMORPH_B_RGB = np.array([0.90, 0.45, 0.10])
BODY_RGB = np.array([0.62, 0.64, 0.66])


def polymorph_mix(phi, a_rgb=TUBE_RGB, b_rgb=POLYMORPH_B_RGB) -> np.ndarray:
    """Colours (n, 3) of order parameters ``phi`` (n,): clipped to [-1, 1], ``a_rgb`` at -1
    mixed linearly to ``b_rgb`` at +1."""
    w = 0.5 * (np.clip(np.asarray(phi, float), -1.0, 1.0) + 1.0)
    return (1.0 - w)[:, None] * np.asarray(a_rgb)[None, :] + w[:, None] * np.asarray(b_rgb)[None, :]


def polymorph_rgb(order, n_segments: int, n_faces_per_ring: int, a_rgb=TUBE_RGB,
                  b_rgb=POLYMORPH_B_RGB) -> np.ndarray:
    """Face colours (Q, 3) of one tube from the order parameter per bead (N,): each of the
    ``n_segments`` ring segments of the resampled centreline (evenly spread over the bonds)
    takes ``phi`` interpolated at its middle, clipped to [-1, 1], mixed from ``a_rgb`` to
    ``b_rgb``."""
    order = np.asarray(order, float)
    n = len(order)
    u = (np.arange(n_segments) + 0.5) * (n - 1) / n_segments  # segment middles, in beads
    rgb = polymorph_mix(np.interp(u, np.arange(n), order), a_rgb, b_rgb)
    return np.repeat(rgb, n_faces_per_ring, axis=0)
BODY_ALPHA = 0.4


def _shade(normals, camera, rgb, ambient=0.35, diffuse=0.65):
    light = np.asarray(camera.toward) + 0.5 * np.array([0, 0, 1.0]) - 0.4 * np.asarray(camera.right)
    light /= np.linalg.norm(light)
    lam = np.clip(normals @ light, 0.0, None)
    rgb = np.asarray(rgb)
    return np.clip((ambient + diffuse * lam)[:, None] * (rgb if rgb.ndim == 2 else rgb[None, :]),
                   0, 1)


class Renderer:
    """Draws the scene of one run into 2D matplotlib axes, one camera per axes.

    Parameters
    ----------
    scene : :class:`Scene`
    sides, subdivide : tube resolution (ring vertices; points per bond)
    n_around : azimuthal resolution of the body mesh
    tube_rgb, body_rgb, body_alpha : colours; the body is semi-transparent

    Notes
    -----
    Reuse one instance for many frames: the body mesh is built once, and :meth:`draw` updates
    the collection it created on an axes instead of adding a new one (fast movies).
    """

    def __init__(self, scene: Scene, sides: int = 12, subdivide: int = 3, n_around: int = 48,
                 tube_rgb=TUBE_RGB, body_rgb=BODY_RGB, body_alpha: float = BODY_ALPHA):
        self.scene = scene
        self.sides = sides
        self.subdivide = subdivide
        self.tube_rgb = np.asarray(tube_rgb, float)
        self.body_rgb = np.asarray(body_rgb, float)
        self.body_alpha = float(body_alpha)
        v, f = (body_surface(scene.body_radius, scene.body_length, n_around=n_around,
                             shape=scene.body_shape) if scene.has_body else (None, None))
        if v is not None:  # a shape without a mesh is not drawn
            self._body = v[f]
            self._body_n = _face_normals(self._body)
        else:
            self._body = np.zeros((0, 3, 3))
            self._body_n = np.zeros((0, 3))
        self._collections = {}

    # geometry ------------------------------------------------------------------------------
    def polygons(self, x: np.ndarray, camera: Camera, pose=None, order=None):
        """Depth-sorted 2D polygons and RGBA colours of one frame seen by ``camera``.

        Parameters
        ----------
        x : (N, 3) bead positions [m]
        pose : ``(X, R)`` of a moving body (its reference point [m] and rotation, body to
            lab), or ``None`` for the fixed body at the origin
        order : (N,) a polymorphic filament's order parameter per bead: the tube coloured by
            polymorph (:func:`polymorph_rgb`), or ``None`` (one colour)

        Returns
        -------
        polys : list of (k, 2) arrays [m] in image coordinates, back to front
        rgba : (P, 4) face colours
        """
        toward = np.asarray(camera.toward)
        groups = []  # (polys3d list-like, normals, rgb, alpha)
        chains = self.scene.chains(len(x))
        for k, sl in enumerate(chains):  # one tube per flagellum, each its own colour
            quads, qn, caps, cn = tube_faces(x[sl], self.scene.tube_radius, self.sides,
                                             self.subdivide)
            rgb = self.tube_rgb if len(chains) == 1 else TUBE_PALETTE[k % len(TUBE_PALETTE)]
            if order is not None:
                o = np.asarray(order)[sl]
                groups.append((quads, qn, polymorph_rgb(o, len(quads) // self.sides,
                                                        self.sides, a_rgb=rgb), 1.0))
                groups.append((caps, cn, polymorph_mix(o[[0, -1]], rgb), 1.0))
                continue
            groups.append((quads, qn, rgb, 1.0))
            groups.append((caps, cn, rgb, 1.0))
        if len(self._body):
            body, bn = self._body, self._body_n
            if pose is not None:
                X, R = pose
                body, bn = body @ R.T + X, bn @ R.T
            groups.append((body, bn, self.body_rgb, self.body_alpha))
        polys, depth, rgba, lw = [], [], [], []
        for P, n, rgb, alpha in groups:
            front = n @ toward > 0.0
            P, n = P[front], n[front]
            if np.ndim(rgb) == 2:  # a colour per face (a polymorphic filament)
                rgb = rgb[front]
            if not len(P):
                continue
            u, v, d = camera.project(P)
            polys.extend(np.stack([u, v], axis=-1))
            depth.append(d.mean(axis=1))
            col = _shade(n, camera, rgb)
            rgba.append(np.column_stack([col, np.full(len(col), alpha)]))
            # opaque faces get a hairline edge of their own colour to close antialiasing seams;
            # translucent ones none (overlapping edges would draw the mesh lines, so faint
            # light seams remain on the body)
            lw.append(np.full(len(col), 0.25 if alpha >= 1.0 else 0.0))
        depth = np.concatenate(depth)
        order = np.argsort(depth, kind="stable")
        self._linewidths = np.concatenate(lw)[order]
        return [polys[i] for i in order], np.concatenate(rgba)[order]

    def draw(self, ax, x: np.ndarray, camera: Camera, pose=None, order=None):
        """Draw the frame ``x`` (N, 3) [m] into ``ax`` as seen by ``camera`` (a moving body at
        ``pose``, a polymorphic filament's ``order``: :meth:`polygons`); returns the
        collection."""
        from matplotlib.collections import PolyCollection

        polys, rgba = self.polygons(x, camera, pose, order)
        coll = self._collections.get(id(ax))
        if coll is None:
            coll = PolyCollection(polys, facecolors=rgba, edgecolors=rgba,
                                  linewidths=self._linewidths, antialiaseds=True)
            ax.add_collection(coll)
            self._collections[id(ax)] = coll
        else:
            coll.set_verts(polys)
            coll.set_facecolor(rgba)
            coll.set_edgecolor(rgba)
            coll.set_linewidth(self._linewidths)
        return coll


def view_limits(frames: np.ndarray, scene: Scene, cameras=CAMERAS, margin: float = 0.05,
                poses=None):
    """Common axes limits for every frame and every camera (same scale everywhere).

    Parameters
    ----------
    frames : (F, N, 3) bead positions [m] of all frames to be shown
    margin : extra space as a fraction of ``L``

    Returns
    -------
    (u_min, u_max), (z_min, z_max) : horizontal and vertical limits [m], the horizontal range
    centred on the body axis and wide enough for all cameras. The body is shown whole, up to
    its top (a cell cut off at the frame's edge read as a cropped figure). A moving body
    (``poses``, :func:`body_poses` of the frames shown) is kept in view whole as well.
    """
    frames = np.asarray(frames, float)
    if poses is not None:
        frames = np.concatenate([frames.reshape(-1, 3), body_outline(scene, poses)])[None]
    a = scene.tube_radius
    half = max(scene.body_radius, 1e-12)
    for cam in cameras:
        u, _, _ = cam.project(frames)
        half = max(half, float(np.abs(u).max()) + a)
    zmin = float(frames[..., 2].min()) - a
    zmax = float(frames[..., 2].max()) + a
    if scene.has_body and poses is None:
        # the whole body, to its top; the filament itself is never cut
        zmax = max(zmax, scene.body_radius + scene.body_length)
    m = margin * scene.length
    return (-half - m, half + m), (zmin - m, zmax + m)


def style_view(ax, ulim, zlim, title: str | None = None, scale_bar: float | None = None,
               length: float | None = None):
    """Equal-aspect, frameless axes with optional title and a scale bar of ``scale_bar`` [m]
    at the bottom left: a bar with end ticks, labelled with its length (um, mm or cm) and, if
    the filament's ``length`` [m] is given, as a fraction of ``L``."""
    ax.set_xlim(*ulim)
    ax.set_ylim(*zlim)
    ax.set_aspect("equal", adjustable="box")
    ax.set_xticks([])
    ax.set_yticks([])
    for s in ax.spines.values():
        s.set_visible(False)
    if title:
        ax.set_title(title, fontsize=8)
    if scale_bar:
        du, dz = ulim[1] - ulim[0], zlim[1] - zlim[0]
        x0, y0 = ulim[0] + 0.04 * du, zlim[0] + 0.03 * dz
        tick = 0.012 * dz
        ax.plot([x0, x0 + scale_bar], [y0, y0], color="k", lw=2.0, solid_capstyle="butt",
                zorder=10)
        for x in (x0, x0 + scale_bar):
            ax.plot([x, x], [y0 - tick, y0 + tick], color="k", lw=1.0, zorder=10)
        ax.text(x0, y0 + 1.6 * tick, scale_label(scale_bar, length), ha="left", va="bottom",
                fontsize=6, zorder=10)


def scale_label(bar: float, length: float | None = None) -> str:
    """``"2 cm"`` for a bar of 0.02 m; ``"2 cm = 0.05 L"`` with the filament's length."""
    label = (f"{bar * 100:g} cm" if bar >= 0.01 else
             f"{bar * 1e3:g} mm" if bar >= 1e-3 else f"{bar * 1e6:g} um")
    if length:
        label += f" = {bar / length:.3g} L"
    return label


def nice_scale_bar(span: float, fraction: float = 0.2) -> float:
    """A round length [m] of at most ``fraction`` of ``span`` [m] (1, 2 or 5 times a power of
    ten)."""
    target = span * fraction
    p = 10 ** np.floor(np.log10(target))
    for k in (5, 2, 1):
        if k * p <= target:
            return float(k * p)
    return float(p)
