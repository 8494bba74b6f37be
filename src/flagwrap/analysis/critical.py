"""Critical Machin number ``M_c`` (critical motor speed ``omega_c``) of one geometry.

Paper (main text, Fig. 5 and "Slow dynamics right above the onset of buckling"): a helix
driven CCW for 10 turns and then CW stays in its whirling state below ``omega_c`` and buckles
above it; ``omega_c`` is the boundary in the phase diagram. Since ``M = eta omega L^4 / A`` is
the only dynamical parameter of the model (docs/model.md, Units), the search runs on ``M``
and reports ``omega_c = M_c A / (eta L^4)`` for the config's filament and fluid.

Criterion
---------
A test run is the config with its motor protocol replaced by ``ccw_turns`` CCW turns (default
5: the CCW whirling state of the stored runs settles within ~4 turns, docs/analysis.md) and
``cw_turns = K`` CW turns at the same speed (default 10, the paper's protocol). It counts as
**buckled** when :class:`~flagwrap.analysis.buckling.WaitingTime` (default criteria) detects
the free end coming up within those ``K`` CW turns.

Because ``t_c / T ~ c / eps`` diverges at the threshold, a run at ``eps = (M - M_c)/M_c``
below ``~ c / (K - t_r)`` (``t_r`` ~ 1-2 turns: the rise to the 0.15 L threshold plus the
one-turn hold) is still in its waiting phase when the run ends and is called stable. The
measured ``M_c`` is therefore biased **upward** by about ``c / (K - t_r)``: ~6-8 % for the
paper's ``c = 0.5`` and ``K = 10``; doubling ``K`` halves it. The bias is a property of the
finite protocol, like the paper's own 10 CW turns.

Search
------
1. **Bracket.** Start at ``guess`` (default: the config's ``M``); multiply by ``factor``
   (default 2) while stable, divide while buckled, until one stable and one buckled ``M``
   are known (``bracket`` may be given instead; it is verified by the same runs).
2. **Bisection** in ``log M`` (geometric midpoint) until ``M_hi / M_lo - 1 <= rtol``.
3. **Result**: ``M_c = sqrt(M_lo M_hi)``, the bracket, and every run made (``M``, buckled,
   ``t_c / T``, final class, file, reused or new).

Monotonicity in ``M`` is assumed (one threshold); a non-monotone record (a stable run above
a buckled one) is reported by :attr:`CriticalSearch.monotone`.

Run cache
---------
Each test run is stored as ``<dir>/<key>.nc`` (the run file) and ``<key>.json`` (its analysis
summary), ``key`` = first 16 hex digits of SHA-256 of the test config's TOML text
(:func:`flagwrap.io.config.config_to_toml`) and the package version. A finished run is never
repeated: a rerun of the search, a finer ``rtol`` or another search that needs the same
``M`` reads the JSON instead.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import math
from pathlib import Path

from flagwrap.errors import UserInputError
from flagwrap.io.atomic import atomic_write


@dataclasses.dataclass(frozen=True)
class CriticalRun:
    """One test run of a critical search.

    Attributes
    ----------
    machin : float
        ``M = eta omega L^4 / A`` of the run.
    buckled : bool
        free end came up within the ``K`` CW turns.
    waiting_time : float
        ``t_c / T`` after the switch (nan if stable).
    state : str
        "stable", "folding" or "wrapping" at the end of the run.
    status : str
        the simulator's status ("completed" or "failed").
    key : str
        cache key; the run file is ``<cache>/<key>.nc``.
    reused : bool
        taken from the cache (no simulation made by this search).
    torque_peak : float
        most negative CW motor torque ``N_m R / A`` of the run.
    crossing : float
        ``(t_x - t_s) / T``, the persistent 0.15 L threshold crossing (nan if stable).
    """

    machin: float
    buckled: bool
    waiting_time: float
    state: str
    status: str
    key: str
    reused: bool
    torque_peak: float = float("nan")
    crossing: float = float("nan")


def probe_config(cfg, machin: float, ccw_turns: float = 5.0, cw_turns: float = 10.0):
    """The config of one test run: ``cfg`` at ``M = machin`` with the CCW -> CW test protocol.

    Parameters
    ----------
    cfg : flagwrap.params.Config
        geometry, fluid, numerics (its motor is replaced).
    machin : float
        Machin number ``M`` of the run (the speed of both phases).
    ccw_turns, cw_turns : float
        protocol lengths [turns].
    """
    from flagwrap.params import Motor, Phase

    if not (math.isfinite(machin) and machin > 0):
        raise UserInputError(f"machin must be a finite number > 0, got {machin!r}")
    motor = Motor(machin=float(machin), protocol=(Phase("ccw", float(ccw_turns)), Phase("cw", float(cw_turns))))
    return cfg.replace(motor=motor, name=f"{cfg.name}_M{machin:.4g}")


#: How the test runs are stepped, hashed into every cached result's key: 1, the CW phase in
#: chunks restarted from a re-packed state (step sizes restart at each edge); 2, one run
#: ended by :class:`BuckledStop`. A change of it is a change of the results: they run again.
RUNNER_REVISION = 2


#: the shortest CW phase a test run may have [turns]: the free end needs ~1-2 turns to rise
#: to the threshold near this model's onset (t_c ~ 2 T, docs/critical.md) and must then stay
#: up for the 1-turn hold, so a shorter K calls every slowly buckling run stable
MIN_CW_TURNS = 4.0
#: the most test runs one search may make
MAX_RUNS = 100


def check_search_options(rtol, cw_turns, ccw_turns, factor, max_runs, guess=None,
                         bracket=None, option=str) -> None:
    """The ranges of :class:`CriticalSearch`'s options, before anything runs: one-line
    :class:`UserInputError` s naming the option as ``option(name)`` (the CLI passes its flag
    names, the API keeps the keywords)."""
    def finite(name, v):
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
            raise UserInputError(f"{option(name)} must be a finite number, got {v!r}")

    for name, v in (("rtol", rtol), ("cw_turns", cw_turns), ("ccw_turns", ccw_turns),
                    ("factor", factor)):
        finite(name, v)
    if not 0 < rtol < 1:
        raise UserInputError(f"{option('rtol')} must be in (0, 1), got {rtol}")
    if not MIN_CW_TURNS <= cw_turns <= 1000:
        raise UserInputError(
            f"{option('cw_turns')} must be in [{MIN_CW_TURNS:g}, 1000], got {cw_turns:g}: a test "
            "run needs ~2 turns for the free end to rise plus the 1-turn hold of the buckling "
            "criterion, so a shorter K calls slowly buckling runs stable")
    if not 0.5 <= ccw_turns <= 1000:
        raise UserInputError(f"{option('ccw_turns')} must be in [0.5, 1000], got {ccw_turns:g}")
    if not 1.01 <= factor <= 100:
        raise UserInputError(f"{option('factor')} must be in [1.01, 100], got {factor:g}")
    if isinstance(max_runs, bool) or not isinstance(max_runs, int) or not 1 <= max_runs <= MAX_RUNS:
        raise UserInputError(f"{option('max_runs')} must be an integer in [1, {MAX_RUNS}], got "
                             f"{max_runs!r}")
    if guess is not None:
        finite("guess", guess)
        if not guess > 0:
            raise UserInputError(f"{option('guess')} must be a Machin number > 0, got {guess:g}")
    if bracket is not None:
        lo, hi = bracket
        finite("bracket", lo)
        finite("bracket", hi)
        if not 0 < lo < hi:
            raise UserInputError(f"{option('bracket')} needs 0 < M_LO < M_HI, got {lo:g} {hi:g}")
        if max_runs < 2:
            raise UserInputError(f"{option('bracket')} runs both ends: {option('max_runs')} "
                                 "must be >= 2")


def config_key(cfg, extra: str = "") -> str:
    """16 hex digits of SHA-256 over the config's TOML text, the flagwrap version, the test
    runs' :data:`RUNNER_REVISION` and ``extra`` (whatever else decides the run's result, e.g.
    a sweep's runner and stop rule)."""
    from flagwrap import __version__
    from flagwrap.io.config import config_to_toml

    text = (config_to_toml(cfg.replace(name="run"), for_hash=True)
            + f"\n# flagwrap {__version__}, runner revision {RUNNER_REVISION}\n")
    if extra:
        text += f"# {extra}\n"
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def simulate_until_buckled(cfg, stop_after: float | None = 2.0, chunk_turns: float = 1.0,
                           waiting=None):
    """Simulate ``cfg``; stop ``stop_after`` turns after the buckling crossing is detected.

    One uninterrupted run with a terminating event (:class:`BuckledStop`): from one turn into
    the CW phase, every ``chunk_turns`` turns, :class:`~flagwrap.analysis.buckling.WaitingTime`
    (``waiting``, default criteria) is applied to the free-end height so far. Once buckled with
    the crossing at least ``stop_after`` turns back, the run stops (status "completed",
    message "stopped early ..."): the verdict and ``t_c`` cannot change any more, and the
    post-buckling contact dynamics, the costly part of a run, is skipped. ``stop_after=None``
    runs the whole protocol. The final class of an early stopped run is the state at the stop
    (a fold may still become a wrap later).

    The state is never re-packed between pieces of the run (the event reads the trajectory
    only), so this holds for every kind of system the config builds: lab or turning frame,
    fixed or free body; the frames it keeps are those of the full run, bit for bit.

    Returns
    -------
    flagwrap.simulation.Trajectory
    """
    from threadpoolctl import threadpool_limits

    from flagwrap.simulation import Simulation

    with threadpool_limits(limits=cfg.numerics.threads):
        sim = Simulation(cfg)
        if stop_after is None:
            return sim.run()
        stop = BuckledStop(sim.system.schedule, stop_after=stop_after, every_turns=chunk_turns,
                           waiting=waiting)
        return sim.run(stop=stop)


