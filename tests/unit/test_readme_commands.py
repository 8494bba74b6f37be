"""The README's command lines work after a wheel install, from a folder outside the repository.

What is checked, and what is not:

* fast (every run): each ``flagwrap ...`` line of the README's shell blocks is parsed by the
  real argument parser, its ``examples/NAME.toml`` replaced by the built-in case ``NAME`` (a
  wheel has no examples/ folder), from an empty folder; the config or sweep it names must
  resolve from the package's data, a synopsis line's options must exist, and the speeds the
  README points to must be in docs/speed.md, each once.
* slow (``-m slow``): a wheel is built and installed into a fresh virtual environment (system
  site-packages for numpy & co.; skipped when the wheel cannot be built, e.g. offline), and
  from an empty folder: the README's first run (the full Fig. 4(a) protocol, translated to the
  built-in case) within a time budget taken from docs/speed.md, ``analyze`` on its run file,
  ``--dry-run`` of every other ``run``, ``sweep`` and ``figure`` line, the ``stability`` and
  ``critical`` lines' configs resolved by the installed package (their computations are not
  run here), and ``--help`` of every other command the README names.
"""

from __future__ import annotations

import re
import shlex
import subprocess
import sys
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).parents[2]
README = ROOT / "README.md"
SPEED = ROOT / "docs" / "speed.md"


def readme_command_lines() -> list[str]:
    """Every ``flagwrap ...`` command of the README's shell code blocks (```bash and plain
    ```), comments dropped, ``a && flagwrap b`` split."""
    out = []
    for block in re.findall(r"```(?:bash)?\n(.*?)```", README.read_text(encoding="utf-8"), re.S):
        for line in block.splitlines():
            line = re.split(r"\s#\s", line)[0].strip()
            for part in line.split("&&"):
                part = part.strip()
                if part.startswith("flagwrap "):
                    out.append(part)
    return out


def as_built_in(tokens: list[str]) -> list[str]:
    """``examples/NAME.toml`` and ``examples/sweeps/NAME.toml`` -> ``NAME`` (the shipped copy)."""
    return [re.sub(r"^examples/(?:sweeps/)?([\w.-]+)\.toml$", r"\1", t) for t in tokens]


def drop_optional(tokens: list[str]) -> list[str]:
    """The tokens without the ``[--option VALUE]`` groups."""
    out, depth = [], 0
    for t in tokens:
        depth += t.count("[")
        if depth == 0:
            out.append(t)
        depth -= t.count("]")
    return out


def is_synopsis(tokens) -> bool:
    """A usage line with placeholders (CONFIG.toml, RUN.nc, DIR) or alternatives (a | b),
    outside its optional ``[...]`` parts."""
    return any(t == "|" or re.fullmatch(r"[A-Z][A-Z_]*(\.\w+)?", t)
               for t in drop_optional(tokens)[1:])


def concrete_commands() -> list[list[str]]:
    """The README's runnable lines (optional parts dropped), examples/ paths as case names."""
    cmds = [shlex.split(line) for line in readme_command_lines()]
    return [as_built_in(drop_optional(c)[1:]) for c in cmds if not is_synopsis(c)]


def readme_figures() -> list[str]:
    """The figure names of the README's ``flagwrap figure a | b | ...`` line."""
    for tokens in synopsis_lines():
        if tokens[1] == "figure":
            return [t for t in drop_optional(tokens)[2:] if t != "|"]
    return []


def synopsis_lines() -> list[list[str]]:
    return [shlex.split(line) for line in readme_command_lines()
            if is_synopsis(shlex.split(line))]


def test_the_readme_has_the_commands_this_test_expects():
    # the extraction is not vacuous: the quick start and the command-line block are found
    cmds = [" ".join(c) for c in concrete_commands()]
    assert "run fig4a -o out/fig4a.nc --figure out/fig4a.png" in cmds
    assert any(c.startswith("stability s_putrefaciens") for c in cmds)
    assert any(c.startswith("sweep fig5-quick") for c in cmds)
    assert len(cmds) >= 6 and len(synopsis_lines()) >= 5
    assert {"fig5", "hook"} <= set(readme_figures())


