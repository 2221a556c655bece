"""`make`: classic `gym.make` on gymnasium 1.4."""

from __future__ import annotations

from typing import Any

import gymnasium

from . import events
from .adapter import ClassicEnv
from .envs import register_envs
from .ids import resolve_env_id
from .quiet import OUT_OF_DATE, quiet_gymnasium


def make(env_id: str, **kwargs: Any) -> ClassicEnv:
    """Make the environment a classic id names, with the classic API.

    The id resolves with `resolve_env_id`; the student's keyword arguments override the target's.
    `gymnasium.make` is looked up when called, never bound at import, so a recorder that replaces it
    sees every environment with the arguments actually used.

    Args:
        env_id: the classic id (`"Blackjack-v0"`) or any id registered with gymnasium.
        **kwargs: constructor or `gymnasium.make` arguments, passed on unchanged.

    Returns:
        The environment behind the classic API.

    Raises:
        UnknownEnvironmentError: the id is unknown, retired or never existed (see `resolve_env_id`).
    """
    target = resolve_env_id(env_id)
    register_envs()
    if target.note:
        events.record(
            events.RENAMED_ID,
            env_id,
            f"{env_id} was made as {_describe(target.gymnasium_id, target.kwargs)}: {target.note}",
        )
    # The sandbox's recorder identifies the requested id by finding this function's frame (local
    # `env_id`) as the direct caller of `gymnasium.make`: keep the call here, undelegated.
    with quiet_gymnasium(OUT_OF_DATE):
        env = gymnasium.make(target.gymnasium_id, **target.merged_kwargs(kwargs))
    return ClassicEnv(env, env_id)


def _describe(gymnasium_id: str, kwargs: dict[str, Any]) -> str:
    arguments = "".join(f", {name}={value!r}" for name, value in kwargs.items())
    return f"gymnasium.make({gymnasium_id!r}{arguments})"
