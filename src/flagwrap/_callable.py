"""The module type of the packages whose names are also API functions.

``flagwrap.sweep``, ``flagwrap.bacteria`` and ``flagwrap.stability`` are packages and Python
API calls at once: importing a subpackage binds its name on ``flagwrap`` to the module, so
the module itself answers the call (``flagwrap.sweep(spec)`` runs
:func:`flagwrap.api.sweep`). This module imports nothing of flagwrap, so the packages that
use it do not import the API (which imports them) while they load.
"""

import sys
import types


class CallableModule(types.ModuleType):
    """A module that forwards a call to the API function of its own name."""

    def __call__(self, *args, **kwargs):
        from flagwrap import api

        return getattr(api, self.__name__.rsplit(".", 1)[1])(*args, **kwargs)


def make_callable(name: str) -> None:
    """Make the loaded module ``name`` a :class:`CallableModule`."""
    sys.modules[name].__class__ = CallableModule
