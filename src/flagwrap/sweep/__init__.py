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


# ``flagwrap.sweep(...)`` is the Python API's :func:`flagwrap.api.sweep`
# (:class:`flagwrap._callable.CallableModule`)
from flagwrap._callable import make_callable  # noqa: E402

make_callable(__name__)