def buckled_long_enough(traj, waiting, stop_after: float) -> str:
    """``"stopped early ..."`` if the trajectory so far has buckled by ``waiting``'s criterion
    (:class:`~flagwrap.analysis.buckling.WaitingTime` on the free-end height, core length L)
    with the crossing at least ``stop_after`` turns back; ``""`` otherwise."""
    import numpy as np

    from flagwrap.analysis.buckling import WaitingTime
    from flagwrap.simulation import TWO_PI

    from flagwrap.observables.tip import free_end_heights

    turns = np.asarray(traj.t) / TWO_PI
    heights = free_end_heights(np.asarray(traj.x), 1.0, traj.filament_slices())
    runs = [WaitingTime(**waiting.params()).compute(turns, h, np.asarray(traj.omega))
            for h in heights.T]  # each flagellum; the first to buckle decides
    buckled = [w for w in runs if w.buckled]
    w = min(buckled, key=lambda r: r.crossing_turns) if buckled else runs[0]
    if w.buckled and turns[-1] - w.crossing_turns >= stop_after:
        return (f"stopped early at t/T = {turns[-1]:.3f}: buckled (crossing at "
                f"{w.crossing_turns:.3f}), {stop_after:g} turns later")
    return ""


class BuckledStop:
    """Terminating event of the time loop (``Simulation.run(stop=...)``): once buckled
    (:class:`~flagwrap.analysis.buckling.WaitingTime` on the free-end height so far), with the
    crossing at least ``stop_after`` turns back, the run ends. Checked every ``every_turns``
    from one turn after the first CW phase starts (the schedule ``sched``); every flagellum's
    free end is watched, the first to buckle decides (:func:`simulate_until_buckled`'s
    event).

    It does not restart the integrator, so the frames up to the stop are those of the
    uninterrupted run, bit for bit, and it works on every system (it never re-packs a state).
    """

    def __init__(self, sched, stop_after: float = 2.0, every_turns: float = 1.0, waiting=None):
        from flagwrap.analysis.buckling import WaitingTime
        from flagwrap.simulation import TWO_PI

        self.waiting = waiting if waiting is not None else WaitingTime()
        self.stop_after = float(stop_after)
        self.every = float(every_turns)
        cw = [seg for seg in sched.segments if seg.omega < 0]
        self.next_check = (cw[0].t0 / TWO_PI + 1.0) if cw else math.inf
        self._two_pi = TWO_PI

    def __call__(self, traj) -> str:
        if traj.t[-1] / self._two_pi < self.next_check - 1e-9:
            return ""
        self.next_check += self.every
        return buckled_long_enough(traj, self.waiting, self.stop_after)


