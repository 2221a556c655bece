"""`gym.envs.toy_text.hotter_colder` of classic gym: the compat layer's `HotterColderEnv`."""

from grader.compat.envs import HotterColderEnv

__all__ = ["HotterColderEnv"]
