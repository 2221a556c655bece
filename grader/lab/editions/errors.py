"""Errors of choosing an edition (both are configuration errors: what a person passed or wrote)."""

from grader.errors import ConfigError


class UnknownEdition(ConfigError):
    """Raised when `--edition` or a configuration's `edition = "..."` names no edition pack."""


class EditionConflict(ConfigError):
    """Raised when `--edition` and the configuration given with it grade different problems."""
