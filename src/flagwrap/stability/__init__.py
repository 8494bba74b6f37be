"""Steady whirling states, their linear stability and the critical Machin number from it
(docs/stability.md): :mod:`.steady` (Newton in the turning frame), :mod:`.spectrum`
(eigenvalues), :mod:`.threshold` (continuation in M to the first loss of stability),
:mod:`.boundary` (a sweep's geometries)."""


# ``flagwrap.stability(...)`` is the Python API's :func:`flagwrap.api.stability`
# (:class:`flagwrap._callable.CallableModule`)
from flagwrap._callable import make_callable  # noqa: E402

make_callable(__name__)
