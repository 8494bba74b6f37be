"""Bundle observables (flagwrap.observables.bundle) on ideal helices with known answers, and
`flagwrap analyze` on a run of two flagella."""

import math

import numpy as np
import pytest

from flagwrap.observables.bundle import bundle_phases, bundle_separation, bundle_summary, phase_lags


def helix(R=0.1, P=0.3, turns=2.0, n=401, phase=0.0, centre=(0.0, 0.0)):
    """An ideal helix hanging down from z = 0 about the vertical axis through ``centre``."""
    u = np.linspace(0.0, turns, n)
    a = 2 * math.pi * u + phase
    return np.column_stack([centre[0] + R * np.cos(a), centre[1] + R * np.sin(a), -P * u])


def test_helices_on_one_axis_are_bundled_with_their_phase_lag():
    # the distal half of a 2-turn helix is one whole turn: its centroid lies on the axis, so
    # two helices on one axis are 0 R apart (to the discretisation of 201 points a turn,
    # O(1/n)), and the phase lag is the angle between them (about the axis pointing from the
    # proximal to the distal half, -z here: clockwise seen from above, so -2 rad)
    x = np.concatenate([helix(), helix(phase=2.0)])[None]
    sl = [slice(0, 401), slice(401, 802)]
    assert bundle_separation(x, sl, 0.1)[0] < 1e-2
    assert phase_lags(bundle_phases(x, sl))[0, 1] == pytest.approx(-2.0, abs=1e-2)


def test_helices_side_by_side_are_their_axes_apart():
    x = np.concatenate([helix(), helix(centre=(0.3, 0.0))])[None]
    sl = [slice(0, 401), slice(401, 802)]
    assert bundle_separation(x, sl, 0.1)[0] == pytest.approx(3.0, abs=1e-2)
    s = bundle_summary([0.0], x, sl, 0.1)
    assert not s["bundled"] and s["separation"] == pytest.approx(3.0, abs=1e-2)


def test_three_helices_mean_pair_separation():
    # axes at the corners of an equilateral triangle of side 2R: every pair 2 R apart
    c = [(0.0, 0.0), (0.2, 0.0), (0.1, 0.2 * math.sin(math.pi / 3))]
    x = np.concatenate([helix(centre=cc) for cc in c])[None]
    sl = [slice(401 * k, 401 * (k + 1)) for k in range(3)]
    assert bundle_separation(x, sl, 0.1)[0] == pytest.approx(2.0, abs=1e-2)


@pytest.fixture(scope="module")
def two_run(tmp_path_factory):
    """Two flagella placed symmetrically on the cap (HI off, transparent body), 0.5 CCW +
    1 CW turn: a run file."""
    import tomllib

    from flagwrap.io.config import config_from_dict
    from flagwrap.io.runfile import write_run
    from flagwrap.simulation import simulate
    from test_parts import with_tables

    text = with_tables("[numerics]\nhydrodynamics = false\n[[flagellum]]\npolar_deg = 35\n"
                       "[[flagellum]]\npolar_deg = 35\nazimuth_deg = 180\n")
    text = text.replace('turns = 0.2}, {direction = "cw", turns = 0.1}',
                        'turns = 0.5}, {direction = "cw", turns = 1.0}').replace("tol = 1e-3",
                                                                                "tol = 1e-5")
    tr = simulate(config_from_dict(tomllib.loads(text)))
    assert tr.ok
    return write_run(tr, tmp_path_factory.mktemp("two") / "two.nc")


def test_analyze_reports_each_flagellum_and_the_bundle(two_run, tmp_path):
    # by the half-turn symmetry the two free-end heights are the same series, so their
    # verdicts are too
    import shutil

    from flagwrap.analysis.runfile_attrs import analyze_run_file
    from flagwrap.io.runfile import read_run

    path = shutil.copy(two_run, tmp_path / "two.nc")
    res = analyze_run_file(path)
    assert len(res["filaments"]) == 2 and res["filament"] in (0, 1)
    a, b = res["filaments"]
    assert a["final_height"] == pytest.approx(b["final_height"], abs=1e-6)
    assert a["buckled"] == b["buckled"] and a["state"] == b["state"]
    # each flagellum's torque is its own motor's: half the total here, by symmetry
    assert a["torque_peak_reduced"] == pytest.approx(b["torque_peak_reduced"], rel=1e-6)
    total = read_run(two_run)["motor_torque_reduced"].values
    assert abs(a["torque_peak_reduced"]) <= 0.5 * np.abs(total).max() * (1 + 1e-6)
    assert not res["bundle"]["bundled"]  # 35 deg apart on the cap: two separate helices
    assert res["bundle"]["crossings"] == 0
    ds = read_run(path)
    assert ds["free_end_height"].dims == ("filament", "time")
    assert ds.attrs["analysis_bundle_bundled"] == 0 and "analysis_filaments" in ds.attrs
    np.testing.assert_allclose(ds["free_end_height"].values[0], ds["free_end_height"].values[1],
                               atol=1e-6)
    # the verdict the critical-M runner reads is the first flagellum's to buckle, and
    # analysing flagellum k alone is the same as analysing its beads
    from flagwrap.analysis.runfile_attrs import analyze_dataset

    one = analyze_dataset(read_run(two_run), filament=1).summary()
    assert one["final_height"] == pytest.approx(b["final_height"], abs=1e-12)


