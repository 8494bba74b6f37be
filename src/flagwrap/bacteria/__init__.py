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


# ``flagwrap.bacteria(...)`` is the Python API's :func:`flagwrap.api.bacteria`
# (:class:`flagwrap._callable.CallableModule`)
from flagwrap._callable import make_callable  # noqa: E402

make_callable(__name__)