def simulate_and_analyse(cfg, path: Path, stop_after: float | None = 2.0) -> dict:
    """Default runner: simulate ``cfg`` (:func:`simulate_until_buckled`), write the run file to
    ``path``, analyse it (stored in the file) and return the summary."""
    from flagwrap.analysis.runfile_attrs import analyze_run_file
    from flagwrap.io.runfile import write_run

    traj = simulate_until_buckled(cfg, stop_after=stop_after)
    write_run(traj, path)
    try:
        res = analyze_run_file(path)
    except UserInputError as exc:  # e.g. a run that failed before the CW phase
        return {"buckled": None, "waiting_time_turns": float("nan"), "state": "failed",
                "run_status": traj.status, "message": f"{traj.message}; analysis: {exc}"}
    res["message"] = traj.message
    return res


#: what a cache entry's fields must be (absent is allowed: None)
ENTRY_TYPES = {"buckled": (bool,), "state": (str,), "run_status": (str,), "message": (str,),
               "waiting_time_turns": (int, float), "crossing_turns": (int, float),
               "torque_peak_reduced": (int, float)}


def entry_text(res: dict) -> str:
    """A cache entry: the result and the SHA-256 of its canonical JSON."""
    import hashlib

    body = json.dumps(res, sort_keys=True)
    return json.dumps({"result": res, "sha256": hashlib.sha256(body.encode()).hexdigest()},
                      sort_keys=True, indent=1)


