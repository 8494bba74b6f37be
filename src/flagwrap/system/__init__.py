"""The assembled system's bookkeeping (issue 15): :mod:`flagwrap.system.layout`."""
