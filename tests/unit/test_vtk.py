"""ParaView export: .vtp/.pvd read back (pyvista and plain XML), discrete-geometry oracles."""

import numpy as np
import pytest

from flagwrap.io.runfile import read_run



def _helix(handed=+1, n=80, R=0.03, pitch=0.07, turns=2.0):
    s = np.linspace(0, 2 * np.pi * turns, n)
    # (R cos s, R sin s, b s) is right-handed for b > 0; it hangs down for handed = -1
    return np.column_stack([R * np.cos(s), R * np.sin(s), handed * pitch * s / (2 * np.pi)])


def test_curvature_of_a_circle_and_a_helix():
    from flagwrap.io.vtk import curvature

    rho = 0.05
    s = np.linspace(0, np.pi, 200)
    x = np.column_stack([rho * np.cos(s), rho * np.sin(s), np.zeros_like(s)])
    k = curvature(x)
    assert k[0] == k[-1] == 0
    np.testing.assert_allclose(k[1:-1], 1 / rho, rtol=1e-4)
    # helix: kappa = R / (R^2 + b^2), b = pitch / 2 pi
    R, P = 0.03, 0.07
    b = P / (2 * np.pi)
    np.testing.assert_allclose(curvature(_helix(n=400, R=R, pitch=P))[1:-1], R / (R**2 + b**2),
                               rtol=1e-3)


def test_handedness_sign_of_torsion():
    from flagwrap.io.vtk import handedness

    assert (handedness(_helix(+1)) == 1).all()
    assert (handedness(_helix(-1)) == -1).all()
    line = np.column_stack([np.zeros(10), np.zeros(10), -np.arange(10.0)])
    assert (handedness(line) == 0).all()


def test_twist_rate_of_a_uniformly_twisted_straight_rod():
    from flagwrap.io.vtk import twist_per_bead, voronoi_lengths

    N, tau, ds = 30, 12.0, 0.01
    x = np.column_stack([np.zeros(N), np.zeros(N), -ds * np.arange(N)])
    ang = tau * ds * np.arange(N - 1)
    m1 = np.column_stack([np.cos(ang), np.sin(ang), np.zeros(N - 1)])
    tw = twist_per_bead(x, m1) / voronoi_lengths(x)
    # t = -z: rotating m1 counterclockwise about +z is a negative twist about t
    np.testing.assert_allclose(tw[1:-1], -tau, rtol=1e-9)
    assert tw[0] == tw[-1] == 0


def test_rebuilt_elastic_energy_matches_the_run(tiny_run):
    # oracle: the simulator's stored elastic energy at every saved frame
    from flagwrap.io.runfile import config_of
    from flagwrap.io.vtk import ElasticForces

    ds = read_run(tiny_run)
    ef = ElasticForces(config_of(ds))
    E = np.array([ef(x, m)[0] for x, m in zip(ds["position"].values, ds["director"].values)])
    np.testing.assert_allclose(E, ds["elastic_energy"].values, rtol=1e-8,
                               atol=1e-12 * ds["elastic_energy"].values.max())
    # forces are internal: they sum to zero (no external load in the elastic energy)
    f = ef(ds["position"].values[-1], ds["director"].values[-1])[1]
    assert np.abs(f.sum(axis=0)).max() < 1e-9 * np.abs(f).max()


def _read_vtp_xml(path):
    import xml.etree.ElementTree as ET

    root = ET.parse(path).getroot()
    assert root.get("type") == "PolyData"
    piece = root.find("PolyData/Piece")
    arrays = {a.get("Name"): np.array(a.text.split(), float) for a in piece.iter("DataArray")}
    return piece, arrays


@pytest.fixture(scope="module")
def exported(tiny_run, tmp_path_factory):
    from flagwrap.cli.main import main

    d = tmp_path_factory.mktemp("vtkout")
    assert main(["export-vtk", str(tiny_run), str(d)]) == 0
    return d


def test_pvd_series_lists_every_frame_and_the_body(tiny_run, exported):
    import xml.etree.ElementTree as ET

    ds = read_run(tiny_run)
    entries = ET.parse(exported / "run.pvd").getroot().findall("Collection/DataSet")
    fil = [e for e in entries if e.get("part") == "0"]
    body = [e for e in entries if e.get("part") == "1"]
    assert len(fil) == len(body) == ds.sizes["time"]
    np.testing.assert_allclose([float(e.get("timestep")) for e in fil], ds["turns"].values,
                               rtol=1e-8, atol=1e-12)
    for e in entries:
        assert (exported / e.get("file")).is_file()


def test_vtp_points_and_fields_read_back_as_xml(tiny_run, exported):
    ds = read_run(tiny_run)
    X = ds["position"].values
    files = sorted(exported.glob("filament_*.vtp"))
    assert len(files) == len(X)
    piece, a = _read_vtp_xml(files[-1])
    N = X.shape[1]
    assert int(piece.get("NumberOfPoints")) == N and int(piece.get("NumberOfLines")) == 1
    np.testing.assert_allclose(a["Points"].reshape(N, 3), X[-1], rtol=1e-8, atol=1e-12)
    for name in ("curvature", "twist_rate", "excess_twist_rate", "handedness", "arclength"):
        assert a[name].shape == (N,)
    assert a["elastic_force"].shape == (3 * N,)
    assert set(np.unique(a["handedness"])) <= {-1.0, 0.0, 1.0}
    # the tiny helix is left-handed at rest
    _, a0 = _read_vtp_xml(files[0])
    assert np.mean(a0["handedness"] == -1) > 0.9


def test_without_forces_only_the_force_field_is_left_out(tiny_run, exported, tmp_path):
    from flagwrap.io.vtk import export_vtk

    export_vtk(read_run(tiny_run), tmp_path / "nf", with_forces=False)
    _, with_f = _read_vtp_xml(sorted(exported.glob("filament_*.vtp"))[-1])
    _, without = _read_vtp_xml(sorted((tmp_path / "nf").glob("filament_*.vtp"))[-1])
    assert set(with_f) - set(without) == {"elastic_force"}
    np.testing.assert_array_equal(with_f["excess_twist_rate"], without["excess_twist_rate"])


def test_vtp_and_pvd_read_back_with_pyvista(tiny_run, exported):
    pv = pytest.importorskip("pyvista")
    ds = read_run(tiny_run)
    X = ds["position"].values
    m = pv.read(exported / "filament_0003.vtp")
    assert m.n_points == X.shape[1] and m.n_cells == 1
    np.testing.assert_allclose(m.points, X[3], rtol=1e-8, atol=1e-12)
    assert m.point_data["elastic_force"].shape == (X.shape[1], 3)
    body = pv.read(exported / "body.vtp")
    assert body.is_manifold and body.volume > 0
    reader = pv.get_reader(exported / "run.pvd")
    np.testing.assert_allclose(reader.time_values, ds["turns"].values, atol=1e-9)
    reader.set_active_time_value(reader.time_values[-1])
    blocks = reader.read()
    assert blocks[0].n_points == X.shape[1]
    np.testing.assert_allclose(blocks[0].points, X[-1], rtol=1e-8, atol=1e-12)


def test_export_errors(tiny_run, tmp_path):
    from flagwrap.cli.main import main

    assert main(["export-vtk", str(tmp_path / "none.nc"), str(tmp_path / "o")]) == 2
    assert main(["export-vtk", str(tiny_run), str(tmp_path / "o"), "--stride", "0"]) == 2
