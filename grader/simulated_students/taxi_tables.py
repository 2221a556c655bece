"""Simulated `taxi(q_table, q_table_decay)` students (edition rl1): an honest one and typical mistakes."""

from __future__ import annotations

from typing import Any

import numpy as np

from grader.simulated_students.simulation import Lab

EPISODES = 1000


def _play(
    lab: Lab, table: Any, episodes: int, *, random_play: bool = False, final_only: bool = False
) -> float:
    env = lab.make("Taxi-v3")
    totals = []
    for _ in range(episodes):
        state, _ = env.reset()
        total, reward, done = 0.0, 0.0, False
        while not done:
            action = int(env.action_space.sample()) if random_play else int(np.argmax(table[state]))
            state, reward, terminated, truncated, _ = env.step(action)
            total += reward
            done = terminated or truncated
        totals.append(reward if final_only else total)
    return float(np.mean(totals))


def honest(lab: Lab, q_table: Any, q_table_decay: Any) -> tuple[float, float]:
    """The lab's taxi: 1 000 greedy episodes with each table, the two mean total rewards."""
    return _play(lab, q_table, EPISODES), _play(lab, q_table_decay, EPISODES)


def swapped(lab: Lab, q_table: Any, q_table_decay: Any) -> tuple[float, float]:
    first, second = _play(lab, q_table, EPISODES), _play(lab, q_table_decay, EPISODES)
    return second, first


def random_play(lab: Lab, q_table: Any, q_table_decay: Any) -> tuple[float, float]:
    return _play(lab, q_table, EPISODES, random_play=True), _play(
        lab, q_table_decay, EPISODES, random_play=True
    )


def single_episode(lab: Lab, q_table: Any, q_table_decay: Any) -> tuple[float, float]:
    return _play(lab, q_table, 1), _play(lab, q_table_decay, 1)


def one_table_twice(lab: Lab, q_table: Any, q_table_decay: Any) -> tuple[float, float]:
    return _play(lab, q_table, EPISODES), _play(lab, q_table, EPISODES)


def final_reward(lab: Lab, q_table: Any, q_table_decay: Any) -> tuple[float, float]:
    return _play(lab, q_table, EPISODES, final_only=True), _play(
        lab, q_table_decay, EPISODES, final_only=True
    )


MISTAKES: dict[str, tuple[Any, str]] = {
    "swapped": (swapped, "the means are swapped"),
    "random_play": (random_play, "as in random play"),
    "single_episode": (single_episode, "a single episode per table"),
    "one_table_twice": (one_table_twice, "argmax(q_table_decay["),
    "final_reward": (final_reward, "no split of your 2000 replayed episodes"),
}
"""Mistakes: (the function, words its feedback must contain). Each must fail."""
