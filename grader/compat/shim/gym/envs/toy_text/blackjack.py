"""`gym.envs.toy_text.blackjack`: gymnasium's module of that name."""

from gymnasium.envs.toy_text.blackjack import *  # noqa: F403
