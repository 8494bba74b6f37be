"""Movies: deterministic frame count (formula), size, MP4 and GIF read back with imageio."""

import numpy as np
import pytest

from flagwrap.io.runfile import read_run



def test_movie_frame_count_formula():
    from flagwrap.plotting.movies import movie_times

    t = np.linspace(0.0, 10.0, 21)  # saved every 0.5 s
    # n = floor((t_end - t0) fps / speed) + 1
    assert len(movie_times(t, fps=25, speed=2.0)) == 126
    assert len(movie_times(t, fps=10, speed=3.0)) == 34  # floor(33.33) + 1
    assert len(movie_times(t, fps=10, speed=None)) == 21  # auto: one frame per save
    tm = movie_times(t, fps=10, speed=3.0)
    np.testing.assert_allclose(np.diff(tm), 0.3)
    assert tm[-1] <= t[-1]


def test_speed_and_size_parsing():
    from flagwrap.errors import UserInputError
    from flagwrap.plotting.movies import parse_size, parse_speed

    assert parse_speed("100x") == 100 and parse_speed("2.5") == 2.5 and parse_speed("auto") is None
    assert parse_size("1024x576") == (1024, 576) and parse_size((160, 96)) == (160, 96)
    for bad, near in (("1000x570", "992x576"), ("13x7", "160x96"), ("100000x100000", "7680x4320")):
        with pytest.raises(UserInputError, match=f"nearest allowed: {near}"):  # never resized silently
            parse_size(bad)
    for bad in ("fast", "-3x", "0x"):
        with pytest.raises(UserInputError):
            parse_speed(bad)


def test_mp4_has_expected_frame_count_and_size(tiny_run, tmp_path):
    import imageio.v2 as iio

    from flagwrap.cli.main import main
    from flagwrap.plotting.movies import movie_times

    ds = read_run(tiny_run)
    T = float(ds.attrs["period"])
    speed = 0.1 * T  # 0.1 turn per movie second
    fps = 20
    n = len(movie_times(ds["time"].values, fps, speed))
    assert n == int(np.floor(0.4 / 0.1 * fps + 1e-9)) + 1  # 0.4 turns long
    out = tmp_path / "tiny.mp4"
    rc = main(["movie", str(tiny_run), "-o", str(out), "--fps", str(fps), "--speed",
               f"{speed!r}x", "--size", "320x192", "--quiet"])
    assert rc == 0 and out.exists()
    r = iio.get_reader(out)
    assert r.count_frames() == n
    assert r.get_meta_data()["size"] == (320, 192)
    frame = r.get_data(n // 2)
    assert frame.shape == (192, 320, 3) and frame.std() > 1
    r.close()


def test_gif_fallback(tiny_run, tmp_path):
    import imageio.v2 as iio

    from flagwrap.plotting.movies import write_movie

    ds = read_run(tiny_run)
    p = write_movie(ds, tmp_path / "tiny.gif", fps=10, size=(160, 96))
    assert p.suffix == ".gif"
    frames = list(iio.get_reader(p))
    assert len(frames) == ds.sizes["time"] and frames[0].shape[:2] == (96, 160)


def test_movie_of_missing_file_is_a_user_error(tmp_path):
    from flagwrap.cli.main import main

    assert main(["movie", str(tmp_path / "none.nc"), "--quiet"]) == 2


def test_bad_movie_and_snapshot_outputs_are_one_line_errors(tiny_run, tmp_path, capsys):
    from flagwrap.cli.main import main

    assert main(["movie", str(tiny_run), "-o", str(tmp_path / "m.png")]) == 2
    assert "unknown suffix '.png'; allowed: .gif, .mp4" in capsys.readouterr().err
    assert main(["snapshots", str(tiny_run), "-o", str(tmp_path / "s.png"), "--formats", "xyz"]) == 2
    assert "--formats: xyz not supported" in capsys.readouterr().err
    assert main(["snapshots", str(tiny_run), "-o", str(tmp_path / "s.png"), "--dpi", "0"]) == 2
    assert "--dpi must be in [1, 1200]" in capsys.readouterr().err
