"""`gym.envs.toy_text.kellycoinflip` of classic gym: the compat layer's Kelly coinflip games."""

from grader.compat.envs import KellyCoinflipEnv, KellyCoinflipGeneralizedEnv

__all__ = ["KellyCoinflipEnv", "KellyCoinflipGeneralizedEnv"]
