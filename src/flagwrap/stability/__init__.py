"""Steady whirling states, their linear stability and the critical Machin number from it
(docs/stability.md): :mod:`.steady` (Newton in the turning frame), :mod:`.spectrum`
(eigenvalues), :mod:`.threshold` (continuation in M to the first loss of stability),
:mod:`.boundary` (a sweep's geometries)."""


def _callable():
    # ``flagwrap.stability(...)`` is the Python API's :func:`flagwrap.api.stability` (see
    # CallableModule): importing this package binds its name on ``flagwrap`` to the module
    import sys

    from flagwrap.api import CallableModule

    sys.modules[__name__].__class__ = CallableModule


_callable()
