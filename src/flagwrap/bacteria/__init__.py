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
