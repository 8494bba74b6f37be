"""The ``flagwrap`` command line: a registry of subcommand modules (see :mod:`flagwrap.cli.main`)."""
