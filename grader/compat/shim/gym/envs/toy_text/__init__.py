"""`gym.envs.toy_text`: the toy-text environments under the paths gym (classic and 0.26) gave them.

gym 0.26's four (`BlackjackEnv`, `CliffWalkingEnv`, `FrozenLakeEnv`, `TaxiEnv`) are gymnasium's own
classes; the games classic gym also shipped here are the compat layer's (see `grader.compat.envs`).
"""

from gymnasium.envs.toy_text import BlackjackEnv, CliffWalkingEnv, FrozenLakeEnv, TaxiEnv

from grader.compat.envs import (
    GuessingGameEnv,
    HotterColderEnv,
    KellyCoinflipEnv,
    KellyCoinflipGeneralizedEnv,
    NChainEnv,
    RouletteEnv,
)

__all__ = [
    "BlackjackEnv",
    "CliffWalkingEnv",
    "FrozenLakeEnv",
    "GuessingGameEnv",
    "HotterColderEnv",
    "KellyCoinflipEnv",
    "KellyCoinflipGeneralizedEnv",
    "NChainEnv",
    "RouletteEnv",
    "TaxiEnv",
]
