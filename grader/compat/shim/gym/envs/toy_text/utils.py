"""`gym.envs.toy_text.utils`: gymnasium's module of that name."""

from gymnasium.envs.toy_text.utils import *  # noqa: F403
