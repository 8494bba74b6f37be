"""Critical search on a fake, instant simulator with a known threshold (oracle: M_true)."""

from __future__ import annotations

import math

import pytest

from flagwrap.analysis.critical import CriticalSearch, RunCache, config_key, probe_config
from flagwrap.cases import get_case
from flagwrap.errors import UserInputError

M_TRUE = 417.0


class FakeRunner:
    """Buckled iff M > M_TRUE; t_c/T = 0.5/eps; counts calls."""

    def __init__(self, m_true=M_TRUE):
        self.m_true, self.calls = m_true, []

    def __call__(self, cfg, path):
        m = cfg.machin
        self.calls.append(m)
        eps = m / self.m_true - 1
        b = eps > 0
        return {"buckled": b, "waiting_time_turns": 0.5 / eps if b else float("nan"),
                "state": "folding" if b else "stable", "run_status": "completed",
                "torque_peak_reduced": -1.0}


@pytest.fixture
def cfg():
    return get_case("fig4a")


@pytest.mark.parametrize("guess", [100.0, 283.0, 3000.0])
@pytest.mark.parametrize("rtol", [0.1, 0.02])
def test_converges_to_rtol(tmp_path, cfg, guess, rtol):
    fake = FakeRunner()
    s = CriticalSearch(rtol=rtol, cache=RunCache(tmp_path, runner=fake)).compute(cfg, guess=guess)
    lo, hi = s.bracket
    assert s.converged and s.monotone
    assert lo < M_TRUE <= hi
    assert hi / lo - 1 <= rtol
    assert abs(s.machin_c / M_TRUE - 1) <= rtol
    # every run is reported, in order, with its verdict
    assert [r.machin for r in s.runs] == pytest.approx(fake.calls)
    assert all(r.buckled == (r.machin > M_TRUE) for r in s.runs)
    # bisection halves log(hi/lo): the run count is bounded
    assert len(s.runs) <= 2 + math.ceil(math.log2(abs(math.log(guess / M_TRUE)) / math.log(2)) + 1) \
        + math.ceil(math.log2(math.log(2) / math.log(1 + rtol)))


def test_omega_c_from_machin_c(tmp_path, cfg):
    s = CriticalSearch(rtol=0.05, cache=RunCache(tmp_path, runner=FakeRunner())).compute(cfg)
    fil = cfg.filament
    assert s.omega_c == pytest.approx(s.machin_c * fil.bending_modulus / (cfg.fluid.viscosity * fil.length**4))
    assert s.frequency_c == pytest.approx(s.omega_c / (2 * math.pi))


def test_reuses_cached_runs(tmp_path, cfg):
    fake = FakeRunner()
    s1 = CriticalSearch(rtol=0.1, cache=RunCache(tmp_path, runner=fake)).compute(cfg)
    n1 = len(fake.calls)
    assert n1 == len(s1.runs) and not any(r.reused for r in s1.runs)
    # same search again: nothing simulated, same result
    cache = RunCache(tmp_path, runner=fake)
    s2 = CriticalSearch(rtol=0.1, cache=cache).compute(cfg)
    assert len(fake.calls) == n1 and cache.n_simulated == 0
    assert all(r.reused for r in s2.runs) and s2.machin_c == s1.machin_c
    # a finer tolerance continues from the cached runs
    cache = RunCache(tmp_path, runner=fake)
    s3 = CriticalSearch(rtol=0.01, cache=cache).compute(cfg)
    assert cache.n_simulated == len(fake.calls) - n1 > 0
    assert sum(r.reused for r in s3.runs) == n1
    assert abs(s3.machin_c / M_TRUE - 1) <= 0.01


def test_bracket_given_and_wrong_belief_widened(tmp_path, cfg):
    s = CriticalSearch(rtol=0.05, cache=RunCache(tmp_path, runner=FakeRunner())).compute(
        cfg, bracket=(283.0, 600.0))
    assert s.runs[0].machin == 283.0 and s.runs[1].machin == 600.0
    assert s.bracket[0] < M_TRUE <= s.bracket[1]
    # both ends buckle: the search goes down by `factor`
    s = CriticalSearch(rtol=0.05, cache=RunCache(tmp_path / "b", runner=FakeRunner(150.0))).compute(
        cfg, bracket=(283.0, 600.0))
    assert s.converged and s.bracket[0] < 150.0 <= s.bracket[1]


class WindowRunner(FakeRunner):
    """Buckled only for 100 < M < 300 (non-monotone, like the records without HI)."""

    def __call__(self, cfg, path):
        res = super().__call__(cfg, path)
        b = 100.0 < cfg.machin < 300.0
        res.update(buckled=b, state="folding" if b else "stable")
        return res


def test_inverted_bracket_is_not_bisected(tmp_path, cfg):
    # the given bracket's low end buckles, its high end does not: no switch lies between them,
    # so the search must go below the buckled end (it bisected 200..400 and reported M_c ~ 204)
    s = CriticalSearch(rtol=0.05, cache=RunCache(tmp_path, runner=WindowRunner())).compute(
        cfg, bracket=(200.0, 400.0))
    lo, hi = s.bracket
    assert s.converged and lo <= 100.0 < hi <= 105.0
    assert not s.summary()["monotone"]