def test_every_readme_command_resolves_from_an_empty_folder(tmp_path, monkeypatch):
    from flagwrap.cli.main import build_parser
    from flagwrap.cli.run import load
    from flagwrap.io.config import load_config_or_case
    from flagwrap.sweep.spec import load_spec

    monkeypatch.chdir(tmp_path)  # no examples/ here, as after `pip install flagwrap`
    parser = build_parser()
    for argv in concrete_commands():
        args = parser.parse_args(argv)
        if args.command == "run":
            assert load(args).name
        elif args.command in ("stability", "critical"):
            if getattr(args, "sweep", False):
                assert load_spec(args.config).cases
            else:
                assert load_config_or_case(args.config).name
        elif args.command == "sweep":
            assert load_spec(args.spec).cases


def test_synopsis_lines_name_real_commands_and_options():
    from flagwrap.cli.figure import PLANS
    from flagwrap.cli.main import COMMANDS, build_parser

    parser = build_parser()
    subs = next(a for a in parser._actions if a.dest == "command").choices
    assert readme_figures() and set(readme_figures()) <= set(PLANS)
    for tokens in synopsis_lines():
        if tokens[1] == "figure":  # figure fig3 | fig4 | ...: names, checked above
            continue
        alts = [[]]
        for t in tokens[1:]:  # snapshots RUN.nc | movie RUN.nc ...: a lone | between commands
            if t == "|":
                alts.append([])
            else:
                alts[-1].append(t)
        for words in alts:
            name = words[0]
            assert name in COMMANDS, f"README: flagwrap {name} is not a command"
            known = {o for a in subs[name]._actions for o in a.option_strings}
            for w in words:
                opt = w.strip("[]")
                if opt.startswith("-") and opt != "--help":
                    assert opt in known, f"README: {opt} is not an option of flagwrap {name}"


def speed_claims() -> dict:
    """The headline speeds of docs/speed.md: row label -> (number, unit)."""
    rows = {}
    for line in SPEED.read_text(encoding="utf-8").splitlines():
        m = re.match(r"\|\s*(\w[\w-]*)\s*\|.*?\*\*([0-9.]+) (s|min)\*\*", line)
        if m:
            rows[m.group(1)] = (float(m.group(2)), m.group(3))
    return rows


def test_each_headline_speed_is_stated_once():
    # docs/speed.md holds each number (with its command and machine); the README and the other
    # pages point there instead of repeating (and drifting from) it
    claims = speed_claims()
    assert {"lab", "turning", "stability-sweep", "movie-frame", "tests"} <= set(claims)
    assert "docs/speed.md" in README.read_text(encoding="utf-8")
    pages = [README, *sorted((ROOT / "docs").glob("*.md"))]
    for key in ("lab", "turning", "stability-sweep", "movie-frame", "bifurcation"):
        value, unit = claims[key]
        needle = re.compile(rf"(?<![\d.]){re.escape(f'{value:g}')} {unit}\b")
        where = [p.name for p in pages if p != SPEED and needle.search(p.read_text(encoding="utf-8"))]
        assert not where, f"{key} = {value:g} {unit} is repeated in {where}: refer to docs/speed.md"


# ------------------------------------------------------------------------------------------
# slow: the same from a real wheel in a fresh virtual environment


def _clean_env(**extra) -> dict:
    """The environment without PYTHONPATH (which would import the checkout, not the wheel)."""
    import os

    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME")}
    return {**env, **extra}


