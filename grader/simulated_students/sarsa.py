"""Simulated `sarsa0(env, alpha, gamma, epsilon, N, decay)` students (edition rl1): honest ones and mistakes.

Each is called as ``function(lab, env, alpha, gamma, epsilon, N, decay)`` by
`grader.simulated_students.simulation`, `env` being what the sandbox passes: the environment's name first
(`"Taxi-v3"`). Template-shaped learners begin as the course's template does, ``env = gym.make(env)``
(`lab.make`, logged like the sandbox's recorder); an object-form learner (`takes="object"`) uses `env` as an
env, fails on the name and is called again with an env object, as in the sandbox. They draw their randomness
from `lab.random` and the env's action space.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from grader.simulated_students.simulation import Lab


def epsilon_decay(lab: Lab, episode: int, n: int, start: float = 1.0, end: float = 1e-6) -> float:
    """The lab's linear decay."""
    return start - (episode - 1) * (start - end) / n


def _env(lab: Lab, env: Any, takes: str) -> Any:
    """The env a learner plays: `gym.make(env)` for the template's name, else `env` as it is."""
    return lab.make(env) if takes == "name" else env


def _first_argmax(row: Any, lab: Lab) -> int:
    return int(np.argmax(row))


def _random_argmax(row: Any, lab: Lab) -> int:
    best = np.flatnonzero(row == row.max())
    return int(best[lab.random.randrange(len(best))])


def learner(
    *,
    target: str = "sarsa",
    alpha_used: bool = True,
    gamma_used: bool = True,
    end_update: bool = True,
    choose_from: str = "next",
    explore: bool = True,
    decays: bool = True,
    argmax: Callable[[Any, Lab], int] = _first_argmax,
    stop_on_truncated: bool = False,
    returns: str = "pair",
    fixed: tuple[float, float] | None = None,
    penalty_offset: int = 0,
    runs: int = 1,
    keeps_first_table: bool = False,
    schedule: Callable[..., float] = epsilon_decay,
    dtype: Any = np.float64,
    takes: str = "name",
) -> Callable[..., Any]:
    """A SARSA(0) learner on the lab's skeleton, with one of the typical departures switched on."""
    kept: list[Any] = []

    def sarsa0(
        lab: Lab, env_argument: Any, alpha: float, gamma: float, epsilon: float, n: int, decay: bool
    ) -> Any:
        if fixed is not None:
            alpha, gamma = fixed
        env = _env(lab, env_argument, takes)
        for _ in range(runs):
            q_table = np.zeros((env.observation_space.n, env.action_space.n), dtype=dtype)
            penalties = 0

            def choose(state: int, rate: float, table: Any = q_table) -> int:
                if explore and lab.random.uniform(0, 1) < rate:
                    return int(env.action_space.sample())
                return argmax(table[state], lab)

            for episode in range(1, n + 1):
                rate = schedule(lab, episode, n) if decay and decays else epsilon
                state, _ = env.reset()
                action = choose(state, rate)
                done = False
                while not done:
                    next_state, reward, terminated, truncated, _ = env.step(action)
                    if target == "taken":
                        q_table[state, action] += alpha * (
                            reward + gamma * q_table[next_state, action] - q_table[state, action]
                        )
                    next_action = choose(next_state if choose_from == "next" else state, rate)
                    if target == "max":
                        bootstrap = np.max(q_table[next_state])
                    else:
                        bootstrap = q_table[next_state, next_action]
                    value = reward + (gamma if gamma_used else 1.0) * bootstrap
                    done = terminated or (stop_on_truncated and truncated)
                    if target != "taken" and (end_update or not terminated):
                        if alpha_used:
                            q_table[state, action] = (1 - alpha) * q_table[state, action] + alpha * value
                        else:
                            q_table[state, action] = value
                    penalties += reward == -10
                    state, action = next_state, next_action
        if keeps_first_table:
            kept.append(q_table)
            q_table = kept[0]
        if returns == "table":
            return q_table
        if returns == "lists":
            return q_table.tolist()
        return q_table, penalties + penalty_offset

    return sarsa0


HONEST: dict[str, Callable[..., Any]] = {
    "lab_loop": learner(),
    "table_only": learner(returns="table"),
    "random_ties": learner(argmax=_random_argmax),
    "stops_on_truncated": learner(stop_on_truncated=True),
    "float32_table": learner(dtype=np.float32),
    "float32_lists": learner(dtype=np.float32, returns="lists", argmax=_random_argmax),
    "object_form": learner(takes="object"),
}
"""Honest learners, template-shaped (`env = gym.make(env)` from the name): the lab's loop, the table alone
returned, ties broken at random, a stop on truncated, a float32 table (as an array, and as lists); and one
changed to take an env object (called again with one after failing on the name)."""

MISTAKES: dict[str, tuple[Callable[..., Any], str]] = {
    "q_learning": (learner(target="max"), "which is Q-learning"),
    "next_action_after_update": (learner(target="taken"), "the next action was chosen after the update"),
    "next_action_from_state": (learner(choose_from="state"), "choose the next action from next_state"),
    "missing_alpha": (learner(alpha_used=False), "instead of moving it by alpha"),
    "missing_gamma": (learner(gamma_used=False), "did not discount"),
    "no_end_update": (learner(end_update=False), "skips the update of the last step"),
    "default_parameters": (learner(fixed=(0.1, 0.6)), "alpha=0.1 and gamma=0.6"),
    "trains_twice": (learner(runs=2), "episode(s); N="),
    "table_of_another_run": (learner(keeps_first_table=True), "nor any typical variant"),
    "never_explores": (learner(explore=False), "you explored less than epsilon asks"),
    "ignores_decay": (learner(decays=False), "less than the decayed schedule"),
    "wrong_penalties": (learner(penalty_offset=1), "penalties"),
    "float32_q_learning": (learner(target="max", dtype=np.float32), "which is Q-learning"),
    "float32_missing_gamma": (learner(gamma_used=False, dtype=np.float32), "did not discount"),
}
"""Typical sarsa0 mistakes: (the learner, words its feedback must contain)."""
