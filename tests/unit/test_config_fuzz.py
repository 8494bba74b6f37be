"""Hostile configs: random keys, types and values give a valid Config or one UserInputError.

Oracle: the loader's contract (io/config.py, params.py): every problem with an input is a
:class:`~flagwrap.errors.UserInputError` before any work starts; nothing else may escape
(no ``TypeError``, ``OverflowError``, ``ZeroDivisionError``, ...), and the CLI turns it into
one line on stderr with exit code 2, never a traceback.
"""

from __future__ import annotations

import copy
import datetime
import subprocess
import sys

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from flagwrap.errors import UserInputError
from flagwrap.io.config import config_from_dict, load_config
from flagwrap.params import Config

BASE = {
    "name": "fuzz",
    "filament": {"length": 0.4, "helix_radius": 0.03, "turns": 2.0,
                 "cross_section_radius": 0.0015, "youngs_modulus": 1.5e6, "n_beads": 21},
    "fluid": {"viscosity": 1.1, "density": 1250.0},
    "body": {"radius_ratio": 0.6},
    "motor": {"machin": 100.0, "protocol": [{"direction": "ccw", "turns": 0.2},
                                            {"direction": "cw", "turns": 0.2}]},
    "clamp": {"lead": "kink"},
    "contact": {"range": 1.0, "strength": 1.0},
    "numerics": {"save_every": 0.05, "tol": 1e-3},
    "units": {"length": "m"},
}
SECTIONS = [k for k in BASE if isinstance(BASE[k], dict)]
KNOWN_KEYS = sorted({k for s in SECTIONS for k in BASE[s]} | {
    "pitch", "pitch_angle_deg", "poisson_ratio", "handedness", "hydrodynamic_radius",
    "stretch_stiffness", "frequency", "radius", "cylinder_length", "enabled", "lead_turns",
    "integrator", "hydrodynamics", "dt", "dt_min", "max_steps", "threads", "direction", "speed",
    "pressure", "viscosity", "density"})

# every kind of value TOML can hold, with the extremes
scalars = st.one_of(
    st.integers(min_value=-(2**63), max_value=2**63 - 1),
    st.integers(min_value=-3, max_value=300),
    st.floats(allow_nan=True, allow_infinity=True),
    st.floats(min_value=-1e3, max_value=1e3),
    st.sampled_from([0, 1, -1, 0.0, -0.0, 1e-308, 5e-324, 1e308, 2**63 - 1, 200_001, 10**9]),
    st.booleans(),
    st.text(max_size=8),
    st.sampled_from(["left", "right", "ccw", "cw", "stop", "euler", "ros2", "mm", "MPa", ""]),
    st.datetimes(min_value=datetime.datetime(1, 1, 1)),
    st.dates(),
)
values = st.recursive(scalars, lambda inner: st.one_of(
    st.lists(inner, max_size=3), st.dictionaries(st.text(max_size=6), inner, max_size=3)),
    max_leaves=6)
keys = st.one_of(st.sampled_from(KNOWN_KEYS), st.text(max_size=10))


@st.composite
def mutated_configs(draw):
    d = copy.deepcopy(BASE)
    for _ in range(draw(st.integers(1, 4))):
        op = draw(st.sampled_from(["set", "set", "set", "delete", "new_section", "replace_section",
                                   "protocol"]))
        sec = draw(st.sampled_from(SECTIONS))
        if op == "set":
            if isinstance(d.get(sec), dict):
                d[sec][draw(keys)] = draw(values)
        elif op == "delete":
            if isinstance(d.get(sec), dict) and d[sec]:
                d[sec].pop(draw(st.sampled_from(sorted(d[sec]))))
            elif draw(st.booleans()):
                d.pop(sec, None)
        elif op == "new_section":
            d[draw(keys)] = draw(values)
        elif op == "replace_section":
            d[sec] = draw(values)
        elif isinstance(d.get("motor"), dict):
            d["motor"]["protocol"] = draw(st.one_of(
                values, st.lists(st.dictionaries(keys, values, max_size=4), max_size=3)))
    return d


def _check(d):
    try:
        cfg = config_from_dict(d)
    except UserInputError as exc:
        msg = str(exc)
        assert msg and "\n" not in msg.strip(), msg
        return None
    assert isinstance(cfg, Config)
    return cfg


@settings(max_examples=400, deadline=None, suppress_health_check=list(HealthCheck))
@given(mutated_configs())
def test_fuzzed_dicts_give_config_or_user_error(d):
    _check(d)


@settings(max_examples=300, deadline=None, suppress_health_check=list(HealthCheck))
@given(sec=st.sampled_from(SECTIONS[:-1]), key=st.sampled_from(KNOWN_KEYS), value=values)
def test_every_known_key_any_value(sec, key, value):
    d = copy.deepcopy(BASE)
    d[sec][key] = value
    _check(d)


@settings(max_examples=150, deadline=None, suppress_health_check=list(HealthCheck))
@given(st.text(max_size=200))
def test_random_text_files(tmp_path_factory, text):
    p = tmp_path_factory.mktemp("fz") / "c.toml"
    p.write_bytes(text.encode("utf-8", errors="replace"))
    try:
        load_config(p)
    except UserInputError as exc:
        assert str(exc)


def test_binary_and_non_utf8_files(tmp_path):
    for blob in (b"\xff\xfe\x00bad", b"\x89HDF\r\n\x1a\n\x00\x00", bytes(range(256))):
        p = tmp_path / "b.toml"
        p.write_bytes(blob)
        with pytest.raises(UserInputError):
            load_config(p)


SAMPLES = {
    "malformed": "[filament\nlength = 0.4\n",
    "unknown_key": "[filament]\nlenght = 0.4\n[motor]\nmachin = 1\n",
    "wrong_type": "[filament]\nlength = 0.4\nhelix_radius = 0.03\nturns = 2\n"
                  "cross_section_radius = 0.0015\nyoungs_modulus = 1.5e6\nn_beads = \"many\"\n"
                  "[motor]\nmachin = 100\n",
    "nan": "[filament]\nlength = nan\nhelix_radius = 0.03\nturns = 2\n"
           "cross_section_radius = 0.0015\nyoungs_modulus = 1.5e6\n[motor]\nmachin = 100\n",
    "huge_duration": "[filament]\nlength = 0.4\nhelix_radius = 0.03\nturns = 2\n"
                     "cross_section_radius = 0.0015\nyoungs_modulus = 1.5e6\n[motor]\nmachin = 100\n"
                     "protocol = [{direction = \"cw\", turns = 1e12}]\n",
}


@pytest.mark.parametrize("name", sorted(SAMPLES))
def test_cli_exit_2_without_traceback(tmp_path, name):
    p = tmp_path / f"{name}.toml"
    p.write_text(SAMPLES[name])
    r = subprocess.run([sys.executable, "-m", "flagwrap.cli.main", "run", str(p), "--quiet",
                        "-o", str(tmp_path / "o.nc")], capture_output=True, text=True, timeout=120)
    assert r.returncode == 2, r.stderr
    assert "Traceback" not in r.stderr and "error:" in r.stderr
    assert len(r.stderr.strip().splitlines()) == 1
    assert not (tmp_path / "o.nc").exists()
