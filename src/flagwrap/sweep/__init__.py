"""Parameter sweeps for the stability diagram (paper Fig. 5): spec, hashed store, Dask runner.

* :mod:`flagwrap.sweep.spec` — TOML sweep file -> dimensionless cases -> SI configs, case keys
* :mod:`flagwrap.sweep.store` — one run file + one atomic row file per case; the table
* :mod:`flagwrap.sweep.runner` — Dask (LocalCluster / scheduler address / synchronous), resume
* :mod:`flagwrap.sweep.boundary` — M_c per geometry from rows or from bisection results

See docs/sweeps.md.
"""

from flagwrap.sweep.spec import Case, SweepSpec, load_spec, resolve_geometry, spec_from_dict
from flagwrap.sweep.store import SweepStore

__all__ = ["Case", "SweepSpec", "SweepStore", "load_spec", "resolve_geometry", "spec_from_dict"]


def _callable():
    # ``flagwrap.sweep(...)`` is the Python API's :func:`flagwrap.api.sweep` (see CallableModule)
    import sys

    from flagwrap.api import CallableModule

    sys.modules[__name__].__class__ = CallableModule


_callable()
