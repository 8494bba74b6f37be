"""ParaView export: one VTK XML PolyData (.vtp) per saved frame, a .pvd time series, the body.

Written by hand (ASCII VTK XML, format 0.1), so no VTK library is needed. Layout of ``DIR``::

    DIR/run.pvd            time series; open this in ParaView
    DIR/filament_0000.vtp  one polyline per saved frame (N points, one line cell)
    DIR/body.vtp           the cell body as a closed triangle surface (if the run has a body;
                           a free swimmer's moves: DIR/body_NNNN.vtp, one per frame)
    DIR/boundary.vtp       a [[wall]]'s plane (a square under the run) or a [[tube]]'s wall

Time values in the .pvd are ``t/T`` (the paper's clock) by default, or seconds. Coordinates are
in metres, body axis +z, clamp at the origin (see :mod:`flagwrap.io.runfile`).

Point data of each filament frame (per bead; N values):

=====================  =========  ==================================================================
name                   units      definition
=====================  =========  ==================================================================
arclength              m          ``s`` along the rest contour (cumulative bond length)
curvature              1/m        ``|kappa b_i| / l_i``, ``kappa b_i = 2 t_{i-1} x t_i / (1 + t_{i-1}.t_i)``,
                                  ``l_i`` the Voronoi length (Bergou et al. 2008); 0 at both ends
twist_rate             rad/m      ``m_i / l_i``: ``m_i`` = angle from the parallel-transported
                                  director ``m1_{i-1}`` to ``m1_i`` about ``t_i``; 0 at both ends
excess_twist_rate      rad/m      ``(m_i - m_i^0) / l_i``, twist minus the rest twist (twist strain)
handedness             1          sign of the discrete torsion, ``sign(e_{i-1} . (e_i x e_{i+1}))``
                                  summed over the two triples centred on bead i: +1 right-handed,
                                  -1 left-handed, 0 straight/planar
elastic_force          N          ``-dE/dx_i`` of the Kirchhoff energy (bending, twisting,
                                  stretching) rebuilt from the positions and directors (see below)
polymorph_order        1          a polymorphic filament's order parameter (-1: polymorph A, +1: B);
                                  its rest curvature and twist, and so ``excess_twist_rate`` and
                                  ``elastic_force``, are those of this frame's state
=====================  =========  ==================================================================

The elastic force is recomputed with the simulator's own energy: reference frames by parallel
transport along the rod (zero reference twist), the material angle of each bond measured
from the stored director ``m1``, and the rest state of the run's config. Twist between two
adjacent bonds is thus known modulo 2 pi, which is exact as long as it stays below pi (a rod
twisted by half a turn over one bond would be far outside the model anyway); the rebuilt
elastic energy agrees with the stored ``elastic_energy`` (tested). Contact and motor forces are
not included. Cell data: ``turns`` (t/T) and ``time`` [s] of the frame.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

# --------------------------------------------------------------------------------------------
# discrete geometry of a polyline (pure functions; positions in any length unit)


def _unit(v):
    return v / np.maximum(np.linalg.norm(v, axis=-1, keepdims=True), 1e-300)


def voronoi_lengths(x: np.ndarray) -> np.ndarray:
    """Half the sum of the two bond lengths at each bead (N,); ends get half their bond."""
    ln = np.linalg.norm(np.diff(x, axis=0), axis=1)
    vor = np.empty(len(x))
    vor[1:-1] = 0.5 * (ln[:-1] + ln[1:])
    vor[0], vor[-1] = 0.5 * ln[0], 0.5 * ln[-1]
    return vor


def curvature(x: np.ndarray) -> np.ndarray:
    """Discrete curvature at each bead (N,) [1/length]; 0 at the two ends.

    ``kappa_i = |2 t_{i-1} x t_i / (1 + t_{i-1}.t_i)| / l_i`` (Bergou et al., SIGGRAPH 2008),
    which equals ``2 tan(phi_i/2) / l_i`` for a turning angle ``phi_i``: exact on a circle of
    radius ``rho`` sampled with bond length ``l`` up to ``O((l/rho)^2)``.
    """
    t = _unit(np.diff(x, axis=0))
    kb = 2 * np.cross(t[:-1], t[1:]) / (1 + np.einsum("ij,ij->i", t[:-1], t[1:]))[:, None]
    out = np.zeros(len(x))
    out[1:-1] = np.linalg.norm(kb, axis=1) / voronoi_lengths(x)[1:-1]
    return out


def handedness(x: np.ndarray, rel_tol: float = 1e-6) -> np.ndarray:
    """Local handedness sign at each bead (N,) int: +1 right, -1 left, 0 straight/planar.

    Sign of the discrete torsion ``e_{i-1} . (e_i x e_{i+1})`` (bond vectors ``e``), summed over
    the triples centred on the two bonds adjacent to bead ``i``; beads near the ends use the
    nearest triple. ``|sum| <= rel_tol l^3`` counts as planar.
    """
    e = np.diff(x, axis=0)
    N = len(x)
    if N < 4:
        return np.zeros(N, dtype=int)
    trip = np.einsum("ij,ij->i", e[:-2], np.cross(e[1:-1], e[2:]))  # centred on bond j+1
    # bead i sits between bonds i-1 and i: triples centred there have index i-2 and i-1
    tb = np.zeros(N)
    for i in range(N):
        js = [j for j in (i - 2, i - 1) if 0 <= j < len(trip)]
        if not js:
            js = [min(max(i - 1, 0), len(trip) - 1)]
        tb[i] = trip[js].sum()
    scale = np.mean(np.linalg.norm(e, axis=1)) ** 3
    return np.where(np.abs(tb) > rel_tol * scale, np.sign(tb), 0).astype(int)


def twist_per_bead(x: np.ndarray, m1: np.ndarray) -> np.ndarray:
    """Twist angle ``m_i`` [rad] between bonds ``i-1`` and ``i`` at each bead (N,); 0 at the ends.

    ``m_i`` is the signed angle about ``t_i`` from ``P_i m1_{i-1}`` to ``m1_i``, where ``P_i``
    is the parallel transport from ``t_{i-1}`` to ``t_i`` (the discrete twist of Bergou et al.).
    """
    t = _unit(np.diff(x, axis=0))
    m1 = _unit(np.asarray(m1, float) - np.einsum("ij,ij->i", m1, t)[:, None] * t)
    t1, t2, v = t[:-1], t[1:], m1[:-1]
    c = np.einsum("ij,ij->i", t1, t2)
    b = np.cross(t1, t2)
    pv = (c[:, None] * v + np.cross(b, v)
          + (np.einsum("ij,ij->i", b, v) / (1 + c))[:, None] * b)
    s = np.einsum("ij,ij->i", np.cross(pv, m1[1:]), t2)
    co = np.einsum("ij,ij->i", pv, m1[1:])
    out = np.zeros(len(x))
    out[1:-1] = np.arctan2(s, co)
    return out


class ElasticForces:
    """Elastic forces and energy of saved frames, rebuilt with the run's own energy.

    Parameters
    ----------
    config : :class:`flagwrap.params.Config` of the run

    Notes
    -----
    Builds the run's filaments once (:func:`flagwrap.system.parts.build_parts`: their rest
    states, no mobility or body); each call costs one energy-gradient evaluation.
    """

    def __init__(self, config):
        from flagwrap.system.parts import build_parts

        self.parts = build_parts(config)
        #: a polymorphic filament's two rest shapes (flagwrap.system.polymorph.rest_pair):
        #: :meth:`set_order` moves the rest between them as the simulator does
        self._pairs = None
        if config.polymorph.enabled:
            import dataclasses

            from flagwrap.system.polymorph import rest_pair

            self._pairs = []
            for p in self.parts:
                p.rest = dataclasses.replace(p.rest, kbar=p.rest.kbar.copy(),
                                             mbar=p.rest.mbar.copy())
                self._pairs.append(rest_pair(p, config)[:4])
        self.L = config.scales.length
        self.force_scale = config.scales.force
        self.energy_scale = config.scales.energy

    def set_order(self, order) -> None:
        """Polymorphic filaments' rests at the order parameters ``order`` (every bead of the
        run, one frame's: ``a + (phi + 1)/2 (b - a)``, as the simulator's ``set_rest``)."""
        from flagwrap.elasticity.polymorph import interpolate_rest

        order = np.asarray(order, float)
        start = 0
        for p, (ka, kb, ma, mb) in zip(self.parts, self._pairs):
            phi = order[start:start + p.N]
            p.rest.kbar[:] = interpolate_rest(ka, kb, phi)
            p.rest.mbar[:] = interpolate_rest(ma, mb, phi)
            start += p.N

    def rest_twist(self, filament: int = 0) -> np.ndarray:
        """Rest twist ``m_i^0`` [rad] per bead (N,) of flagellum ``filament``."""
        return np.asarray(self.parts[filament].rest.mbar, float)

    def __call__(self, x: np.ndarray, m1: np.ndarray, filament: int = 0):
        """Elastic energy [J] and forces ``-dE/dx`` (N, 3) [N] of one frame of one flagellum.

        Parameters
        ----------
        x : (N, 3) bead positions [m] of flagellum ``filament``
        m1 : (N-1, 3) its material directors
        """
        from flagwrap.elasticity.rod import Frames, elastic_forces
        from flagwrap.geometry.frames import space_parallel_frames

        xc = np.asarray(x, float) / self.L
        t, d1 = space_parallel_frames(xc)
        d2 = np.cross(t, d1)
        theta = np.arctan2(np.einsum("ij,ij->i", m1, d2), np.einsum("ij,ij->i", m1, d1))
        theta = np.unwrap(theta)  # adjacent differences in (-pi, pi]
        base = Frames(t, d1, np.zeros(len(xc)))
        E, f, _, _ = elastic_forces(xc, theta, base, self.parts[filament].rest)
        return E * self.energy_scale, f * self.force_scale


# --------------------------------------------------------------------------------------------
# XML writers


def _fmt(a) -> str:
    a = np.asarray(a)
    if a.dtype.kind in "iu":
        return " ".join(str(int(v)) for v in a.ravel())
    return " ".join(f"{v:.9g}" for v in a.ravel())


def _data_array(name: str, a, ncomp: int = 1, vtype: str | None = None) -> str:
    a = np.asarray(a)
    if vtype is None:
        vtype = "Int32" if a.dtype.kind in "iu" else "Float64"
    comp = f' NumberOfComponents="{ncomp}"' if ncomp > 1 else ""
    return (f'        <DataArray type="{vtype}" Name="{name}"{comp} format="ascii">\n'
            f"          {_fmt(a)}\n        </DataArray>\n")


def polydata_xml(points: np.ndarray, lines=None, polys=None, point_data: dict | None = None,
                 cell_data: dict | None = None) -> str:
    """VTK XML PolyData text.

    Parameters
    ----------
    points : (P, 3)
    lines : list of 1D index arrays (each a polyline cell)
    polys : (F, k) int array of polygons (e.g. triangles)
    point_data, cell_data : name -> (P,) / (P, 3) arrays; (C,) / (C, 3) for cells
    """
    points = np.asarray(points, float)
    lines = [] if lines is None else [np.asarray(c, int) for c in lines]
    polys = np.zeros((0, 3), int) if polys is None else np.asarray(polys, int)
    out = ['<?xml version="1.0"?>\n',
           '<VTKFile type="PolyData" version="0.1" byte_order="LittleEndian">\n',
           "  <PolyData>\n",
           f'    <Piece NumberOfPoints="{len(points)}" NumberOfVerts="0" '
           f'NumberOfLines="{len(lines)}" NumberOfStrips="0" NumberOfPolys="{len(polys)}">\n']

    def block(tag, data):
        if not data:
            return
        out.append(f"      <{tag}>\n")
        for name, a in data.items():
            a = np.asarray(a)
            out.append(_data_array(name, a, a.shape[1] if a.ndim == 2 else 1))
        out.append(f"      </{tag}>\n")

    block("PointData", point_data)
    block("CellData", cell_data)
    out.append("      <Points>\n")
    out.append(_data_array("Points", points, 3, "Float64"))
    out.append("      </Points>\n")
    for tag, cells in (("Lines", lines), ("Polys", list(polys))):
        out.append(f"      <{tag}>\n")
        conn = np.concatenate(cells) if len(cells) else np.zeros(0, int)
        offs = np.cumsum([len(c) for c in cells]).astype(int)
        out.append(_data_array("connectivity", conn.astype(int), 1, "Int32"))
        out.append(_data_array("offsets", offs, 1, "Int32"))
        out.append(f"      </{tag}>\n")
    out.append("    </Piece>\n  </PolyData>\n</VTKFile>\n")
    return "".join(out)


def pvd_xml(entries) -> str:
    """ParaView collection text; ``entries`` = iterable of (time, part, relative file)."""
    rows = "".join(f'    <DataSet timestep="{t:.9g}" group="" part="{part}" file="{f}"/>\n'
                   for t, part, f in entries)
    return ('<?xml version="1.0"?>\n'
            '<VTKFile type="Collection" version="0.1" byte_order="LittleEndian">\n'
            f"  <Collection>\n{rows}  </Collection>\n</VTKFile>\n")


def frames_point_data(x, m1, slices, forces: ElasticForces | None = None,
                      rest_twists=None) -> dict:
    """:func:`frame_point_data` of every flagellum (bead ``slices``; their bonds follow one
    another likewise, one fewer per flagellum), concatenated in bead order."""
    parts = []
    for k, sl in enumerate(slices):
        bonds = slice(sl.start - k, sl.stop - k - 1)
        parts.append(frame_point_data(
            x[sl], m1[bonds], None if forces is None else (lambda xx, mm, k=k: forces(xx, mm, k)),
            None if rest_twists is None else rest_twists[k]))
    return {key: np.concatenate([p[key] for p in parts]) for key in parts[0]}


def frame_point_data(x: np.ndarray, m1: np.ndarray, forces=None,
                     rest_twist: np.ndarray | None = None) -> dict:
    """The per-bead fields of one frame (see the module docstring); ``x`` in [m]."""
    vor = voronoi_lengths(x)
    tw = twist_per_bead(x, m1)
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(x, axis=0), axis=1))])
    data = {
        "arclength": s,
        "curvature": curvature(x),
        "twist_rate": tw / vor,
        "handedness": handedness(x),
    }
    if rest_twist is not None:
        ex = tw - rest_twist
        ex[0] = ex[-1] = 0.0
        data["excess_twist_rate"] = ex / vor
    if forces is not None:
        data["elastic_force"] = forces(x, m1)[1]
    return data


def export_vtk(ds, directory, time_unit: str = "turns", stride: int = 1,
               with_forces: bool = True, n_around: int = 48) -> Path:
    """Write a run as a ParaView time series; returns the path of the .pvd file.

    Parameters
    ----------
    ds : run dataset (:func:`flagwrap.io.runfile.read_run`)
    directory : output folder (created)
    time_unit : "turns" (t/T, default) or "seconds": the .pvd time values
    stride : write every ``stride``-th saved frame
    with_forces : rebuild the elastic force per bead (one energy evaluation per frame)
    n_around : azimuthal resolution of the body surface
    """
    from flagwrap.errors import UserInputError
    from flagwrap.io.runfile import config_of, filament_slices
    from flagwrap.plotting.render import body_poses, body_surface, scene_of

    if time_unit not in ("turns", "seconds"):
        raise UserInputError(f"time unit must be 'turns' or 'seconds', got {time_unit!r}")
    if stride < 1:
        raise UserInputError(f"stride must be >= 1, got {stride}")
    d = Path(directory)
    d.mkdir(parents=True, exist_ok=True)
    X = ds["position"].values
    M1 = ds["director"].values
    turns = ds["turns"].values
    secs = ds["time"].values
    tvals = turns if time_unit == "turns" else secs
    elastic = ElasticForces(config_of(ds))  # the rest twist is needed either way
    slices = filament_slices(ds)
    rest = [elastic.rest_twist(k) for k in range(len(slices))]
    forces = elastic if with_forces else None
    entries = []
    idx = range(0, len(turns), stride)
    width = max(4, len(str(len(turns) - 1)))
    line = [np.arange(sl.start, sl.stop) for sl in slices]  # one polyline per flagellum
    order = ds["polymorph_order"].values if "polymorph_order" in ds.variables else None
    for i in idx:
        name = f"filament_{i:0{width}d}.vtp"
        if order is not None:  # the rests of this frame's polymorph state
            elastic.set_order(order[i])
        pdata = frames_point_data(X[i], M1[i], slices, forces, rest)
        if order is not None:
            pdata["polymorph_order"] = np.asarray(order[i], float)
        cdata = {"turns": np.array([turns[i]]), "time": np.array([secs[i]])}
        _write(d / name, polydata_xml(X[i], lines=line, point_data=pdata, cell_data=cdata))
        entries.append((float(tvals[i]), 0, name))
    scene = scene_of(ds)
    poses = body_poses(ds)
    v, f = (body_surface(scene.body_radius, scene.body_length, n_around=n_around,
                         shape=scene.body_shape) if scene.has_body else (None, None))
    if v is not None and poses is None:
        _write(d / "body.vtp", polydata_xml(v, polys=f))
        entries += [(float(tvals[i]), 1, "body.vtp") for i in idx]
    elif v is not None:  # a free swimmer: the body where it is, frame by frame
        for i in idx:
            name = f"body_{i:0{width}d}.vtp"
            _write(d / name, polydata_xml(v @ poses[1][i].T + poses[0][i], polys=f))
            entries.append((float(tvals[i]), 1, name))
    bv, bf = boundary_mesh(config_of(ds), X)
    if bv is not None:  # the wall or the tube, still: one file for every frame
        _write(d / "boundary.vtp", polydata_xml(bv, polys=bf))
        entries += [(float(tvals[i]), 2, "boundary.vtp") for i in idx]
    pvd = d / "run.pvd"
    _write(pvd, pvd_xml(entries))  # last: a complete .pvd names only complete frames
    return pvd


def boundary_mesh(config, positions, n_around: int = 48):
    """The config's boundary as triangles in metres, or ``(None, None)``: a ``[[tube]]``'s
    wall (:meth:`flagwrap.confinement.tube.Tube.surface_mesh`), or a ``[[wall]]``'s plane as
    a square (two triangles) centred under the beads' mean position over the run, its side
    three times their largest distance from it (at least three filament lengths)."""
    if config.tubes:
        return config.tubes[0].geometry(1.0).surface_mesh(n_around)
    if not config.walls:
        return None, None
    w = config.walls[0]
    n, p = w.unit_normal, np.asarray(w.point, float)
    x = np.asarray(positions, float).reshape(-1, 3)
    c = x.mean(axis=0)
    c = c - ((c - p) @ n) * n
    half = 1.5 * max(float(np.linalg.norm(x - c, axis=1).max()), 2.0 * config.filament.length)
    t = np.array([1.0, 0.0, 0.0]) if abs(n[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    e1 = t - (t @ n) * n
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(n, e1)
    v = np.array([c + half * (su * e1 + sv * e2) for su, sv in ((-1, -1), (1, -1), (1, 1), (-1, 1))])
    return v, np.array([[0, 1, 2], [0, 2, 3]])


def _write(path, text: str) -> None:
    """Write one VTK file atomically (temporary file beside it, renamed in)."""
    from flagwrap.io.atomic import atomic_write

    atomic_write(path, lambda tmp: tmp.write_text(text))
