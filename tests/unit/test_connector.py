"""The connector lead (``clamp.lead = "connector"``, issue 35): the helix centred on the motor
axis, reached by a rigid arm the motor holds (no drag, no elastic energy). Its shape, its
stress-free start on every joint, every kind of system it can be part of, the twist of its held
bond (no wind-up over turns, lab and turning frame alike) and its refusals."""

import math
import tomllib

import numpy as np
import pytest

from conftest import system_kinds, tiny_toml
from flagwrap.errors import UserInputError
from flagwrap.geometry.helix import connector_arm_bonds, filament_positions, held_beads
from flagwrap.io.config import config_from_dict

CONNECTOR = "\n[clamp]\nlead = 'connector'\n"


def _cfg(text=None, extra_numerics="", tables="", lead="connector", **kw):
    text = tiny_toml(**kw) if text is None else text
    text = text.replace("[numerics]\n", "[numerics]\n" + extra_numerics)
    return config_from_dict(tomllib.loads(text + tables + f"\n[clamp]\nlead = '{lead}'\n"))


def test_shape_is_the_kink_helix_centred_on_the_axis():
    cfg = _cfg()
    fil = cfg.filament
    R, b, N = fil.helix_radius, fil.bond_length, fil.n_beads
    k = connector_arm_bonds(R, b)
    assert k == math.ceil(R / b) and held_beads(fil, cfg.clamp) == k + 2
    x = filament_positions(fil, cfg.clamp)
    kink = filament_positions(fil, _cfg(lead="kink").clamp)
    assert len(x) == N + k
    # the arm: radial, in the anchor plane, from the anchor to radius R, bonds <= b
    arm = x[:k + 1]
    assert np.all(arm[:, 2] == 0.0) and np.all(arm[:, 1] == 0.0)
    assert np.allclose(np.linalg.norm(np.diff(arm, axis=0), axis=1), R / k)
    # then the clamped bond along the axis, length b, and the helix at radius R about the axis
    assert np.allclose(x[k + 1] - x[k], [0.0, 0.0, -b])
    hel = x[k + 1:]
    assert np.allclose(np.hypot(hel[:, 0], hel[:, 1]), R, rtol=1e-12)
    # the filament proper is the kink lead's, moved by R
    assert np.allclose(hel - [-R, 0.0, 0.0], kink[1:], rtol=0, atol=1e-15)
    assert np.allclose(np.linalg.norm(np.diff(hel, axis=0), axis=1), b)


JOINTS = {
    "clamp": "",
    "lumped hook": "\n[joint]\nkind = 'hook'\nhook_length = 0.004\nhook_bending_modulus = 5e-9\n",
    "resolved hook": ("\n[joint]\nkind = 'hook'\nhook_length = 0.004\nhook_bending_modulus = 5e-9"
                      "\nhook_segments = 3\n"),
}


@pytest.mark.parametrize("joint", list(JOINTS))
def test_start_is_stress_free_and_the_arm_is_held(joint):
    from flagwrap.system.rod_system import RodSystem

    cfg = _cfg(tables=JOINTS[joint])
    kink = RodSystem(_cfg(tables=JOINTS[joint], lead="kink"))
    s = RodSystem(cfg)
    nh = held_beads(cfg.filament, cfg.clamp)
    j = s.joint
    assert (j.n_beads, j.n_edges, j.vertex, j.motor_bond) == (nh, nh - 1, nh - 1, nh - 2)
    assert j.twist_rate == 1.0  # the motor's bond is along the axis
    # the same active beads and unknowns as the kink lead: the arm is not in the hydrodynamics
    assert s.parts[0].nb == kink.parts[0].nb and len(s.initial_y()) == len(kink.initial_y())
    info = s.forces(s.initial_y(), s.frames0.copy())
    assert np.abs(info.G).max() < 1e-9 * np.abs(kink.forces(kink.initial_y() + 1e-4,
                                                            kink.frames0.copy()).G).max()
    # no stiffness between held bonds; the joint's vertex has the joint's
    assert np.all(s.rest.cbend[1:nh - 1] == 0.0) and np.all(s.rest.ctwist[1:nh - 1] == 0.0)
    assert s.rest.cbend[nh - 1] == kink.rest.cbend[1]


KINDS = {**system_kinds(polar_deg=45),  # at 30 deg the two arms would cross
         "no body": ("", "[body]\nenabled = false\n"),
         "torque motor": ("", "", "[motor]\nkind = 'torque-speed'\nstall_torque = 2e-4\n"
                                  "zero_load_speed = 0.05\n")}


