"""`gym.envs.toy_text.cliffwalking`: gymnasium's module of that name."""

from gymnasium.envs.toy_text.cliffwalking import *  # noqa: F403
