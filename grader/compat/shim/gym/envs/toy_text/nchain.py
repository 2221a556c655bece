"""`gym.envs.toy_text.nchain` of classic gym: the compat layer's `NChainEnv`."""

from grader.compat.envs import NChainEnv

__all__ = ["NChainEnv"]
