"""`gym.error`: gymnasium's errors under their classic name."""

from gymnasium.error import *  # noqa: F403
