"""Environments removed from gym that lab code uses: the lab's NChain and GuessingGame, and every other
toy-text game that classic gym shipped and the `gym_toytext` package re-registered for gym 0.26."""

from __future__ import annotations

import gymnasium

from .guessing_game import GuessingGameEnv
from .hotter_colder import HotterColderEnv
from .kelly_coinflip import KellyCoinflipEnv, KellyCoinflipGeneralizedEnv
from .nchain import NChainEnv
from .roulette import RouletteEnv

__all__ = [
    "TOY_TEXT_IDS",
    "GuessingGameEnv",
    "HotterColderEnv",
    "KellyCoinflipEnv",
    "KellyCoinflipGeneralizedEnv",
    "NChainEnv",
    "RouletteEnv",
    "register_envs",
]

# id -> (class, max_episode_steps): the registrations of `gym_toytext` 0.25 (and of classic gym before it).
_REGISTRATIONS: dict[str, tuple[type, int | None]] = {
    "GuessingGame-v0": (GuessingGameEnv, 200),
    "HotterColder-v0": (HotterColderEnv, 200),
    "KellyCoinflip-v0": (KellyCoinflipEnv, None),
    "KellyCoinflipGeneralized-v0": (KellyCoinflipGeneralizedEnv, None),
    "NChain-v0": (NChainEnv, 1000),
    "Roulette-v0": (RouletteEnv, 100),
}

TOY_TEXT_IDS = tuple(_REGISTRATIONS)
"""The ids `import gym_toytext` registers."""


def register_envs() -> None:
    """Register the toy-text ids (`TOY_TEXT_IDS`) with gymnasium; calling it again does nothing."""
    for env_id, (env_class, max_episode_steps) in _REGISTRATIONS.items():
        if env_id not in gymnasium.envs.registry:
            gymnasium.register(
                id=env_id,
                entry_point=f"{env_class.__module__}:{env_class.__name__}",
                max_episode_steps=max_episode_steps,
            )
