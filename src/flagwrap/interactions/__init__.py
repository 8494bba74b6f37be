"""Interactions between the parts of the system (issue 15's layout): so far the filament's
self-contact (:mod:`flagwrap.interactions.self_contact`)."""
