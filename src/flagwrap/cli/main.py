"""Entry point of the ``flagwrap`` command.

Each subcommand is a module of this package exposing ``add_arguments(parser)`` and
``run(args) -> int``, with its one-line help as the first line of its docstring. Heavy
imports stay inside ``run`` so that ``flagwrap --help`` is instant. Errors the user can fix
(bad config, missing file) are :class:`flagwrap.errors.UserInputError`: printed on one
line, exit code 2, never a traceback.
"""

from __future__ import annotations

import argparse
import importlib
import sys

# name on the command line -> module under flagwrap.cli
COMMANDS: dict[str, str] = {
    "run": "run",
    "theory": "theory",
    "triangulate": "triangulate",
    "viscosity": "viscosity",
    "density": "density",
    "bacteria": "bacteria",
    "analyze": "analyze",
    "snapshots": "snapshots",
    "movie": "movie",
    "export-vtk": "export_vtk",
    "figure": "figure",
    "critical": "critical",
    "stability": "stability",
    "sweep": "sweep",
}


class _Parser(argparse.ArgumentParser):
    """argparse with its errors on one line (``flagwrap CMD: error: ...``, exit 2) instead of
    the usage block followed by the error: every bad input is one line, whoever catches it."""

    def error(self, message):
        self.exit(2, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


def _load(name: str):
    return importlib.import_module(f"flagwrap.cli.{COMMANDS[name]}")


def build_parser() -> argparse.ArgumentParser:
    from flagwrap import __version__

    parser = _Parser(
        prog="flagwrap",
        description="Simulate and analyse the torque-induced buckling of a rotating elastic helix.",
    )
    parser.add_argument("--version", action="version", version=f"flagwrap {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name in COMMANDS:
        mod = _load(name)
        doc = (mod.__doc__ or "").strip().splitlines()
        # the module docstrings are laid out by hand (example lines, tables): keep their lines
        p = sub.add_parser(name, help=doc[0] if doc else "", description=(mod.__doc__ or ""),
                           formatter_class=argparse.RawDescriptionHelpFormatter)
        mod.add_arguments(p)
        p.set_defaults(_module=mod)
    return parser


def main(argv: list[str] | None = None) -> int:
    from flagwrap.errors import OutputWriteError, SimulationError, UserInputError

    parser = build_parser()
    args = parser.parse_args(argv)
    if getattr(args, "_module", None) is None:
        parser.print_help()
        return 2
    try:
        return int(args._module.run(args) or 0)
    except BrokenPipeError:  # `flagwrap ... | head`: the reader left; no traceback
        import os

        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0
    except OutputWriteError as exc:  # the work is done and kept elsewhere: not an input error
        print(f"flagwrap {args.command}: error: {exc}", file=sys.stderr)
        return 1
    except UserInputError as exc:
        print(f"flagwrap {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except SimulationError as exc:  # a result that is not one (ResultError) or a run that stopped
        print(f"flagwrap {args.command}: error: {exc}", file=sys.stderr)
        return 1


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
