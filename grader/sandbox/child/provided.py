"""The grader's own definitions a call may put in place of the submission's (`Call.provided`).

Edition rl1's `sarsa0` calls the module's `epsilon_decay`; a configuration that grades sarsa0 with the
grader's decay instead of the student's (so a wrong decay is counted only in its own problem) has the
child bind these for the duration of the call. The second lab's `policy_iteration` likewise calls the
evaluation and improvement steps by their edition's names (`compute_policy_v`/`extract_policy` to 2023,
`iter_policy_eval`/`policy_improvement` since 2024): the grader's are the lab's algorithms, iterative
evaluation from zeros until a sweep changes V by less than tol (so a start policy that never ends its
episodes at discount 1 still never converges) and the first best action. Stdlib and numpy only: the child
imports it.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from typing import Any

import numpy as np


def epsilon_decay(
    episode: int, N: int, epsilon_start: float = 1.0, epsilon_end: float = 1e-6, decay_type: str = "linear"
) -> float:
    """The lab's decay: episode i (1-based) of N gets `start - (i - 1) * (start - end) / N` (or "exp")."""
    if decay_type == "exp":
        return float(epsilon_start * (epsilon_end / epsilon_start) ** (episode / N))
    return epsilon_start - (episode - 1) * (epsilon_start - epsilon_end) / N


Table = Mapping[int, Mapping[int, Sequence[tuple[float, int, float, bool]]]]


def policy_improvement(P: Table, nS: int, nA: int, V: Any, beta: float = 1.0) -> np.ndarray:
    """The greedy policy for V: in each state the first action of best `sum p * (r + beta * V[s'])`."""
    values = np.asarray(V, dtype=np.float64).reshape(-1)
    look = np.zeros((nS, nA))
    for state in range(nS):
        for action in range(nA):
            for probability, next_state, reward, _ in P[state][action]:
                look[state, action] += probability * (reward + beta * values[next_state])
    return np.argmax(look, axis=1).astype(np.int64)


def iter_policy_eval(
    P: Table, nS: int, nA: int, policy: Any, beta: float = 1.0, tol: float = 1e-8
) -> np.ndarray:
    """The policy's values: sweeps of its own Bellman equation from zeros until a sweep changes V by < tol."""
    actions = np.asarray(policy).reshape(-1).astype(np.int64)
    values = np.zeros(nS)
    while True:
        updated = np.zeros(nS)
        for state in range(nS):
            for probability, next_state, reward, _ in P[state][int(actions[state])]:
                updated[state] += probability * (reward + beta * values[next_state])
        change = float(np.max(np.abs(updated - values)))
        values = updated
        if change < tol:
            return values


PROVIDED: dict[str, Callable[..., Any]] = {
    "epsilon_decay": epsilon_decay,
    "policy_improvement": policy_improvement,
    "extract_policy": policy_improvement,
    "iter_policy_eval": iter_policy_eval,
    "compute_policy_v": iter_policy_eval,
}
"""The names a call may provide, and the grader's definition of each."""
