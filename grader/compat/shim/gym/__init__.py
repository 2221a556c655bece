"""`gym` with the classic API the OpenGym AI lab was written for, provided by gymgrade on gymnasium 1.4.

Only code run through `grader.compat` (its shim directory first on `sys.path`) imports this module.
"""

from gymnasium import (
    ActionWrapper,
    Env,
    ObservationWrapper,
    RewardWrapper,
    Space,
    Wrapper,
    register,
)

from grader.compat.envs import register_envs
from grader.compat.make import make

from . import envs, error, logger, spaces, wrappers

__version__ = "0.17.3+gymgrade.compat"

__all__ = [
    "ActionWrapper",
    "Env",
    "ObservationWrapper",
    "RewardWrapper",
    "Space",
    "Wrapper",
    "envs",
    "error",
    "logger",
    "make",
    "register",
    "spaces",
    "wrappers",
]

register_envs()
