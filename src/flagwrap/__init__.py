"""flagwrap: torque-induced buckling of a rotating elastic helix beside a cell body.

Reproduces and extends Kataoka, Yoneda, Nakane & Wada, "Bacteria exploit torque-induced
buckling instability for flagellar wrapping" (the seed paper in ``shared/seeds``).

Data flows one way: parameters -> initial state -> stepper(forces, mobility) -> trajectory
-> analysis -> figures.
"""

__version__ = "0.1.0"

#: the Python API (flagwrap.api), one function per command, imported on first use
_API = ("load", "run", "RunResult", "analyze", "critical", "CriticalResult", "stability",
        "sweep", "figure", "bacteria")
__all__ = ["__version__", *_API]


def __getattr__(name):
    if name in ("sweep", "bacteria"):  # packages whose modules are callable (_callable.CallableModule)
        import importlib

        return importlib.import_module(f"flagwrap.{name}")
    if name in _API:
        from flagwrap import api

        return getattr(api, name)
    raise AttributeError(f"module 'flagwrap' has no attribute {name!r}")