def test_vtk_draws_one_polyline_per_flagellum(two_run, tmp_path):
    import re

    from flagwrap.io.runfile import read_run
    from flagwrap.io.vtk import export_vtk

    ds = read_run(two_run)
    pvd = export_vtk(ds, tmp_path / "vtk", stride=10)
    first = sorted((tmp_path / "vtk").glob("filament_*.vtp"))[0].read_text()
    n = ds.sizes["bead"]
    assert f'NumberOfPoints="{n}"' in first and 'NumberOfLines="2"' in first
    # the arclength restarts at the second flagellum's first bead
    arc = re.search(r'Name="arclength"[^>]*>\s*([^<]+)<', first).group(1).split()
    assert float(arc[0]) == 0.0 and float(arc[n // 2]) == 0.0 and float(arc[n // 2 - 1]) > 0
    assert pvd.is_file()


def test_renderer_draws_every_flagellum(two_run):
    from flagwrap.io.runfile import read_run
    from flagwrap.plotting.render import CAMERAS, Renderer, scene_of

    ds = read_run(two_run)
    scene = scene_of(ds)
    assert len(scene.chains(ds.sizes["bead"])) == 2
    x = ds["position"].values[-1]
    one = Renderer(scene.__class__(scene.tube_radius, 0.0, 0.0, scene.length))
    polys_two, _ = Renderer(scene.__class__(scene.tube_radius, 0.0, 0.0, scene.length,
                                            filaments=scene.filaments)).polygons(x, CAMERAS[0])
    polys_one, _ = one.polygons(x, CAMERAS[0])
    # as two tubes, no tube joins the first flagellum's free end to the second one's anchor
    assert len(polys_two) != len(polys_one)


def test_analyze_and_its_figure_on_a_free_cell_with_two_flagella(tmp_path, capsys):
    # the free swimmer kind: the analysis in the body's frame, per flagellum, and the
    # swimming figure with one height line per flagellum
    import json
    import tomllib

    from flagwrap.cli.main import main
    from flagwrap.io.config import config_from_dict
    from flagwrap.io.runfile import write_run
    from flagwrap.simulation import simulate
    from test_parts import TWO

    text = TWO + ("[body]\nsurface = 'no-slip'\nmotion = 'free'\nblob_spacing = 0.025\n"
                  "[[flagellum]]\npolar_deg = 35\n[[flagellum]]\npolar_deg = 35\n"
                  "azimuth_deg = 180\n")
    tr = simulate(config_from_dict(tomllib.loads(text)))
    assert tr.ok and tr.body
    path = write_run(tr, tmp_path / "free2.nc")
    png = tmp_path / "swim.png"
    assert main(["analyze", str(path), "--json", "--figure", str(png)]) == 0
    res = json.loads(capsys.readouterr().out)
    assert len(res["filaments"]) == 2 and "separation" in res["bundle"]
    # both motors' power (each torque times its own rate) and an efficiency below one
    assert all(p["motor_power"] > 0 and 0 < p["efficiency"] < 1 for p in res["swimming"])
    assert png.is_file() and png.stat().st_size > 10_000
    from flagwrap.io.runfile import read_run

    ds = read_run(path)  # every motor's torque and rate, in SI
    assert ds["motor_torques"].dims == ("time", "filament")
    np.testing.assert_allclose(ds["motor_torques"].values.sum(axis=1), ds["motor_torque"].values,
                               rtol=1e-12)
    np.testing.assert_allclose(ds["motor_rates"].values[:, 1], ds["omega"].values, rtol=1e-12)


def test_rebuilt_elastic_energy_of_each_flagellum_adds_up_to_the_simulators(two_run):
    # oracle: the simulator's stored elastic energy, every saved frame; each flagellum's
    # rebuilt with its own rest state (its own reference frames: the copies' differ)
    from flagwrap.io.runfile import config_of, filament_slices, read_run
    from flagwrap.io.vtk import ElasticForces

    ds = read_run(two_run)
    ef = ElasticForces(config_of(ds))
    sl = filament_slices(ds)
    E = []
    for x, m in zip(ds["position"].values, ds["director"].values):
        E.append(sum(ef(x[s], m[s.start - k:s.stop - k - 1], k)[0] for k, s in enumerate(sl)))
    ref = ds["elastic_energy"].values
    np.testing.assert_allclose(E, ref, rtol=1e-8, atol=1e-12 * ref.max())


def test_the_last_whole_turn_centres_a_helix_of_any_length():
    # a 1.85-turn helix (P. putida's coil): its distal half is 0.93 turn, whose centroid is
    # off the axis by a phase-dependent ~0.1 R; its last whole turn's lies on it
    from flagwrap.observables.bundle import last_turn

    R, P, turns = 0.1, 0.3, 1.85
    L = turns * math.hypot(2 * math.pi * R, P)
    distal = last_turn(R, P, L)
    assert distal == pytest.approx(1 - 1 / turns)
    sl = [slice(0, 741), slice(741, 1482)]
    for phase in np.linspace(0, 2 * math.pi, 5):
        x = np.concatenate([helix(R, P, turns, 741, phase), helix(R, P, turns, 741, phase + 3.0)])
        assert bundle_separation(x[None], sl, R, distal)[0] < 1e-2
    half = bundle_separation(x[None], sl, R, 0.5)[0]
    assert half > 5e-2  # the half-filament centroid is off the axis
