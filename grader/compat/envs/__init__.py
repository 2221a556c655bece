"""Environments removed from gym that the lab walks through, registered on demand."""

from __future__ import annotations

import gymnasium

from .guessing_game import GuessingGameEnv
from .nchain import NChainEnv

__all__ = ["GuessingGameEnv", "NChainEnv", "register_envs"]

_REGISTRATIONS = {
    "NChain-v0": (f"{NChainEnv.__module__}:NChainEnv", 1000),
    "GuessingGame-v0": (f"{GuessingGameEnv.__module__}:GuessingGameEnv", 200),
}


def register_envs() -> None:
    """Register `NChain-v0` and `GuessingGame-v0` with gymnasium; calling it again does nothing."""
    for env_id, (entry_point, max_episode_steps) in _REGISTRATIONS.items():
        if env_id not in gymnasium.envs.registry:
            gymnasium.register(id=env_id, entry_point=entry_point, max_episode_steps=max_episode_steps)
