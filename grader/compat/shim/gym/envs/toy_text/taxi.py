"""`gym.envs.toy_text.taxi`: gymnasium's module of that name."""

from gymnasium.envs.toy_text.taxi import *  # noqa: F403