def read_entry(path) -> tuple[dict | None, str]:
    """``(result, "")`` of a sound cache entry, ``(None, why)`` of a damaged one: unreadable or
    not JSON, a checksum that does not match (entries written before checksums: their fields
    alone are checked), or a field of the wrong type (``buckled = "maybe"``)."""
    import hashlib

    try:
        data = json.loads(Path(path).read_text())
    except (OSError, UnicodeDecodeError, ValueError) as exc:
        return None, f"not readable JSON: {exc}"
    if not isinstance(data, dict):
        return None, "not a JSON object"
    if "sha256" in data:
        res = data.get("result")
        if not isinstance(res, dict):
            return None, "no result"
        body = json.dumps(res, sort_keys=True)
        if hashlib.sha256(body.encode()).hexdigest() != data["sha256"]:
            return None, "its checksum does not match"
    else:
        res = data
    for k, types in ENTRY_TYPES.items():
        v = res.get(k)
        if v is not None and (not isinstance(v, types) or (bool not in types and isinstance(v, bool))):
            return None, f"{k} = {v!r} is not a {' or '.join(t.__name__ for t in types)}"
    if res.get("buckled") is None and res.get("state") != "failed" and "run_status" not in res:
        return None, "no buckling verdict and no run status"
    return res, ""


