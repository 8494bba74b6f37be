"""Each motor its own schedule: ``[[flagellum]] protocol`` (flagwrap.motor.protocol.
MotorSchedules), against single-filament runs, through the run file and the analysis, and
its refusals."""

import dataclasses

import numpy as np
import pytest

from conftest import make_config, paper_filament
from flagwrap.errors import UserInputError
from flagwrap.motor.protocol import MotorSchedules, Schedule, motor_schedule
from flagwrap.params import Flagellum, Numerics, Phase
from flagwrap.simulation import simulate

REF = (("ccw", 0.3), ("cw", 0.3))
OWN = (Phase("ccw", 0.45), Phase("cw", 0.15))  # reverses a quarter turn later


def _cfg(protocol=REF, tol=1e-6, **kw):
    cfg = make_config(machin=283.0, protocol=protocol, hi=False,
                      filament=paper_filament(n_beads=21),
                      numerics=Numerics(hydrodynamics=False, tol=tol))
    return cfg.replace(body=dataclasses.replace(cfg.body, enabled=False), **kw)


def _pair(own=OWN, **kw):
    L = paper_filament().length
    return _cfg(flagella=(Flagellum(anchor=(0.0, 0.0, 0.0), axis=(0.0, 0.0, -1.0)),
                          Flagellum(anchor=(3 * L, 0.0, 0.0), axis=(0.0, 0.0, -1.0),
                                    protocol=own)), **kw)


def test_the_schedules_cut_at_every_motors_switch():
    s = motor_schedule(_pair())
    assert isinstance(s, MotorSchedules)
    ref, own = Schedule(_cfg().motor.protocol), Schedule(OWN)
    assert s.t_end == pytest.approx(ref.t_end)
    assert [seg.t0 for seg in s.segments] == pytest.approx([0.0, ref.segments[1].t0,
                                                            own.segments[1].t0])
    np.testing.assert_array_equal([seg.omega for seg in s.segments],
                                  [[1, 1], [-1, 1], [-1, -1]])
    assert [seg.label for seg in s.segments] == ["ccw", "cw", "cw"]
    # a table whose protocol is motor.protocol's, or none: the shared scalar schedule
    same = _pair(own=_cfg().motor.protocol)
    assert type(motor_schedule(same)) is Schedule


def test_each_flagellum_far_apart_follows_its_own_single_run():
    # HI off, 3 L apart: nothing couples the two but the shared step sequence, so each is its
    # own single-filament run (its protocol) up to the integrators' global errors, which
    # fall with the tolerance (measured, flagellum 0 / 1: 7.9e-6 / 4.1e-6 L at tol 1e-6,
    # 2.5e-7 / 1.2e-7 at 1e-8, about as tol^0.75): below 10 x 1e-6, and converging
    errs = []
    for tol in (1e-6, 1e-8):
        two = simulate(_pair(tol=tol))
        one = simulate(_cfg(tol=tol))
        own = simulate(_cfg(protocol=tuple((p.direction, p.turns) for p in OWN), tol=tol))
        assert two.ok and one.ok and own.ok
        N = 21
        x2 = np.asarray(two.x)
        d = np.array([3.0, 0.0, 0.0])
        t2 = np.asarray(two.t)
        for single, sl, shift in ((one, slice(0, N), 0.0), (own, slice(N, 2 * N), d)):
            assert np.allclose(np.asarray(single.t), t2)  # the same saved times
            err = np.abs(x2[:, sl] - shift - np.asarray(single.x)).max()
            assert err < 1e-5, (tol, err)
            errs.append(err)
    assert errs[2] < errs[0] / 10 and errs[3] < errs[1] / 10
    rates = np.asarray(two.motors)[:, 2:]  # each motor at its own speed
    t_turns = t2 / (2 * np.pi)
    assert np.all(rates[t_turns < 0.29, 0] == 1) and np.all(rates[t_turns > 0.31, 0] == -1)
    assert np.all(rates[t_turns < 0.44, 1] == 1) and np.all(rates[t_turns > 0.46, 1] == -1)


def test_the_run_file_and_the_analysis_read_each_motors_own_rate(tmp_path, capsys):
    from flagwrap.analysis.runfile_attrs import analyze_dataset
    from flagwrap.io.config import config_to_toml, load_config
    from flagwrap.io.runfile import read_run, write_run

    base = _cfg()
    cfg = base.replace(body=dataclasses.replace(base.body, enabled=True),
                       flagella=(Flagellum(polar_deg=0.0),  # flagellum 1 never reverses
                                 Flagellum(polar_deg=40.0, azimuth_deg=180.0,
                                           protocol=(Phase("ccw", 0.6),))))
    (tmp_path / "c.toml").write_text(config_to_toml(cfg))
    assert load_config(tmp_path / "c.toml").flagella == cfg.flagella  # TOML round trip
    tr = simulate(cfg)
    assert tr.ok, tr.message
    ds = read_run(write_run(tr, tmp_path / "r.nc"))
    rates = ds["motor_rates"].values
    assert (rates[:, 1] > 0).all() and (rates[-1, 0] < 0)
    a0, a1 = analyze_dataset(ds, filament=0), analyze_dataset(ds, filament=1)
    assert a0.motor_reversed and not a1.motor_reversed  # read against the run's reversal
    assert a0.summary()["switch_turns"] == a1.summary()["switch_turns"] == pytest.approx(0.3,
                                                                                        abs=0.06)
    from flagwrap.analysis.runfile_attrs import analyze_run_file

    res = analyze_run_file(tmp_path / "r.nc", write=False)
    assert [f["motor_reversed"] for f in res["filaments"]] == [True, False]
    from flagwrap.cli.main import main

    assert main(["analyze", str(tmp_path / "r.nc")]) == 0
    out = capsys.readouterr().out
    assert "flagellum 1:" in out and "its motor never reversed" in out.split("flagellum 1:")[1]


