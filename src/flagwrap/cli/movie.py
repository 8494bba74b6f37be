"""Render a movie of a run: two camera views, clock, motor direction, live tip height and torque.

Frame k shows t_k = t_0 + k * speed / fps; n_frames = floor((t_end - t_0) fps / speed) + 1.
``--speed auto`` (default) gives one movie frame per saved frame. MP4 via imageio-ffmpeg, GIF
if ffmpeg is missing or the output ends in .gif.

Examples::

    flagwrap movie out/fig4a.nc -o fig4a.mp4 --speed 100x --fps 25
"""

from __future__ import annotations

#: limits of the options (a movie frame takes ~0.2 s to render)
MAX_FPS = 240.0
MAX_FRAMES = 100_000


def add_arguments(p):
    p.add_argument("run_file", help="run file (.nc) written by `flagwrap run`")
    p.add_argument("-o", "--output", help="movie file (.mp4 or .gif); default RUN.mp4 beside the run")
    p.add_argument("--fps", type=float, default=25.0, help="frames per second (25)")
    p.add_argument("--speed", default="auto",
                   help="replay speed, physical seconds per movie second, e.g. 100x (default auto: "
                        "one frame per saved frame)")
    p.add_argument("--size", default="1024x576", help="frame size WxH in pixels, multiples of 16")
    p.add_argument("--quiet", action="store_true", help="no progress bar")


def run(args) -> int:
    from pathlib import Path

    from flagwrap.io.runfile import read_run
    from flagwrap.plotting.movies import (movie_times, parse_size, parse_speed,
                                          write_movie)

    import math

    from flagwrap.errors import UserInputError
    from flagwrap.io.outputs import check_output_file

    out = Path(args.output) if args.output else Path(args.run_file).with_suffix(".mp4")
    if out.suffix == "":
        out = out.with_suffix(".mp4")
    check_output_file(out, "movie (-o)", suffixes={".mp4", ".gif"})
    if not (math.isfinite(args.fps) and 0 < args.fps <= MAX_FPS):
        raise UserInputError(f"--fps must be in (0, {MAX_FPS}], got {args.fps}")
    speed = parse_speed(args.speed)
    size = parse_size(args.size)
    ds = read_run(args.run_file)
    n = len(movie_times(ds["time"].values, args.fps, speed))
    if n > MAX_FRAMES:
        raise UserInputError(f"the movie would have {n} frames (more than {MAX_FRAMES}, ~{n / 5 / 3600:.2g} "
                             f"h of rendering): raise --speed or lower --fps")
    bar = None
    if not args.quiet:
        from tqdm import tqdm

        bar = tqdm(total=n, unit="frame", desc=f"movie {out.name}")

    def progress(k, total):
        if bar is not None:
            bar.update(1)

    import time

    start = time.perf_counter()
    try:
        path = write_movie(ds, out, fps=args.fps, speed=speed, size=size, progress=progress)
    finally:
        if bar is not None:
            bar.close()
    if path.suffix != out.suffix:
        print(f"ffmpeg unavailable: wrote a GIF instead of {out.suffix}")
    took = time.perf_counter() - start
    print(f"{path}: {n} frames of {size[0]}x{size[1]} at {args.fps:g} fps, rendered and encoded "
          f"in {took:.1f} s ({took / max(n, 1):.3f} s per frame)")
    return 0
