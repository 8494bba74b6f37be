"""Flagellar-wrapping bacteria on the stability diagram (SI, "Parameter values of ...")."""

from flagwrap.bacteria.species import (
    Provenance,
    Species,
    default_species,
    format_table,
    load_species_file,
    parse_species,
)

__all__ = ["Provenance", "Species", "default_species", "format_table", "load_species_file", "parse_species"]


def _callable():
    # ``flagwrap.bacteria(...)`` is the Python API's :func:`flagwrap.api.bacteria` (see CallableModule)
    import sys

    from flagwrap.api import CallableModule

    sys.modules[__name__].__class__ = CallableModule


_callable()