def test_max_runs_not_converged(tmp_path, cfg):
    s = CriticalSearch(rtol=1e-4, max_runs=4, cache=RunCache(tmp_path, runner=FakeRunner())).compute(cfg)
    assert not s.converged and len(s.runs) == 4


def test_key_depends_on_config_and_protocol(cfg):
    a = probe_config(cfg, 300.0)
    assert config_key(a) == config_key(probe_config(cfg, 300.0))
    assert config_key(a) != config_key(probe_config(cfg, 300.1))
    assert config_key(a) != config_key(probe_config(cfg, 300.0, cw_turns=12))
    assert a.motor.protocol[0].direction == "ccw" and a.motor.protocol[0].turns == 5.0
    assert a.machin == pytest.approx(300.0)


def test_guards(tmp_path, cfg):
    with pytest.raises(UserInputError):
        CriticalSearch(rtol=0)
    with pytest.raises(UserInputError):
        CriticalSearch(factor=1.0)
    s = CriticalSearch(cache=RunCache(tmp_path, runner=FakeRunner()))
    with pytest.raises(AttributeError):
        s.machin_c
    with pytest.raises(UserInputError):
        s.compute(cfg, bracket=(600.0, 283.0))


def test_cli_with_fake_runner(tmp_path, cfg, monkeypatch, capsys):
    import flagwrap.analysis.critical as crit
    from flagwrap.cli.main import main
    from flagwrap.io.config import config_to_toml

    path = tmp_path / "c.toml"
    path.write_text(config_to_toml(cfg))

    class Cache(RunCache):
        def __init__(self, directory, runner=None):
            super().__init__(directory, runner=FakeRunner())

    monkeypatch.setattr(crit, "RunCache", Cache)
    rc = main(["critical", str(path), "--rtol", "0.1", "--cache", str(tmp_path / "cache")])
    out = capsys.readouterr().out
    assert rc == 0
    assert "M_c" in out and "omega_c" in out
    assert out.count("out/critical") == 0 and out.count(".nc") >= 3
    # --json is strict JSON: the stable runs' NaN waiting times inside "runs" become null
    import json

    def no_nan(name):
        raise ValueError(f"{name} in the JSON output")

    rc = main(["critical", str(path), "--rtol", "0.1", "--cache", str(tmp_path / "cache"), "--json"])
    res = json.loads(capsys.readouterr().out, parse_constant=no_nan)
    assert rc == 0 and any(r["waiting_time"] is None for r in res["runs"])


def _prefix_of_full_run(cfg, stop_after, every_turns):
    """The runner's frames against the uninterrupted simulator's (the oracle): the same,
    bit for bit, up to where the runner stopped."""
    import numpy as np

    from flagwrap.analysis.critical import simulate_until_buckled
    from flagwrap.simulation import simulate

    a = simulate(cfg)
    b = simulate_until_buckled(cfg, stop_after=stop_after, chunk_turns=every_turns)
    assert a.ok and b.ok and 1 < len(b.t) <= len(a.t)
    n = len(b.t)
    for k in ("t", "x", "theta", "phi"):
        assert np.array_equal(np.asarray(getattr(b, k)), np.asarray(getattr(a, k))[:n]), k
    return a, b


def test_runner_equals_the_full_run(cfg):
    """The checks every 0.5 turn read the trajectory and never restart the integrator."""
    from flagwrap.io.config import config_from_dict

    d = cfg.to_dict()
    d["filament"]["n_beads"] = 21
    small = probe_config(config_from_dict(d), 283.0, ccw_turns=0.5, cw_turns=2.0)
    a, b = _prefix_of_full_run(small, 2.0, 0.5)
    assert len(a.t) == len(b.t)  # stable: the whole protocol


def test_runner_stops_a_turning_frame_run_off_whole_turns_without_a_jump():
    """The turning frame (its state is not the lab's ``pack``): checks 0.37 turn apart, a
    buckling run (M = 1500) stopped early. The re-packing runner of before jumped 0.17 L at
    such an edge."""
    import dataclasses

    import numpy as np

    from flagwrap.io.config import config_from_dict
    from flagwrap.io.config import load_config

    base = load_config("examples/fig4a.toml")
    d = base.to_dict()
    d["filament"]["n_beads"] = 21
    c = probe_config(config_from_dict(d), 1500.0, ccw_turns=1.0, cw_turns=6.0)
    c = c.replace(numerics=dataclasses.replace(c.numerics, frame="rotating"))
    a, b = _prefix_of_full_run(c, 0.5, 0.37)
    assert b.message.startswith("stopped early") and len(b.t) < len(a.t), b.message
    step = np.abs(np.diff(np.asarray(b.x)[:, -1, :], axis=0)).max()
    assert step < 0.1  # free end moves < 0.1 L between frames 0.05 T apart: no jump