@pytest.mark.parametrize("kind", list(KINDS))
def test_every_kind_of_system_runs_with_the_connector(kind, tmp_path):
    from flagwrap.io.runfile import config_of, read_run, write_run
    from flagwrap.simulation import make_system, simulate

    numerics, tables, *motor = KINDS[kind]
    text = tiny_toml(ccw=0.1, cw=0.05)
    if motor:
        text = text.replace("[motor]\n", motor[0]).replace("machin = 100", "frequency = 0.02")
    cfg = _cfg(text, numerics, tables)
    s = make_system(cfg)
    nh = held_beads(cfg.filament, cfg.clamp)
    assert all(p.nc == nh for p in s.parts)
    tr = simulate(cfg)
    assert tr.ok and tr.n_steps > 0
    path = tmp_path / "run.nc"
    write_run(tr, path)
    ds = read_run(path)
    assert config_of(ds).clamp.lead == "connector"  # stored in the run file
    # the arm turns with the motor: its end stays at radius R from the motor axis
    x = ds["position"].values / cfg.filament.length
    if "body_position" in ds.variables:
        from flagwrap.observables.swimming import body_frame

        x = body_frame(x, ds["body_position"].values / cfg.filament.length,
                       ds["body_orientation"].values)
    if len(s.parts) == 1:
        r = np.hypot(x[:, nh - 2, 0], x[:, nh - 2, 1])
        assert np.allclose(r, cfg.filament.helix_radius / cfg.filament.length, rtol=1e-9)


@pytest.mark.parametrize("lead", ["connector", "kink"])
def test_held_twist_does_not_wind_up_and_frames_agree(lead):
    # a wrong twist rate of the motor's bond would add its error to the joint's twist every
    # turn (2 pi per turn for a rate off by 1); the steady whirl's twist torque at the joint
    # must repeat from turn to turn, and the lab and turning frames must give the same one
    from flagwrap.simulation import simulate

    text = tiny_toml(ccw=3.0, cw=0.05, machin=100)
    out = {}
    for frame in ("lab", "rotating"):
        tr = simulate(_cfg(text.replace("tol = 1e-3", "tol = 1e-6"), f"frame = '{frame}'\n",
                           lead=lead))
        assert tr.ok
        rec = tr.arrays()
        turns = np.asarray(rec["t"]) / (2 * np.pi)  # speed 1: a turn per 2 pi
        tw = np.asarray(rec["hook_twist_torque"])
        out[frame] = [float(tw[np.argmin(np.abs(turns - T))]) for T in (2.0, 3.0)]
    lab, rot = out["lab"], out["rotating"]
    # turn 2 and turn 3 of the steady whirl: equal to the integrator's tolerance (1e-6 local)
    assert abs(lab[1] - lab[0]) < 1e-3 * abs(lab[1])
    assert abs(rot[1] - rot[0]) < 1e-3 * abs(rot[1])
    # lab against turning frame: the same steady state, to the tolerance's accumulated error
    assert abs(lab[1] - rot[1]) < 1e-2 * abs(rot[1])


def test_analysis_skips_the_held_arm(tmp_path):
    # the arm lies at the pole: were it counted, a fixed cell would have beads beside its body
    from flagwrap.analysis.runfile_attrs import analyze_run_file
    from flagwrap.io.runfile import write_run
    from flagwrap.simulation import simulate

    cfg = _cfg(tiny_toml(ccw=0.1, cw=0.05))
    path = tmp_path / "run.nc"
    write_run(simulate(cfg), path)
    res = analyze_run_file(path, write=False)
    assert res["params"]["first_bead"] == held_beads(cfg.filament, cfg.clamp)


# ---- refusals --------------------------------------------------------------------------------

def test_straight_filament_refuses_the_connector():
    with pytest.raises(UserInputError, match="clamp.lead = 'connector'.*straight"):
        _cfg(tiny_toml().replace("n_beads = 21\n", "n_beads = 21\nshape = 'straight'\n"))


def test_unknown_lead_names_the_choices():
    with pytest.raises(UserInputError, match="clamp.lead must be one of 'kink', 'ramp', 'connector'"):
        _cfg(lead="centre")


def test_arm_into_the_body_is_refused_by_the_cli(tmp_path, capsys):
    # a motor axis tilted 80 deg from the surface normal puts the arm's plane through the body:
    # one line naming clamp.lead, exit 2, no output file
    from flagwrap.cli.main import main

    text = tiny_toml() + CONNECTOR + (
        "[[flagellum]]\nanchor = [0.0, 0.0, 0.0]\naxis = [0.98481, 0.0, -0.17365]\n"
        "spin_deg = SPIN\n")
    refused = 0
    for spin in (0, 90, 180, 270):
        path = tmp_path / f"tilt{spin}.toml"
        path.write_text(text.replace("SPIN", str(spin)))
        out = tmp_path / f"tilt{spin}.nc"
        rc = main(["run", str(path), "-o", str(out)])
        err = capsys.readouterr().err.strip().splitlines()
        if rc == 2 and err and "clamp.lead = 'connector'" in err[-1]:
            assert len(err) == 1 and "enters the body" in err[0] and not out.exists()
            refused += 1
    assert refused >= 1  # the arm points up the tilted normal at spin 180 (into the body)
    with pytest.raises(UserInputError, match="enters the body by 0.0289 m"):
        config_from_dict(tomllib.loads(text.replace("SPIN", "180")))
    config_from_dict(tomllib.loads(text.replace("SPIN", "0")))  # and away from it at 0
