"""Rendering geometry (tube, body mesh, cameras) and headless snapshot strips."""

import numpy as np
import pytest

from flagwrap.cli.main import main
from flagwrap.io.runfile import read_run
from flagwrap.plotting.render import (CAMERAS, Renderer, Scene, body_surface,
                                      resample_centerline, tube_faces, view_limits)



def test_body_mesh_is_closed_with_outward_normals():
    # oracle: divergence theorem, volume = (2/3) pi R^3 + pi R^2 H for the exact body
    R, H = 0.05, 0.25
    v, f = body_surface(R, H, n_around=96, n_cap=24)
    tri = v[f]
    vol = np.einsum("ij,ij->i", tri[:, 0], np.cross(tri[:, 1], tri[:, 2])).sum() / 6
    exact = 2 / 3 * np.pi * R**3 + np.pi * R**2 * H
    assert vol > 0 and abs(vol / exact - 1) < 3e-3
    # every edge shared by exactly two triangles, in opposite directions (closed, oriented)
    edges = np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]])
    fwd = {tuple(e) for e in edges}
    assert len(fwd) == len(edges) and all((b, a) in fwd for a, b in fwd)
    # lowest point is the cap's pole at the origin
    assert np.isclose(v[:, 2].min(), 0.0) and np.isclose(v[:, 2].max(), R + H)


def test_tube_has_the_filament_radius_and_follows_the_beads():
    s = np.linspace(0, 4 * np.pi, 40)
    x = np.column_stack([0.03 * np.cos(s), 0.03 * np.sin(s), -0.01 * s])
    c = resample_centerline(x, 3)
    assert len(c) == 3 * (len(x) - 1) + 1
    np.testing.assert_allclose(c[::3], x, atol=1e-12)  # the spline passes through the beads
    quads, qn, caps, cn = tube_faces(x, 0.0015, sides=10, subdivide=3)
    assert quads.shape == ((len(c) - 1) * 10, 4, 3)
    # each quad vertex lies at distance a from the resampled centreline
    d = np.linalg.norm(quads[:, :, None, :] - c[None, None, :, :], axis=-1).min(axis=-1)
    np.testing.assert_allclose(d, 0.0015, rtol=0.05)
    np.testing.assert_allclose(np.linalg.norm(qn, axis=1), 1.0)


def test_cameras_are_the_experiments_orthogonal_horizontal_views():
    c1, c2 = CAMERAS
    for cam in CAMERAS:
        assert np.asarray(cam.toward)[2] == 0 and np.dot(cam.toward, cam.right) == 0
    assert np.dot(c1.toward, c2.toward) == 0
    # a point on +y appears to the right in C1 and straight ahead (depth) in C2
    u1, v1, d1 = c1.project(np.array([0.0, 1.0, 2.0]))
    u2, v2, d2 = c2.project(np.array([0.0, 1.0, 2.0]))
    assert (u1, v1, d1) == (1.0, 2.0, 0.0) and (u2, v2, d2) == (0.0, 2.0, 1.0)


def test_painter_order_puts_the_near_tube_in_front_of_the_body():
    scene = Scene(tube_radius=0.0015, body_radius=0.05, body_length=0.25, length=0.4)
    rend = Renderer(scene)
    # a straight vertical filament in front of the body (toward camera C1) and one behind it
    z = np.linspace(0.05, 0.2, 11)
    front = np.column_stack([np.full(11, 0.06), np.zeros(11), z])
    polys, rgba = rend.polygons(front, CAMERAS[0])
    opaque = rgba[:, 3] == 1.0
    assert opaque[-1] and not opaque[0]  # drawn last: tube; first: body
    behind = front * [-1, 1, 1]
    polys, rgba = rend.polygons(behind, CAMERAS[0])
    assert rgba[-1, 3] < 1.0  # translucent body drawn over the tube behind it


def test_view_limits_cover_all_frames_with_one_scale():
    scene = Scene(0.0015, 0.05, 0.25, 0.4)
    frames = np.zeros((2, 3, 3))
    frames[1, 2] = [0.2, -0.1, -0.3]
    (u0, u1), (z0, z1) = view_limits(frames, scene)
    assert u0 < -0.2 and u1 > 0.2 and np.isclose(u0, -u1)  # centred on the body axis
    assert z0 < -0.3 and z1 >= 0.1
    # a filament that climbs above a short body's top is framed whole (it was cut at the top)
    short = Scene(0.0015, 0.05, 0.05, 0.4)
    frames[1, 2] = [0.0, 0.0, 0.3]
    assert view_limits(frames, short)[1][1] > 0.3
    frames[1, 2] = [0.0, 0.0, -0.3]  # hanging below: the body is still shown to its top
    assert 0.1 <= view_limits(frames, short)[1][1] < 0.15
    # a long body is never cropped at the top (a strip cut the cell off mid-cylinder)
    long = Scene(0.0015, 0.05, 0.6, 0.4)
    assert view_limits(frames, long)[1][1] >= 0.05 + 0.6


