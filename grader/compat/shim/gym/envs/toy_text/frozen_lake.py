"""`gym.envs.toy_text.frozen_lake`: gymnasium's module of that name."""

from gymnasium.envs.toy_text.frozen_lake import *  # noqa: F403
