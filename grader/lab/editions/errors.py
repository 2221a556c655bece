"""Errors of choosing a lab and an edition (configuration errors: what a person passed or wrote)."""

from grader.errors import ConfigError


class UnknownEdition(ConfigError):
    """Raised when `--edition` or a configuration's `edition = "..."` names no edition pack."""


class EditionConflict(ConfigError):
    """Raised when `--edition` and the configuration given with it grade different problems."""


class UnknownLab(ConfigError):
    """Raised when `--lab`, `GYMGRADE_LAB` or a configuration's `lab = "..."` names no lab."""


class LabConflict(ConfigError):
    """Raised when an edition named (flag, setting or configuration) is not an edition of the lab named."""