def test_scale_bar_is_a_labelled_bar_in_metres_and_L():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from flagwrap.plotting.render import nice_scale_bar, scale_label, style_view

    assert scale_label(0.02, 0.4) == "2 cm = 0.05 L" and scale_label(1e-6, 8e-6) == "1 um = 0.125 L"
    assert scale_label(5e-3) == "5 mm"
    assert nice_scale_bar(0.13) == 0.02 and nice_scale_bar(0.13, fraction=0.4) == 0.05
    fig, ax = plt.subplots()
    style_view(ax, (-0.1, 0.1), (-0.5, 0.2), scale_bar=0.05, length=0.4)
    bar = max(ax.lines, key=lambda l: abs(np.ptp(l.get_xdata())))
    assert np.ptp(bar.get_xdata()) == pytest.approx(0.05) and np.ptp(bar.get_ydata()) == 0
    assert len(ax.lines) == 3  # the bar and its two end ticks
    assert [t.get_text() for t in ax.texts] == ["5 cm = 0.125 L"]
    plt.close(fig)


def test_snapshot_strip_headless(tiny_run, tmp_path):
    out = tmp_path / "strip.png"
    rc = main(["snapshots", str(tiny_run), "-o", str(out), "-n", "3", "--dpi", "80"])
    assert rc == 0
    png, pdf = out, out.with_suffix(".pdf")
    assert png.stat().st_size > 5000 and pdf.stat().st_size > 5000
    import imageio.v2 as iio

    img = iio.imread(png)
    assert img.ndim == 3 and img.shape[0] > 100
    assert (img[..., :3].std(axis=(0, 1)) > 1).all()  # not a blank image


def test_snapshot_strip_shows_the_whole_body_and_one_scale_bar(tiny_run):
    import matplotlib.pyplot as plt

    from flagwrap.plotting.render import scene_of
    from flagwrap.plotting.snapshots import snapshot_figure

    ds = read_run(tiny_run)
    scene = scene_of(ds)
    fig = snapshot_figure(ds, n=3)
    axes = np.array(fig.axes).reshape(2, 3)
    for ax in axes.flat:  # the body's top inside every panel
        assert ax.get_ylim()[1] >= scene.body_radius + scene.body_length
    labelled = [(r, c) for r in range(2) for c in range(3) if axes[r, c].texts]
    assert labelled == [(1, 0)]  # bottom left, under the strip, not between the rows
    assert axes[1, 0].texts[0].get_text().endswith(" L")
    plt.close(fig)


def test_default_snapshot_times_span_the_cw_phase(tiny_run):
    from flagwrap.plotting.snapshots import cw_phase, default_times

    ds = read_run(tiny_run)
    lo, hi = cw_phase(ds)
    assert lo == pytest.approx(0.2) and hi == pytest.approx(0.4)
    np.testing.assert_allclose(default_times(ds, 5), np.linspace(0.2, 0.4, 5))


def test_snapshot_time_outside_run_is_a_user_error(tiny_run, tmp_path):
    rc = main(["snapshots", str(tiny_run), "-o", str(tmp_path / "s.png"), "-t", "5"])
    assert rc == 2
    assert main(["snapshots", str(tmp_path / "missing.nc")]) == 2


def test_summary_figure_marks_the_switch_at_its_time(tiny_run):
    # the frame at the switch carries the old phase's speed: the line belongs at its time
    # (find_switch's t_s), not one save interval later
    from flagwrap.analysis.buckling import find_switch
    from flagwrap.io.runfile import read_run
    from flagwrap.plotting.summary import _switch_turns

    ds = read_run(tiny_run)
    t = ds["turns"].values
    i = find_switch(t, ds["omega"].values)
    assert _switch_turns(ds) == [pytest.approx(t[i - 1])]


def test_summary_figure_names_the_phases_the_criterion_and_the_verdict(tiny_run, tmp_path):
    # issue 34, item 9: each phase named by its motor's sense, the dashed zero line and the
    # rise criterion in a legend, the verdict in the title (that of `flagwrap analyze`)
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from flagwrap.analysis.runfile_attrs import analyze_dataset
    from flagwrap.io.runfile import read_run
    from flagwrap.plotting import summary

    ds = read_run(tiny_run)
    captured = {}
    real_close = plt.close
    plt.close = lambda fig: captured.setdefault("fig", fig)
    try:
        summary.summary_figure(ds, tmp_path / "s.png")
    finally:
        plt.close = real_close
    a1 = captured["fig"].axes[0]
    texts = [t.get_text() for t in a1.texts]
    assert texts == ["CCW", "CW"]
    labels = [t.get_text() for t in a1.get_legend().get_texts()]
    assert "free end level with the clamp" in labels and any("rise criterion" in x for x in labels)
    state = analyze_dataset(ds).summary()["state"]
    assert a1.get_title().endswith(f"final state: {state}")
