"""Errors raised by the lab-compatibility layer."""

from __future__ import annotations

import gymnasium.error


class CompatError(Exception):
    """Root of every error raised by `grader.compat`."""


class UnknownEnvironmentError(CompatError, gymnasium.error.UnregisteredEnv):
    """Raised when an environment id is neither a lab id nor registered with gymnasium.

    It is also a `gymnasium.error.UnregisteredEnv` (hence a `gym.error.Error` for classic code), so
    code written against gym that catches its errors still does.
    """


class RetiredEnvironmentError(UnknownEnvironmentError):
    """Raised when an id names a version retired before the lab, or a version that never existed."""


class InvalidActionError(CompatError, ValueError):
    """Raised when an environment registered by the layer receives an action outside its action space."""


class UnsupportedRenderModeError(CompatError, ValueError):
    """Raised when `render(mode=...)` asks for a mode the environment cannot draw."""


class AmbiguousApiError(CompatError, TypeError):
    """Raised when code's lines expect both gym APIs (classic and 0.26) and no caller decides which."""
