"""`gym.logger`: classic gym's logger (`gym.logger.set_level(40)`) on top of gymnasium's."""

from __future__ import annotations

import gymnasium.logger
from gymnasium.logger import deprecation, error, warn

__all__ = [
    "DEBUG",
    "DISABLED",
    "ERROR",
    "INFO",
    "WARN",
    "debug",
    "deprecation",
    "error",
    "info",
    "set_level",
    "warn",
]

DEBUG = 10
INFO = 20
WARN = gymnasium.logger.WARN
ERROR = gymnasium.logger.ERROR
DISABLED = 50


def set_level(level: int) -> None:
    """Show only messages at `level` or above; gymnasium's own warnings obey it too."""
    gymnasium.logger.min_level = level


def debug(msg: str, *args: object) -> None:
    """Print a debug message if the level allows it, as classic gym did."""
    if gymnasium.logger.min_level <= DEBUG:
        print(f"DEBUG: {msg % args}")


def info(msg: str, *args: object) -> None:
    """Print an informational message if the level allows it, as classic gym did."""
    if gymnasium.logger.min_level <= INFO:
        print(f"INFO: {msg % args}")