class RunCache:
    """Directory of test runs keyed by :func:`config_key` (``<key>.nc`` + ``<key>.json``).

    Parameters
    ----------
    directory : path-like
        created on first use.
    runner : callable, optional
        ``runner(cfg, path) -> dict`` with at least ``buckled``, ``waiting_time_turns``,
        ``state``, ``run_status``; default :func:`simulate_and_analyse`. Tests pass a fake.
    key_extra : str
        what besides the config decides ``runner``'s result (a sweep's case function and
        ``stop_after``), hashed into the keys so a change of it runs again.
    """

    def __init__(self, directory="out/critical", runner=None, key_extra: str = ""):
        self.directory = Path(directory)
        self.runner = runner if runner is not None else simulate_and_analyse
        self.key_extra = key_extra
        self.n_simulated = 0

    def paths(self, cfg):
        key = config_key(cfg, self.key_extra)
        return key, self.directory / f"{key}.nc", self.directory / f"{key}.json"

    def run(self, cfg) -> CriticalRun:
        """Result of ``cfg``: from ``<key>.json`` if present and sound (:func:`read_entry`),
        else by running it; a damaged entry is named on stderr and recomputed."""
        key, nc, js = self.paths(cfg)
        res = None
        if js.is_file():
            res, why = read_entry(js)
            if res is None:
                import sys

                print(f"flagwrap: cache entry {js} is damaged ({why}); running it again",
                      file=sys.stderr)
        reused = res is not None
        if not reused:
            self.directory.mkdir(parents=True, exist_ok=True)
            res = self.runner(cfg, nc)
            self.n_simulated += 1
            res = {k: (None if isinstance(v, float) and math.isnan(v) else v)
                   for k, v in res.items() if isinstance(v, (bool, int, float, str, type(None)))}
            text = entry_text(res)
            atomic_write(js, lambda tmp: tmp.write_text(text))

        def num(k):
            v = res.get(k)
            return float("nan") if v is None else float(v)

        status = str(res.get("run_status", ""))
        if res.get("buckled") is None or (status not in ("completed", "") and not res["buckled"]):
            # a run that stopped (guard tripped) before buckling has no verdict: never "stable"
            raise UserInputError(f"test run at M = {cfg.machin:.6g} ({self.directory / key}.nc) "
                                 f"failed without a buckling verdict: {res.get('message', status)}")

        return CriticalRun(machin=float(cfg.machin), buckled=bool(res["buckled"]),
                           waiting_time=num("waiting_time_turns"), state=str(res.get("state", "")),
                           status=status, key=key, reused=reused,
                           torque_peak=num("torque_peak_reduced"), crossing=num("crossing_turns"))


