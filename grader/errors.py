"""Errors raised by the grader's own code (never by a student's submission, whose failures are data)."""


class GraderError(Exception):
    """Root of every error raised by the `grader` package outside its subpackages."""


class ConfigError(GraderError, ValueError):
    """Raised when the assignment configuration file is missing, not TOML, or has an invalid field."""


class PlanError(GraderError, ValueError):
    """Raised when a check is asked to plan calls with a configuration of another problem."""
