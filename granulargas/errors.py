"""Exceptions that the command line turns into one clear line and an exit code.

Everything a user can cause (bad config, missing file, a run leaving the model's
range) derives from :class:`UserError`; the CLI prints ``error: <message>`` and
exits with ``exit_code`` without a traceback. Programming errors stay ordinary
exceptions and keep their traceback.
"""


class UserError(Exception):
    """An error caused by input; printed as one line by the CLI (``<prefix>: <message>``)."""

    exit_code = 2
    prefix = "error"


class ConfigError(UserError):
    """Invalid configuration: message names file, key, value and what is allowed."""


class InputFileError(UserError):
    """A file given on the command line is missing, unreadable or not ours."""


class SimulationError(UserError):
    """The run cannot continue (inelastic collapse, table range, engine failure)."""

    exit_code = 3


class InelasticCollapseError(SimulationError):
    """The event rate diverges: constant restitution collapse.

    ``where`` says when and between which particles, without the cure, so that a
    caller can name the cure in its user's terms (a config run: the config key).
    """

    def __init__(self, message: str, where: str = ""):
        super().__init__(message)
        self.where = where


class TableRangeError(SimulationError):
    """An impact speed reached beyond the restitution table."""
