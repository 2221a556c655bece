"""Replay many Taxi episodes at once from gymnasium's own transition table.

`TaxiEnv.step` looks up `P[state][action]`, a list of `(probability, next_state, reward,
terminated)`; with default arguments (no rain, no fickle passenger) every list holds one transition
of probability 1.0, so the random draw `step` makes cannot change the outcome and an episode is
a chain of table lookups. Here the parent's own env provides the table (checked to be deterministic)
and the initial-state distribution, sampled as its `reset(seed)` does (`seeded_draws`); all episodes
advance in lockstep, one array lookup per step. `grader.sandbox.replay` checks every batch against
the scalar env, which stays the authority for every mismatch.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import gymnasium
import numpy as np
from gymnasium.envs.toy_text.taxi import TaxiEnv

from grader.sandbox.batched.draws import seeded_draws
from grader.sandbox.batched.replayer import BatchedEpisode, int_actions, lockstep, plain_arguments
from grader.sandbox.episode_log import EpisodeLog

ENV_IDS = frozenset({"Taxi-v4"})
ACTIONS = 6
MAX_HORIZON = 10_000_000
"""Longest time limit a Taxi batch accepts: sarsa0's env has one beyond its call's step budget (400 001
steps). A batch is as long as its longest logged episode, whose steps the call's budget bounds, and a
Taxi step takes 25 bytes of arrays, so the time limit itself costs nothing."""


class TaxiReplayer:
    """`BatchedReplayer` for `Taxi-v4` with default arguments (optionally `max_episode_steps`)."""

    def is_batchable(self, log: EpisodeLog) -> bool:
        """Plain Taxi arguments, no reset options, actions 0 to 5."""
        return plain_arguments(log, ENV_IDS, MAX_HORIZON) and int_actions(log.actions, ACTIONS)

    def replay(self, logs: Sequence[EpisodeLog]) -> list[BatchedEpisode]:
        """Replay Taxi logs sharing `env_id` and `env_kwargs` in lockstep.

        Raises:
            TypeError: the registered env is not gymnasium's deterministic `TaxiEnv`.
        """
        return lockstep(logs, TaxiEnv, _advance)


def _advance(
    scalar: gymnasium.Env[Any, Any], taxi: TaxiEnv, logs: Sequence[EpisodeLog], actions: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    next_states, rewards, terminal = _tables(taxi)
    observations = np.empty((actions.shape[0] + 1, len(logs)), dtype=np.int64)
    observations[0] = _initial_states(taxi, logs)
    for step in range(actions.shape[0]):
        observations[step + 1] = next_states[observations[step], actions[step]]
    before = observations[:-1]
    return observations, rewards[before, actions], terminal[before, actions]


def _initial_states(taxi: TaxiEnv, logs: Sequence[EpisodeLog]) -> np.ndarray:
    """What `TaxiEnv.reset(seed)` draws: `categorical_sample(initial_state_distrib, np_random)`.

    That is `argmax(cumsum(distribution) > np_random.random())`, the first draw of each seed's generator.
    """
    cumulative = np.cumsum(np.asarray(taxi.initial_state_distrib))
    uniforms = np.array([draws.random() for draws in seeded_draws([log.reset_seed for log in logs])])
    states: np.ndarray = np.argmax(cumulative[None, :] > uniforms[:, None], axis=1).astype(np.int64)
    return states


def _tables(taxi: TaxiEnv) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    states = len(taxi.P)
    next_states = np.empty((states, ACTIONS), dtype=np.int64)
    rewards = np.empty((states, ACTIONS), dtype=np.float64)
    terminal = np.empty((states, ACTIONS), dtype=np.bool_)
    for state, by_action in taxi.P.items():
        for action, transitions in by_action.items():
            if len(transitions) != 1 or transitions[0][0] != 1.0:
                raise TypeError(f"Taxi state {state}, action {action} is not deterministic: {transitions}")
            _, next_states[state, action], rewards[state, action], terminal[state, action] = transitions[0]
    return next_states, rewards, terminal
