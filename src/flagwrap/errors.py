"""Exceptions with a user-facing meaning."""


class UserInputError(ValueError):
    """A parameter, config file or input file the user can fix; the CLI exits with code 2."""


class SimulationError(RuntimeError):
    """A run that cannot continue (NaN, overlap, step size underflow); partial output is kept."""


class OutputWriteError(UserInputError):
    """A finished result could not be written where asked (disk full, folder gone); the
    message names where it was kept instead. Exit code 1 (the input was fine)."""
