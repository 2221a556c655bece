"""Replay many Blackjack episodes cheaply: gymnasium's own `BlackjackEnv`, no new Generator per episode.

A seeded `reset` of the scalar env builds a new `numpy.random.Generator` and then draws every card
with `Generator.choice(deck)`, which converts the deck to an array at each draw; together they
cost more than the student's whole game. Here the game logic stays gymnasium's: one unwrapped
`BlackjackEnv` plays every episode through its own `reset()` and `step()`, but its `np_random` is a
`SeededDraws` that returns, for each `choice(sequence)`, the element `Generator.choice` would return
(`grader.sandbox.batched.draws.SeededDraws`). `grader.sandbox.replay` re-checks every
batch against the real, seeded scalar env, which stays the authority for every mismatch.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable, Sequence
from typing import Any, SupportsFloat

import gymnasium
from gymnasium.envs.toy_text.blackjack import BlackjackEnv

from grader.sandbox.batched.draws import SeededDraws, seeded_draws
from grader.sandbox.batched.replayer import BatchedEpisode
from grader.sandbox.episode_log import EpisodeLog

ENV_IDS = frozenset({"Blackjack-v1"})
GAME_ARGUMENTS = frozenset({"natural", "sab"})


class BlackjackReplayer:
    """`BatchedReplayer` for `Blackjack-v1` with only `natural`/`sab` arguments (no time limit)."""

    def is_batchable(self, log: EpisodeLog) -> bool:
        """Blackjack with bool `natural`/`sab` only, no reset options, actions 0 or 1."""
        if log.env_id not in ENV_IDS or log.reset_options is not None or not log.actions:
            return False
        if not GAME_ARGUMENTS.issuperset(log.env_kwargs):
            return False
        if any(type(value) is not bool for value in log.env_kwargs.values()):
            return False
        return set(map(type, log.actions)) == {int} and set(log.actions) <= {0, 1}

    def replay(self, logs: Sequence[EpisodeLog]) -> list[BatchedEpisode]:
        """Replay Blackjack logs sharing `env_id` and `env_kwargs`, each from its own seed's card draws.

        Raises:
            TypeError: the registered env is not gymnasium's `BlackjackEnv`.
        """
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", DeprecationWarning)
            wrapped = gymnasium.make(logs[0].env_id, disable_env_checker=True, **logs[0].env_kwargs)
        blackjack = wrapped.unwrapped
        if type(blackjack) is not BlackjackEnv or wrapped.spec is None or wrapped.spec.max_episode_steps:
            wrapped.close()
            raise TypeError(f"{logs[0].env_id} is not gymnasium's BlackjackEnv without a time limit")
        try:
            draws = seeded_draws([log.reset_seed for log in logs])
            return [_play(blackjack, log, cards) for log, cards in zip(logs, draws, strict=True)]
        finally:
            wrapped.close()


def _play(blackjack: BlackjackEnv, log: EpisodeLog, cards: SeededDraws) -> BatchedEpisode:
    blackjack._np_random = cards  # type: ignore[assignment]  # duck-typed Generator
    observations: list[Any] = [blackjack.reset()[0]]
    rewards: list[float] = []
    terminated: list[bool] = []
    truncated: list[bool] = []
    step: Callable[[int], tuple[Any, SupportsFloat, bool, bool, dict[str, Any]]] = blackjack.step
    for action in log.actions:
        observation, reward, ended, cut, _ = step(action)
        observations.append(observation)
        rewards.append(float(reward))
        terminated.append(bool(ended))
        truncated.append(bool(cut))
        if ended or cut:
            break
    return BatchedEpisode(observations, rewards, terminated, truncated, terminated[-1] or truncated[-1])
