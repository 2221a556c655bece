"""`gym_toytext`: the toy-text games gym 0.26 dropped, registered as the PyPI package registers them.

Provided by gymgrade (nothing is installed): importing it registers `GuessingGame-v0`, `HotterColder-v0`,
`KellyCoinflip-v0`, `KellyCoinflipGeneralized-v0`, `NChain-v0` and `Roulette-v0` and exposes the package's
class names. Only code run through `grader.compat` imports this module.
"""

from grader.compat.envs import (
    GuessingGameEnv,
    HotterColderEnv,
    KellyCoinflipEnv,
    KellyCoinflipGeneralizedEnv,
    NChainEnv,
    RouletteEnv,
    register_envs,
)

GuessingGame = GuessingGameEnv
HotterColder = HotterColderEnv

__version__ = "0.25.0+gymgrade.compat"

__all__ = [
    "GuessingGame",
    "HotterColder",
    "KellyCoinflipEnv",
    "KellyCoinflipGeneralizedEnv",
    "NChainEnv",
    "RouletteEnv",
]

register_envs()
