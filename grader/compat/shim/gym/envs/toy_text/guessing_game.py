"""`gym.envs.toy_text.guessing_game` of classic gym: the compat layer's `GuessingGameEnv`."""

from grader.compat.envs import GuessingGameEnv

__all__ = ["GuessingGameEnv"]