@pytest.fixture(scope="module")
def wheel_env(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("wheel")
    build = subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "-q", "-w",
                            str(tmp / "dist"), str(ROOT)], capture_output=True, text=True)
    wheels = sorted((tmp / "dist").glob("flagwrap-*.whl"))
    if build.returncode != 0 or not wheels:
        pytest.skip(f"no wheel could be built here (offline?): {build.stderr.strip()[-300:]}")
    subprocess.run([sys.executable, "-m", "venv", "--system-site-packages", str(tmp / "venv")],
                   check=True, env=_clean_env())
    py = tmp / "venv" / "bin" / "python"
    subprocess.run([str(py), "-m", "pip", "install", "-q", "--no-deps", "--no-index",
                    str(wheels[0])], check=True, env=_clean_env())
    work = tmp / "work"  # outside the repository: no examples/, no src/
    work.mkdir()
    where = subprocess.run([str(py), "-c", "import flagwrap; print(flagwrap.__file__)"],
                           capture_output=True, text=True, cwd=work, check=True,
                           env=_clean_env()).stdout.strip()
    assert Path(where).is_relative_to(tmp / "venv"), f"the wheel's flagwrap is not the one imported: {where}"
    return py, tmp / "venv" / "bin" / "flagwrap", work


def _flagwrap(env, *argv, timeout=600):
    py, exe, work = env
    return subprocess.run([str(exe), *argv], capture_output=True, text=True, cwd=work,
                          timeout=timeout, env=_clean_env(MPLBACKEND="Agg"))


@pytest.mark.slow
def test_readme_from_a_wheel_install(wheel_env):
    py, exe, work = wheel_env
    cmds = concrete_commands()
    first = cmds[0]
    assert first[:2] == ["run", "fig4a"]
    # the README's first run, in full, against the lab-frame time docs/speed.md states; the
    # budget allows a shared, loaded machine (measured: 48 s idle, 146 s with a sweep on both
    # cores, against 28 s), start-up and compiling: it catches a run gone several times
    # slower or a hang, it is not a benchmark
    lab, unit = speed_claims()["lab"]
    budget = 6 * lab * (60 if unit == "min" else 1) + 180
    t0 = time.perf_counter()
    r = _flagwrap(wheel_env, *first, timeout=budget)
    took = time.perf_counter() - t0
    assert r.returncode == 0, r.stderr[-2000:]
    assert (work / "out" / "fig4a.nc").is_file() and (work / "out" / "fig4a.png").is_file()
    print(f"README first run from the wheel: {took:.1f} s (budget {budget:.0f} s)")
    r = _flagwrap(wheel_env, "analyze", "out/fig4a.nc")
    assert r.returncode == 0 and "summary stored in out/fig4a.nc" in r.stdout, r.stderr
    assert "stable" in r.stdout
    assert _flagwrap(wheel_env, "run", "--list-cases").stdout.count("\n") >= 17
    for argv in cmds[1:]:
        cmd = argv[0]
        if cmd in ("run", "sweep", "figure"):
            r = _flagwrap(wheel_env, *argv, "--dry-run")
        elif cmd in ("stability", "critical"):
            # resolved only: the README's stability lines take minutes (a bacterium, the Fig. 5
            # grid, the --far diagram, which tests/unit/test_bifurcation.py runs in-process)
            name = argv[1]
            code = (f"from flagwrap.sweep.spec import load_spec; load_spec({name!r})"
                    if "--sweep" in argv else
                    f"from flagwrap.io.config import load_config_or_case; load_config_or_case({name!r})")
            r = subprocess.run([str(py), "-c", code], capture_output=True, text=True, cwd=work,
                               env=_clean_env())
        else:
            r = _flagwrap(wheel_env, cmd, "--help")
        assert r.returncode == 0, f"{' '.join(argv)}: {r.stderr[-1000:]}"
    for name in readme_figures():  # flagwrap figure fig3 | fig4 | ... [--dry-run]
        r = _flagwrap(wheel_env, "figure", name, "--dry-run")
        assert r.returncode == 0, f"figure {name} --dry-run: {r.stderr[-1000:]}"
    from flagwrap.cli.main import COMMANDS

    for name in COMMANDS:  # every command the synopsis names starts from the wheel
        assert _flagwrap(wheel_env, name, "--help").returncode == 0, name