@pytest.mark.parametrize("own, match", [
    ((Phase("ccw", 0.5),), r"flagellum\[1\].protocol lasts 0.5 reference turns, motor.protocol 0.6"),
    ((), r"flagellum.protocol must be a non-empty array"),
])
def test_refusals_name_the_table(own, match):
    with pytest.raises(UserInputError, match=match):
        _pair(own=own)


def test_a_torque_motor_refuses_a_phase_speed_in_a_flagellums_protocol():
    cfg = _pair()
    m = dataclasses.replace(cfg.motor, kind="torque", stall_torque=1e-4)
    with pytest.raises(UserInputError, match=r"flagellum\[1\].protocol speed = 2"):
        cfg.replace(motor=m, flagella=(cfg.flagella[0], dataclasses.replace(
            cfg.flagella[1], protocol=(Phase("ccw", 0.3, 2.0), Phase("cw", 0.45)))))


def test_the_config_file_takes_a_flagellums_protocol(tmp_path):
    from flagwrap.io.config import load_config

    from conftest import tiny_toml

    p = tmp_path / "c.toml"
    p.write_text(tiny_toml(ccw=1, cw=1) + """
[body]
enabled = false
[[flagellum]]
anchor = [0.0, 0.0, 0.0]
axis = [0.0, 0.0, -1.0]
[[flagellum]]
anchor = [1.2, 0.0, 0.0]
axis = [0.0, 0.0, -1.0]
protocol = [{ direction = "ccw", turns = 2 }]
""")
    cfg = load_config(p)
    assert cfg.flagella[1].protocol == (Phase("ccw", 2.0),) and cfg.flagella[0].protocol is None
    p.write_text(p.read_text().replace('protocol = [{ direction = "ccw", turns = 2 }]',
                                       'protocol = [{ direction = "ccw" }]'))
    with pytest.raises(UserInputError, match=r"flagellum\[1\].protocol\[0\] is missing turns"):
        load_config(p)


def test_each_flagellum_its_own_motor_law():
    # one torque motor among speed motors ([[flagellum]] kind): far apart without HI, the
    # speed motor's flagellum is the speed-driven single run and the torque motor's the
    # torque-driven single run, up to the integrators' global errors, which converge with
    # the tolerance (measured, speed / torque flagellum: 7.0e-7 / 5.3e-5 L at tol 1e-6,
    # 9.0e-9 / 1.4e-6 at 1e-8: the torque motor's angle carries a phase error)
    from flagwrap.system.rod_system import MixedDrives, RodSystem

    L = paper_filament().length
    tau = 2e-5  # [N m]: a load-limited rate below the speed motor's
    errs = []
    for tol in (1e-6, 1e-8):
        base = _cfg(protocol=(("ccw", 0.3),), tol=tol)
        mixed = base.replace(flagella=(
            Flagellum(anchor=(0.0, 0.0, 0.0), axis=(0.0, 0.0, -1.0)),
            Flagellum(anchor=(3 * L, 0.0, 0.0), axis=(0.0, 0.0, -1.0), kind="torque",
                      stall_torque=tau)))
        s = RodSystem(mixed)
        assert isinstance(s.drive, MixedDrives) and s.drive.free
        assert [d.free for d in s.drives] == [False, True]
        two = simulate(mixed)
        speed = simulate(base)
        torque = simulate(base.replace(motor=dataclasses.replace(base.motor, kind="torque",
                                                                 stall_torque=tau)))
        assert two.ok and speed.ok and torque.ok, (two.message, torque.message)
        x2 = np.asarray(two.x)
        d = np.array([3.0, 0.0, 0.0])
        errs.append((np.abs(x2[:, :21] - np.asarray(speed.x)).max(),
                     np.abs(x2[:, 21:] - d - np.asarray(torque.x)).max()))
        rates = np.asarray(two.motors)[:, 2:]
        assert np.all(rates[1:, 0] == 1.0)  # the speed motor at the protocol's rate
        assert 0.3 < rates[-1, 1] < 0.5  # the torque motor at its load (0.405 omega)
    assert errs[0][0] < 1e-5 and errs[0][1] < 1e-4
    assert errs[1][0] < errs[0][0] / 10 and errs[1][1] < errs[0][1] / 10


@pytest.mark.parametrize("table, match", [
    (dict(kind="torque"), r"flagellum\[1\].kind = 'torque' needs flagellum.stall_torque"),
    (dict(stall_torque=1e-5), r"flagellum\[1\].stall_torque and zero_load_speed need flagellum.kind"),
    (dict(kind="warp"), r"flagellum\[1\].kind must be one of"),
])
def test_a_flagellums_motor_law_is_checked_and_named(table, match):
    L = paper_filament().length
    with pytest.raises(UserInputError, match=match):
        _cfg().replace(flagella=(
            Flagellum(anchor=(0.0, 0.0, 0.0), axis=(0.0, 0.0, -1.0)),
            Flagellum(anchor=(3 * L, 0.0, 0.0), axis=(0.0, 0.0, -1.0), **table)))
