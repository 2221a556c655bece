"""`gym.spaces`: gymnasium's spaces under their classic name."""

from gymnasium.spaces import *  # noqa: F403
from gymnasium.spaces import __all__  # noqa: F401
