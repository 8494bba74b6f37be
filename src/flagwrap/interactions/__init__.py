"""Interactions of the system (the interface: :mod:`flagwrap.interactions.base`): so far the
filament's self-contact (:mod:`flagwrap.interactions.self_contact`)."""