class CriticalSearch:
    """Bracketing + bisection on ``M`` for the buckling threshold of one geometry.

    Parameters
    ----------
    rtol : float
        stop when ``M_hi / M_lo - 1 <= rtol``; default 0.05.
    cw_turns : float
        ``K``, CW turns of a test run (buckled = onset within them); default 10.
    ccw_turns : float
        CCW turns before the switch; default 5.
    factor : float
        bracketing step (multiplicative, > 1); default 2.
    max_runs : int
        give up (``converged = False``) after this many test runs; default 16.
    cache : RunCache, optional
        default ``RunCache("out/critical")``.
    on_run : callable, optional
        called with each :class:`CriticalRun` as soon as it is known (progress printing).
    """

    def __init__(self, rtol=0.05, cw_turns=10.0, ccw_turns=5.0, factor=2.0, max_runs=16,
                 cache=None, on_run=None):
        self.rtol = float(rtol)
        if not (math.isfinite(self.rtol) and 0 < self.rtol < 1):
            raise UserInputError(f"rtol must be in (0, 1), got {rtol!r}")
        self.cw_turns = float(cw_turns)
        self.ccw_turns = float(ccw_turns)
        if not (self.cw_turns > 0 and self.ccw_turns > 0):
            raise UserInputError("cw_turns and ccw_turns must be > 0")
        self.factor = float(factor)
        if not self.factor > 1:
            raise UserInputError(f"factor must be > 1, got {factor!r}")
        self.max_runs = int(max_runs)
        self.cache = cache if cache is not None else RunCache()
        self.on_run = on_run
        self._computed = False

    def params(self) -> dict:
        return {"rtol": self.rtol, "cw_turns": self.cw_turns, "ccw_turns": self.ccw_turns,
                "factor": self.factor, "max_runs": self.max_runs}

    def _test(self, machin):
        cfg = probe_config(self._cfg, machin, self.ccw_turns, self.cw_turns)
        r = self.cache.run(cfg)
        self._runs.append(r)
        if self.on_run is not None:
            self.on_run(r)
        return r.buckled

    def compute(self, cfg, guess=None, bracket=None):
        """Search the threshold of ``cfg``'s geometry.

        Parameters
        ----------
        cfg : flagwrap.params.Config
        guess : float, optional
            first ``M`` to try (default: ``cfg.machin``).
        bracket : (float, float), optional
            ``(M_lo, M_hi)`` believed stable / buckled; both are run (or read from the cache)
            and the search widens the bracket by ``factor`` if a belief is wrong.

        Returns
        -------
        self
        """
        self._cfg, self._runs = cfg, []
        self._converged = False
        lo = hi = None
        if bracket is not None:
            b_lo, b_hi = (float(v) for v in bracket)
            if not 0 < b_lo < b_hi:
                raise UserInputError(f"bracket must be 0 < M_lo < M_hi, got {bracket!r}")
            for m in (b_lo, b_hi):
                if self._test(m):
                    hi = m if hi is None else min(hi, m)
                else:
                    lo = m if lo is None else max(lo, m)
        else:
            m = float(guess) if guess is not None else float(cfg.machin)
            if not (math.isfinite(m) and m > 0):
                raise UserInputError(f"guess must be a finite number > 0, got {guess!r}")
            if self._test(m):
                hi = m
            else:
                lo = m
        # bracketing
        while True:
            while (lo is None or hi is None) and len(self._runs) < self.max_runs:
                if hi is None:
                    m = lo * self.factor
                    if self._test(m):
                        hi = m
                    else:
                        lo = m
                else:
                    m = hi / self.factor
                    if self._test(m):
                        hi = m
                    else:
                        lo = m
            if lo is not None and hi is not None and lo > hi:
                # a buckled M below a stable one (non-monotone): a bracket between them holds
                # no switch, so look below the smallest buckled M for a stable one (the
                # lowest switch; summary()["monotone"] reports the inversion)
                lo = None
                continue
            break
        # bisection in log M
        while (lo is not None and hi is not None and hi / lo - 1 > self.rtol
               and len(self._runs) < self.max_runs):
            m = math.sqrt(lo * hi)
            if self._test(m):
                hi = m
            else:
                lo = m
        self._lo, self._hi = lo, hi
        self._converged = lo is not None and hi is not None and hi / lo - 1 <= self.rtol
        self._computed = True
        return self

    def _need(self):
        if not self._computed:
            raise AttributeError("CriticalSearch: call compute() first")

    @property
    def converged(self) -> bool:
        self._need()
        return self._converged

    @property
    def bracket(self) -> tuple:
        """``(M_lo, M_hi)``: largest stable and smallest buckled ``M`` found (None if missing)."""
        self._need()
        return (self._lo, self._hi)

    @property
    def machin_c(self) -> float:
        """``M_c = sqrt(M_lo M_hi)`` (nan without a bracket)."""
        self._need()
        if self._lo is None or self._hi is None:
            return float("nan")
        return math.sqrt(self._lo * self._hi)

    @property
    def relative_uncertainty(self) -> float:
        """Half-width of the bracket in log M: ``sqrt(M_hi / M_lo) - 1``."""
        self._need()
        if self._lo is None or self._hi is None:
            return float("nan")
        return math.sqrt(self._hi / self._lo) - 1

    def omega_of(self, machin: float) -> float:
        """``omega = M A / (eta L^4)`` [rad/s] for the searched geometry and fluid."""
        self._need()
        fil = self._cfg.filament
        return machin * fil.bending_modulus / (self._cfg.fluid.viscosity * fil.length**4)

    @property
    def omega_c(self) -> float:
        """Critical motor angular speed [rad/s]."""
        return self.omega_of(self.machin_c)

    @property
    def frequency_c(self) -> float:
        """Critical motor frequency ``omega_c / 2 pi`` [Hz]."""
        return self.omega_c / (2 * math.pi)

    @property
    def runs(self) -> list:
        """Every :class:`CriticalRun` of the search, in the order made (reused ones included)."""
        self._need()
        return list(self._runs)

    @property
    def monotone(self) -> bool:
        """No stable run at a larger ``M`` than a buckled one."""
        self._need()
        st = [r.machin for r in self._runs if not r.buckled]
        bk = [r.machin for r in self._runs if r.buckled]
        return not (st and bk and max(st) > min(bk))

    def summary(self) -> dict:
        """JSON-able result."""
        self._need()
        lo, hi = self._lo, self._hi
        return {
            "machin_c": self.machin_c, "bracket": [lo, hi], "converged": self.converged,
            "relative_uncertainty": self.relative_uncertainty,
            "omega_c": self.omega_c, "frequency_c": self.frequency_c,
            "machin_critical_scaling": float(self._cfg.machin_critical_scaling),
            "gravity_number": float(self._cfg.gravity_number),
            "monotone": self.monotone, "params": self.params(),
            "runs": [dataclasses.asdict(r) for r in self._runs],
        }
