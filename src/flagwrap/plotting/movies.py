"""Movies of a run: both camera views side by side, clock, motor direction and live traces.

Like the paper's SI movies, a movie replays the run at a chosen speed: ``speed = 100`` ("100x")
shows 100 s of physical time per second of movie. Frame ``k`` shows the physical time

    t_k = t_0 + k * speed / fps,        k = 0, 1, ..., n_frames - 1,
    n_frames = floor((t_end - t_0) * fps / speed + 1e-9) + 1,

with ``t_0``, ``t_end`` the first and last saved times of the run [s]; positions and traces
are interpolated linearly in time between saved frames (the motor direction is that of the
nearest earlier saved frame). The default ``speed = "auto"`` is ``save interval * fps``: one
movie frame per saved frame. The frame count is thus a pure function of the run's duration,
the replay speed and the frame rate (:func:`movie_times`), and the movie is deterministic.

Encoding: H.264 MP4 (yuv420p) through ``imageio-ffmpeg``; if ffmpeg is unavailable, or the
output name ends in ``.gif``, an animated GIF (Pillow) is written instead. Frame sizes are
rounded to multiples of 16 pixels (the H.264 macroblock) so that no encoder rescales them.
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np

from flagwrap.errors import UserInputError

DEFAULT_SIZE = (1024, 576)


def parse_speed(text) -> float | None:
    """Replay speed from ``"100x"``, ``"100"`` or a number; ``"auto"``/``None`` -> ``None``."""
    if text is None:
        return None
    if isinstance(text, (int, float)):
        val = float(text)
    else:
        s = str(text).strip().lower()
        if s == "auto":
            return None
        m = re.fullmatch(r"([0-9]*\.?[0-9]+(?:e[+-]?[0-9]+)?)\s*x?", s)
        if not m:
            raise UserInputError(f"replay speed must look like '100x' or 'auto', got {text!r}")
        val = float(m.group(1))
    if not (val > 0 and math.isfinite(val)):
        raise UserInputError(f"replay speed must be positive, got {text!r}")
    return val


#: frame size limits [pixel]: the layout needs 160 x 96; 7680 x 4320 (8K) bounds the memory
#: of one RGB frame (~100 MB) and of the encoder
MIN_SIZE, MAX_SIZE = (160, 96), (7680, 4320)


def parse_size(text) -> tuple[int, int]:
    """``"WxH"`` in pixels: multiples of 16 (the H.264 macro block) within
    :data:`MIN_SIZE` .. :data:`MAX_SIZE`; anything else is an error naming the nearest
    allowed size (nothing is resized silently)."""
    if isinstance(text, (tuple, list)) and len(text) == 2:
        w, h = text
    else:
        m = re.fullmatch(r"\s*(\d+)\s*[xX]\s*(\d+)\s*", str(text))
        if not m:
            raise UserInputError(f"size must look like 1024x576, got {text!r}")
        w, h = int(m.group(1)), int(m.group(2))
    w, h = int(w), int(h)
    ok = [MIN_SIZE[i] <= v <= MAX_SIZE[i] and v % 16 == 0 for i, v in enumerate((w, h))]
    if not all(ok):
        near = [min(MAX_SIZE[i], max(MIN_SIZE[i], 16 * round(v / 16))) for i, v in enumerate((w, h))]
        raise UserInputError(f"size {w}x{h}: width and height must be multiples of 16 within "
                             f"{MIN_SIZE[0]}x{MIN_SIZE[1]} .. {MAX_SIZE[0]}x{MAX_SIZE[1]}; nearest "
                             f"allowed: {near[0]}x{near[1]}")
    return w, h


def movie_times(time: np.ndarray, fps: float, speed: float | None = None) -> np.ndarray:
    """Physical times [s] of the movie frames (see the module docstring for the formula).

    Parameters
    ----------
    time : (F,) saved times of the run [s], increasing
    fps : frames per second of the movie [1/s]
    speed : replay speed (physical seconds per movie second); ``None`` = one frame per saved
        frame (``speed = median save interval * fps``)
    """
    time = np.asarray(time, float)
    if not fps > 0:
        raise UserInputError(f"fps must be positive, got {fps}")
    if len(time) < 2:
        return time[:1].copy()
    if speed is None:
        speed = float(np.median(np.diff(time))) * fps
    n = int(math.floor((time[-1] - time[0]) * fps / speed + 1e-9)) + 1
    return time[0] + np.arange(n) * (speed / fps)


def _interp_frames(time, X, tq):
    """Positions (..., N, 3) linearly interpolated at times ``tq`` [s]."""
    i = np.clip(np.searchsorted(time, tq, side="right") - 1, 0, len(time) - 2)
    w = np.clip((tq - time[i]) / (time[i + 1] - time[i]), 0.0, 1.0)
    w = w.reshape((-1,) + (1,) * (X.ndim - 1))
    return (1 - w) * X[i] + w * X[i + 1], i


class MovieFrames:
    """Renders the frames of a movie of one run (an iterator of RGB arrays).

    Parameters
    ----------
    ds : run dataset
    fps : frames per second [1/s]
    speed : replay speed (physical seconds per movie second), ``None`` = one frame per save
    size : (width, height) [pixel], multiples of 16
    renderer_kwargs : passed to :class:`flagwrap.plotting.render.Renderer`

    Attributes
    ----------
    times : (n_frames,) physical times [s]; turns : the same as t/T
    """

    def __init__(self, ds, fps: float = 25.0, speed: float | None = None,
                 size=DEFAULT_SIZE, renderer_kwargs: dict | None = None):
        from flagwrap.plotting.render import Renderer, body_poses, scene_of, view_limits

        self.ds = ds
        self.fps = float(fps)
        self.size = parse_size(size)
        self.time = ds["time"].values
        self.times = movie_times(self.time, self.fps, speed)
        self.turns = np.interp(self.times, self.time, ds["turns"].values)
        self.X = ds["position"].values
        #: a polymorphic filament's order parameter per frame and bead (coloured by form)
        self.order = ds["polymorph_order"].values if "polymorph_order" in ds.variables else None
        self.scene = scene_of(ds)
        self.renderer = Renderer(self.scene, **(renderer_kwargs or {}))
        self.poses = body_poses(ds)  # a free swimmer's body, drawn where it is
        self.ulim, self.zlim = view_limits(self.X, self.scene, poses=self.poses)
        self._fig = None

    def __len__(self) -> int:
        return len(self.times)

    def _setup(self):
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        from flagwrap.plotting.render import CAMERAS, nice_scale_bar, style_view

        ds = self.ds
        w, h = self.size
        dpi = 100
        fig = plt.figure(figsize=(w / dpi, h / dpi), dpi=dpi)
        fig.patch.set_facecolor("white")
        # two camera views on the left ~2/3, traces on the right
        self.ax_views = [fig.add_axes((0.01, 0.02, 0.31, 0.88)), fig.add_axes((0.33, 0.02, 0.31, 0.88))]
        bar = nice_scale_bar(self.ulim[1] - self.ulim[0])
        from flagwrap.io.runfile import config_of
        from flagwrap.plotting.render import draw_boundary

        cfg = config_of(ds)
        for k, (ax, cam) in enumerate(zip(self.ax_views, CAMERAS)):
            draw_boundary(ax, cfg, cam)  # still: drawn once, behind the frames
            style_view(ax, self.ulim, self.zlim, title=cam.name, scale_bar=bar if k == 0 else None,
                       length=self.scene.length)
        turns = ds["turns"].values
        L = ds.attrs["length"]
        from flagwrap.io.runfile import filament_slices
        from flagwrap.observables.tip import free_end_heights

        zt = free_end_heights(self.X, L, filament_slices(ds))  # (T, flagella)
        tq = ds["motor_torque_reduced"].values
        self.ax_z = fig.add_axes((0.72, 0.52, 0.26, 0.24))
        self.ax_t = fig.add_axes((0.72, 0.12, 0.26, 0.24), sharex=self.ax_z)
        self._cursor = []
        self._dots = []
        self._series = []
        many = zt.shape[1] > 1  # one height line per flagellum, in its tube's colour
        for ax, ys, cols, lab in (
                (self.ax_z, zt.T, [f"C{k}" if many else "C0" for k in range(zt.shape[1])],
                 r"$[z(L)-z(0)]/L$"),
                (self.ax_t, [tq], ["C3"], r"$N_m R/A$" + (" (all)" if many else ""))):
            for y, col in zip(ys, cols):
                ax.plot(turns, y, color=col, lw=0.6, alpha=0.3)
                (live,) = ax.plot([], [], color=col, lw=1.2)
                (dot,) = ax.plot([], [], "o", color=col, ms=4)
                self._series.append((live, y))
                self._dots.append(dot)
            self._cursor.append(ax.axvline(turns[0], color="0.4", lw=0.6))
            ax.set_ylabel(lab, fontsize=8)
            ax.tick_params(labelsize=7)
            ax.axhline(0, color="0.7", lw=0.5, ls="--")
        self.ax_z.tick_params(labelbottom=False)
        self.ax_t.set_xlabel(r"$t/T$", fontsize=8)
        self.ax_t.set_xlim(turns[0], turns[-1])
        hi = "with HI" if ds.attrs.get("hydrodynamics", 1) else "without HI"
        fig.text(0.01, 0.965, f"{ds.attrs.get('title', 'flagwrap run')}: "
                 f"M = {float(ds.attrs['machin']):.4g}, {hi}", fontsize=9, va="center")
        self._clock = fig.text(0.72, 0.94, "", fontsize=12, family="monospace", va="center")
        self._motor = fig.text(0.72, 0.87, "", fontsize=11, va="center")
        fig.text(0.72, 0.81, "(seen from the free end)", fontsize=7, color="0.4", va="center")
        self._turns_saved = turns
        self._fig = fig

    def render(self, k: int) -> np.ndarray:
        """RGB image (height, width, 3) uint8 of frame ``k``."""
        from flagwrap.plotting.render import CAMERAS

        if self._fig is None:
            self._setup()
        tq = self.times[k]
        x, i = _interp_frames(self.time, self.X, np.array([tq]))
        x, i = x[0], int(i[0])
        # direction of the nearest earlier saved frame (ties at a switch: the new direction)
        j = min(int(np.searchsorted(self.time, tq, side="right")), len(self.time) - 1)
        om = float(self.ds["omega"].values[max(j, 1) if tq > self.time[0] else 0])
        pose = None
        if self.poses is not None:  # the body's position interpolated as the beads are
            Xb = np.array([np.interp(tq, self.time, self.poses[0][:, c]) for c in range(3)])
            pose = (Xb, self.poses[1][i])
        order = None
        if self.order is not None:  # interpolated in time as the beads are
            order = _interp_frames(self.time, self.order, np.array([tq]))[0][0]
        for ax, cam in zip(self.ax_views, CAMERAS):
            self.renderer.draw(ax, x, cam, pose, order)
        turn = self.turns[k]
        self._clock.set_text(f"t/T = {turn:6.2f}")
        if om < 0:
            self._motor.set_text("motor: CW")
            self._motor.set_color("C3")
        elif om > 0:
            self._motor.set_text("motor: CCW")
            self._motor.set_color("C0")
        else:
            self._motor.set_text("motor: stopped")
            self._motor.set_color("0.3")
        ts = self._turns_saved
        for cur in self._cursor:
            cur.set_xdata([turn, turn])
        for (live, y), dot in zip(self._series, self._dots):
            upto = ts <= turn
            yi = float(np.interp(turn, ts, y))
            live.set_data(np.append(ts[upto], turn), np.append(y[upto], yi))
            dot.set_data([turn], [yi])
        canvas = self._fig.canvas
        canvas.draw()
        img = np.asarray(canvas.buffer_rgba())[..., :3].copy()
        return img

    def __iter__(self):
        for k in range(len(self)):
            yield self.render(k)

    def close(self):
        import matplotlib.pyplot as plt

        if self._fig is not None:
            plt.close(self._fig)
            self._fig = None


def ffmpeg_available() -> bool:
    """Whether imageio-ffmpeg and its ffmpeg binary can be used."""
    try:
        import imageio_ffmpeg

        return Path(imageio_ffmpeg.get_ffmpeg_exe()).exists()
    except Exception:
        return False


def write_movie(ds, path, fps: float = 25.0, speed=None, size=DEFAULT_SIZE, progress=None,
                renderer_kwargs: dict | None = None) -> Path:
    """Render a run to an MP4 (or GIF) file; returns the path written.

    Parameters
    ----------
    ds : run dataset
    path : output file: ``.mp4`` (``.gif`` in its place when ffmpeg is unavailable) or
        ``.gif``; a name without a suffix gets ``.mp4``; any other suffix is an error
    fps : frames per second [1/s]
    speed : replay speed: number, ``"100x"``, or ``None``/``"auto"`` (one frame per save)
    size : ``"WxH"`` or (W, H) [pixel], rounded to multiples of 16
    progress : optional callable ``progress(k, n)`` after each frame (the CLI's bar)
    """
    import imageio.v2 as iio

    from flagwrap.errors import UserInputError

    path = Path(path)
    if path.suffix == "":
        path = path.with_suffix(".mp4")
    if path.suffix.lower() not in (".mp4", ".gif"):
        raise UserInputError(f"movie file must end in .mp4 or .gif, got {str(path)!r}")
    frames = MovieFrames(ds, fps=fps, speed=parse_speed(speed), size=size,
                         renderer_kwargs=renderer_kwargs)
    path.parent.mkdir(parents=True, exist_ok=True)
    gif = path.suffix.lower() == ".gif" or not ffmpeg_available()
    if gif:
        path = path.with_suffix(".gif")
    # rendered into a temporary file beside the target and renamed in when complete: an
    # interrupted or failed movie never replaces an existing one
    import os
    import tempfile

    fd, tmp = tempfile.mkstemp(prefix=f".{path.stem}.", suffix=path.suffix, dir=path.parent)
    os.close(fd)
    final, path = path, Path(tmp)
    if gif:
        writer = iio.get_writer(path, mode="I", duration=1000.0 / fps, loop=0)
    else:
        writer = iio.get_writer(path, format="FFMPEG", mode="I", fps=fps, codec="libx264",
                                pixelformat="yuv420p", quality=7, macro_block_size=16,
                                ffmpeg_log_level="error")
    n = len(frames)
    done = False
    try:
        for k in range(n):
            writer.append_data(frames.render(k))
            if progress is not None:
                progress(k + 1, n)
        done = True
    finally:
        writer.close()
        frames.close()
        if done:
            from flagwrap.io.atomic import _UMASK

            os.chmod(path, 0o666 & ~_UMASK)  # mkstemp made it 0600
            os.replace(path, final)
        elif path.exists():
            path.unlink()
    return final
