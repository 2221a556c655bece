"""The helper module the second lab hands out (2024 and later), provided by gymgrade.

Students import it as `model_free_RL` (the template) or `model_free_rl` (the 2024 lab text); both shim
modules (`shim/model_free_RL.py`, `shim/model_free_rl/`) re-export these functions.

The lab's `model_comparison` trains a Q-table with `run_qlearn` on slippery 8x8 FrozenLake, which saves it
as `q_table.npy` in the working directory, and plays it with `run_simulation_table`, which loads it from
there. Students do not hand this module in; the grader puts it on `sys.path` and runs every grading in a
working directory of its own, so one student's table is never another's.

Restated from the lab's description (same names, parameters and defaults, same file). Its randomness comes
from the `random` module (exploration and random actions) and from resets seeded by it, so a grading's seed
fixes a training run. An episode ends when the env says terminated or truncated: a learned table can trap
the walker (up along the top row), and on `gym.make`'s env the time limit then ends the episode.
"""

from __future__ import annotations

import random
from pathlib import Path
from typing import Any

import numpy as np
from gymnasium.envs.toy_text.frozen_lake import FrozenLakeEnv
from gymnasium.wrappers import TimeLimit

TRAINING_STEPS = 100
"""The time limit of the training env: `gym.make('FrozenLake-v1', ...)`'s registered 100 steps."""
Q_TABLE_FILE = "q_table.npy"
"""Where `run_qlearn` saves the table and `run_simulation_table` reads it: the working directory."""


def epsilon_decay(
    episode: int, N: int, epsilon_start: float = 1.0, epsilon_end: float = 1e-6, decay_type: str = "linear"
) -> float:
    """The exploration rate of episode `episode` (counted from 1) of N, decayed linearly or exponentially.

    Raises:
        ValueError: `decay_type` is neither 'linear' nor 'exp'.
    """
    kind = decay_type.lower()
    if kind == "linear":
        return epsilon_start - (epsilon_start - epsilon_end) * (episode - 1) / N
    if kind == "exp":
        return float(epsilon_start * (epsilon_end / epsilon_start) ** (episode / N))
    raise ValueError(f"decay_type is 'linear' or 'exp' (exponential), not {decay_type!r}")


def run_qlearn(
    env: str,
    alpha: float = 0.1,
    gamma: float = 0.6,
    epsilon: float = 0.1,
    N: int = 70_000,
    decay: bool = False,
    decay_type: str = "linear",
) -> None:
    """Train a Q-table by Q-learning on slippery 8x8 FrozenLake and save it as `q_table.npy` here.

    Args:
        env: the environment's name (the lab passes 'FrozenLake-v1'; the 8x8 slippery map is always used).
        alpha: learning rate.
        gamma: discount of the update's target.
        epsilon: exploration rate when `decay` is off.
        N: episodes to train.
        decay: decay the exploration rate over the episodes with `epsilon_decay`.
        decay_type: 'linear' or 'exp'.
    """
    # The training episodes are the helper's, not the student's: the env is built without gym.make, so a
    # sandbox's recorder neither logs nor counts them (70 000 episodes; only the played ones are graded).
    # The same game as gym.make(env, map_name="8x8", is_slippery=True): its 100-step limit included.
    lake = TimeLimit(FrozenLakeEnv(desc=None, map_name="8x8", is_slippery=True), TRAINING_STEPS)
    n_actions = int(lake.action_space.n)  # type: ignore[attr-defined]
    table = np.zeros((int(lake.observation_space.n), n_actions))  # type: ignore[attr-defined]
    lake.reset(seed=random.randrange(2**32))
    for episode in range(1, N + 1):
        rate = epsilon_decay(episode, N, decay_type=decay_type) if decay else epsilon
        state, _ = lake.reset()
        done = False
        while not done:
            action = random.randrange(n_actions) if random.random() < rate else int(np.argmax(table[state]))
            next_state, reward, terminated, truncated, _ = lake.step(action)
            target = float(reward) + gamma * np.max(table[next_state])
            table[state, action] += alpha * (target - table[state, action])
            state = next_state
            done = terminated or truncated
    lake.close()
    np.save(Path.cwd() / Q_TABLE_FILE, table)


def run_simulation_table(env: Any, beta: float = 1.0) -> float:
    """Play one episode greedily on the saved `q_table.npy`; return `sum beta**k * r_k` from k = 0.

    Args:
        env: a FrozenLake environment (gymnasium's API), reset here and left open.
        beta: the discount factor.
    """
    table = np.load(Path.cwd() / Q_TABLE_FILE)
    state, _ = env.reset()
    total, weight, done = 0.0, 1.0, False
    while not done:
        state, reward, terminated, truncated, _ = env.step(int(np.argmax(table[state])))
        total += weight * float(reward)
        weight *= beta
        done = terminated or truncated
    return total
