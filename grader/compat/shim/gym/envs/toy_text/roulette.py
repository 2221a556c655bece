"""`gym.envs.toy_text.roulette` of classic gym: the compat layer's `RouletteEnv`."""

from grader.compat.envs import RouletteEnv

__all__ = ["RouletteEnv"]