def test_runner_takes_a_free_swimmer_off_whole_turns(tmp_path):
    """The free swimmer (its state carries the body's pose): the runner of before raised
    TypeError at its second chunk. Here the default runner (run file + analysis) on it."""
    import math

    from flagwrap.analysis.critical import simulate_and_analyse
    from test_swimmer import swimmer_config

    c = swimmer_config(protocol=(("ccw", 0.3), ("cw", 1.6)))
    _prefix_of_full_run(c, 2.0, 0.37)
    res = simulate_and_analyse(c, tmp_path / "run.nc")
    assert res["run_status"] == "completed" and res["buckled"] in (True, False)
    assert (tmp_path / "run.nc").is_file() and not math.isnan(res["torque_peak_reduced"])


def test_failed_run_is_not_called_stable(tmp_path, cfg):
    def failing(cfg, path):
        return {"buckled": False, "waiting_time_turns": float("nan"), "state": "stable",
                "run_status": "failed", "message": "bead 40 entered the cell body"}

    s = CriticalSearch(cache=RunCache(tmp_path, runner=failing))
    with pytest.raises(UserInputError, match="entered the cell body"):
        s.compute(cfg)


def test_buckled_stop_event_ends_the_uninterrupted_run():
    """Oracle: the full run. The event stops the loop once buckled, and the frames it kept are
    the full run's, bit for bit (no restart of the integrator)."""
    import dataclasses

    import numpy as np

    from flagwrap.analysis.buckling import WaitingTime
    from flagwrap.analysis.critical import BuckledStop
    from flagwrap.io.config import load_config
    from flagwrap.params import Phase
    from flagwrap.simulation import TWO_PI, Simulation

    cfg = load_config("examples/fig4a.toml")
    fil = dataclasses.replace(cfg.filament, n_beads=21, pitch_angle_deg=None, pitch=None, turns=2.0)
    cfg = cfg.replace(filament=fil, motor=dataclasses.replace(
        cfg.motor, machin=1500.0, protocol=(Phase("ccw", 1.0), Phase("cw", 8.0))))
    full = Simulation(cfg).run()
    sim = Simulation(cfg)
    ev = sim.run(stop=BuckledStop(sim.system.schedule, stop_after=1.0))
    assert full.ok and ev.ok and "stopped early" in ev.message
    n = len(ev.t)
    assert n < len(full.t)
    assert np.array_equal(np.asarray(full.x)[:n], np.asarray(ev.x))
    x = np.asarray(full.x)
    w = WaitingTime().compute(np.asarray(full.t) / TWO_PI, x[:, -1, 2] - x[:, 0, 2], np.asarray(full.omega))
    assert w.buckled and ev.t[-1] / TWO_PI - w.crossing_turns >= 1.0 - 1e-9


@pytest.mark.parametrize("damage, why", [
    (lambda t: t[: len(t) // 2], "not readable JSON"),                       # truncated
    (lambda t: t.replace('"buckled": true', '"buckled": "maybe"'), "checksum does not match"),
    (lambda t: '{"buckled": "maybe", "run_status": "completed"}', "buckled = 'maybe' is not a bool"),
    (lambda t: "[1, 2]", "not a JSON object"),
])
def test_a_damaged_cache_entry_is_named_and_run_again_never_trusted(tmp_path, cfg, capsys,
                                                                    damage, why):
    # issue 33: a truncated entry gave a JSONDecodeError traceback, one holding
    # buckled = "maybe" was trusted as buckled
    fake = FakeRunner()
    probe = cfg.replace(motor=cfg.motor.__class__(machin=500.0, protocol=cfg.motor.protocol))
    cache = RunCache(tmp_path, runner=fake)
    first = cache.run(probe)
    assert first.buckled and not first.reused and len(fake.calls) == 1
    key, _, js = cache.paths(probe)
    assert cache.run(probe).reused and len(fake.calls) == 1  # a sound entry is reused
    js.write_text(damage(js.read_text()))
    again = RunCache(tmp_path, runner=fake).run(probe)
    assert not again.reused and again.buckled and len(fake.calls) == 2
    err = capsys.readouterr().err
    assert f"cache entry {js} is damaged" in err and why in err and "running it again" in err
    assert RunCache(tmp_path, runner=fake).run(probe).reused  # rewritten sound


def test_an_entry_written_before_checksums_is_still_read(tmp_path, cfg):
    import json

    fake = FakeRunner()
    cache = RunCache(tmp_path, runner=fake)
    probe = cfg.replace(motor=cfg.motor.__class__(machin=300.0, protocol=cfg.motor.protocol))
    _, _, js = cache.paths(probe)
    tmp_path.mkdir(exist_ok=True)
    js.write_text(json.dumps({"buckled": False, "state": "stable", "run_status": "completed",
                              "waiting_time_turns": None}))
    r = cache.run(probe)
    assert r.reused and not r.buckled and not fake.calls
