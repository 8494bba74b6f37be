"""The Python counterpart of the ``flagwrap`` command line: one function per subcommand.

Each function takes what its command takes (a config as a TOML path, a built-in case name or
a :class:`~flagwrap.params.Config`), does the same checks before any work (bad input is a
:class:`~flagwrap.errors.UserInputError` naming the parameter), and returns the numbers the
command prints::

    import flagwrap

    res = flagwrap.run("fig4a", output="out/fig4a.nc")       # RunResult
    print(res.status, res.machin, res.gravity_number)
    flagwrap.analyze("out/fig4a.nc")["state"]                 # "stable"
    c = flagwrap.critical("examples/fig4a.toml", rtol=0.1)    # CriticalResult
    print(c.machin_c, c.bracket, c.omega_c)
    s = flagwrap.stability("examples/fig4a.toml")             # StabilityResult (seconds)
    print(s.machin_c, s.crossing, s.mode_frequency)
    flagwrap.sweep("examples/sweeps/fig5-quick.toml")         # SweepReport
    flagwrap.figure("fig5")                                   # [paths]
    flagwrap.bacteria()                                       # [dict per species]

Everything is also importable from ``flagwrap`` itself (``flagwrap.run`` etc.), loaded on
first use so that ``import flagwrap`` stays light.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from pathlib import Path


def load(config):
    """A :class:`~flagwrap.params.Config` from a Config, a built-in case name (``"fig4a"``,
    :data:`flagwrap.cases.CASES`) or a TOML path."""
    from flagwrap.cases import CASES
    from flagwrap.errors import UserInputError
    from flagwrap.io.config import load_config_or_case
    from flagwrap.params import Config

    if isinstance(config, Config):
        return config
    if isinstance(config, (str, Path)):  # a file of that name, else the case (as the CLI)
        return load_config_or_case(config)
    raise UserInputError(f"config must be a Config, a case name ({', '.join(CASES)}) or a TOML "
                         f"path, got {type(config).__name__}")


def _with_numerics(cfg, hydrodynamics=None, integrator=None):
    num = cfg.numerics
    if hydrodynamics is not None:
        num = dataclasses.replace(num, hydrodynamics=bool(hydrodynamics))
    if integrator is not None:
        num = dataclasses.replace(num, integrator=integrator)
    return cfg.replace(numerics=num)


@dataclass
class RunResult:
    """What ``flagwrap run`` reports: the trajectory (core units), the file written (or None),
    status, step counts and the dimensionless numbers."""

    trajectory: object
    path: Path | None
    status: str
    message: str
    n_steps: int
    n_rejected: int
    wall_time: float
    machin: float
    reynolds: float
    gravity_number: float

    @property
    def ok(self) -> bool:
        return self.status == "completed"


def run(config, output=None, figure=None, hydrodynamics=None, integrator=None,
        progress: bool = False, precise: bool = False) -> RunResult:
    """``flagwrap run``: simulate ``config``'s protocol; write the run file to ``output`` (and
    a summary figure to ``figure``) if given. The same output checks and lock as the command.
    ``precise``: ``--precise`` (``numerics.tol`` at most 1e-6, for quoting mean rates)."""
    import dataclasses

    from flagwrap.cli.run import PRECISE_TOL
    from flagwrap.io.outputs import check_output_file, output_lock, write_or_rescue
    from flagwrap.io.runfile import write_run
    from flagwrap.resources import check_disk, check_memory
    from flagwrap.simulation import simulate

    cfg = _with_numerics(load(config), hydrodynamics, integrator)
    if precise and cfg.numerics.tol > PRECISE_TOL:
        cfg = cfg.replace(numerics=dataclasses.replace(cfg.numerics, tol=PRECISE_TOL))
    check_memory(cfg)
    out = None
    if output is not None:
        out = check_output_file(output, "output")
        check_disk(cfg, out, checkpoint=False)
    if figure is not None:
        from flagwrap.plotting.summary import figure_suffixes

        check_output_file(figure, "figure", suffixes=figure_suffixes())
    with output_lock(out):
        traj = simulate(cfg, progress=progress)
        if out is not None:
            write_or_rescue(lambda p: write_run(traj, p), out, "run file")
    if figure is not None and out is not None:
        from flagwrap.io.runfile import read_run
        from flagwrap.plotting.summary import summary_figure

        summary_figure(read_run(out), figure)
    return RunResult(traj, out, traj.status, traj.message, traj.n_steps, traj.n_rejected,
                     traj.wall_time, cfg.machin, cfg.reynolds, cfg.gravity_number)


def analyze(run_file, write: bool = True, **criteria) -> dict:
    """``flagwrap analyze``: buckling, waiting time and final state of one run file (dict of
    the printed fields); ``criteria``: the options of :class:`~flagwrap.analysis.buckling.WaitingTime`
    (threshold, hold_turns, smooth_turns, onset) and :class:`~flagwrap.analysis.buckling.FinalState`
    (min_winding_turns, min_contact_fraction, contact_distance, final_turns)."""
    from flagwrap.analysis.buckling import BucklingAnalysis, FinalState, WaitingTime
    from flagwrap.analysis.runfile_attrs import analyze_run_file

    wt_keys = {"threshold", "hold_turns", "smooth_turns", "onset"}
    fs_keys = {"min_winding_turns", "min_contact_fraction", "contact_distance", "final_turns"}
    unknown = set(criteria) - wt_keys - fs_keys
    if unknown:
        from flagwrap.errors import UserInputError

        raise UserInputError(f"analyze: unknown criteria {', '.join(sorted(unknown))}; allowed: "
                             f"{', '.join(sorted(wt_keys | fs_keys))}")
    analysis = BucklingAnalysis(WaitingTime(**{k: v for k, v in criteria.items() if k in wt_keys}),
                                FinalState(**{k: v for k, v in criteria.items() if k in fs_keys}))
    return analyze_run_file(run_file, analysis, write=write)


@dataclass
class CriticalResult:
    """What ``flagwrap critical`` reports (``summary`` holds every field, runs included)."""

    machin_c: float
    bracket: tuple
    converged: bool
    relative_uncertainty: float
    omega_c: float
    frequency_c: float
    gravity_number: float
    monotone: bool
    runs: list = field(default_factory=list)
    summary: dict = field(default_factory=dict)


def critical(config, rtol: float = 0.05, cw_turns: float = 10.0, ccw_turns: float = 5.0,
             cache="out/critical", guess=None, bracket=None, factor: float = 2.0,
             max_runs: int = 16, hydrodynamics=None, on_run=None) -> CriticalResult:
    """``flagwrap critical``: M_c by bracketing and bisection (cached test runs); the option
    ranges are those of the command."""
    from flagwrap.analysis.critical import CriticalSearch, RunCache, check_search_options
    from flagwrap.io.outputs import check_output_dir

    check_search_options(rtol, cw_turns, ccw_turns, factor, max_runs, guess, bracket)
    check_output_dir(cache, "cache")
    cfg = _with_numerics(load(config), hydrodynamics)
    search = CriticalSearch(rtol=rtol, cw_turns=cw_turns, ccw_turns=ccw_turns, factor=factor,
                            max_runs=max_runs, cache=RunCache(cache), on_run=on_run)
    search.compute(cfg, guess=guess, bracket=bracket)
    s = search.summary()
    return CriticalResult(s["machin_c"], tuple(s["bracket"]), s["converged"],
                          s["relative_uncertainty"], s["omega_c"], s["frequency_c"],
                          s["gravity_number"], s["monotone"], s["runs"], s)


def stability(config, direction: str = "cw", m_start: float = 10.0, m_max=None,
              rtol: float = 1e-3, factor: float = 1.25, hydrodynamics=None, on_point=None):
    """``flagwrap stability``: M_c from the linear stability of the steady whirl
    (:class:`flagwrap.stability.threshold.StabilityResult`: ``machin_c``, ``bracket``,
    ``crossing``, ``eigenvalue``, ``mode_frequency``, ``omega_c``, ``branch``, ``summary()``);
    the option ranges are those of the command."""
    from flagwrap.errors import UserInputError
    from flagwrap.stability.threshold import (DIRECTIONS, check_continuation_options,
                                              critical_from_config)

    if direction not in DIRECTIONS:
        raise UserInputError(f"direction must be 'cw' or 'ccw', got {direction!r}")
    check_continuation_options(m_start, m_max, rtol, factor)
    cfg = _with_numerics(load(config), hydrodynamics)
    return critical_from_config(cfg, direction, m_start=m_start, m_max=m_max, factor=factor,
                                rtol=rtol, on_point=on_point)


def sweep(spec, out="out/sweeps", scheduler: str = "local", workers=None,
          retry_failed: bool = False, progress: bool = False):
    """``flagwrap sweep``: run a sweep file (path) or a parsed
    :class:`~flagwrap.sweep.spec.SweepSpec`; returns the
    :class:`~flagwrap.sweep.runner.SweepReport` (counts, wall time, table path, errors)."""
    from flagwrap.io.outputs import check_output_dir
    from flagwrap.sweep.runner import run_sweep
    from flagwrap.sweep.spec import SweepSpec, load_spec

    spec = spec if isinstance(spec, SweepSpec) else load_spec(spec)
    root = check_output_dir(Path(out) / spec.name, "sweep folder")
    return run_sweep(spec, root, scheduler=scheduler, n_workers=workers,
                     retry_failed=retry_failed, progress=progress)


def figure(name: str, outdir="out/figures") -> list:
    """``flagwrap figure NAME``: draw a figure; returns the paths written."""
    from flagwrap.cli.figure import FIGURES
    from flagwrap.errors import UserInputError
    from flagwrap.io.outputs import check_output_dir

    if name not in FIGURES:
        raise UserInputError(f"unknown figure {name!r}; available: {', '.join(sorted(FIGURES))}")
    check_output_dir(outdir, "figure folder")
    return [str(p) for p in FIGURES[name](outdir)]


def bacteria(prefactor: float = 0.06, files=(), only_files: bool = False) -> list:
    """``flagwrap bacteria``: the species on the stability diagram, one dict per species
    (``M``, ``(R/L)^3``, ``M_c`` and ``M/M_c`` for ``M_c = prefactor (R/L)^-3``, side)."""
    from flagwrap.bacteria.species import default_species, load_species_file
    from flagwrap.errors import check_positive

    check_positive("prefactor", prefactor)
    species = [] if only_files else default_species()
    for f in files:
        species += load_species_file(f)
    return [{"key": s.key, "name": s.name, "form": s.form, "machin": s.machin,
             "r_over_l_cubed": s.radius_over_length_cubed, "machin_c": s.critical_machin(prefactor),
             "instability_ratio": s.instability_ratio(prefactor), "side": s.side(prefactor),
             "paper_side": s.paper_side} for s in species]


__all__ = ["load", "run", "RunResult", "analyze", "critical", "CriticalResult", "stability", "sweep",
           "figure", "bacteria"]
