"""The grader's own definitions a call may put in place of the submission's (`Call.provided`).

Edition rl1's `sarsa0` calls the module's `epsilon_decay`; a configuration that grades sarsa0 with the
grader's decay instead of the student's (so a wrong decay is counted only in its own problem) has the
child bind these for the duration of the call. The second lab's `policy_iteration` likewise calls the
evaluation and improvement steps by their edition's names (`compute_policy_v`/`extract_policy` to 2023,
`iter_policy_eval`/`policy_improvement` since 2024): the grader's are the lab's algorithms, iterative
evaluation from zeros until a sweep changes V by less than tol (so a start policy that never ends its
episodes at discount 1 still never converges) and the first best action. Its `frozen_lake` calls the
solvers and `run_simulation`: the lab's value iteration, policy iteration (from the all-ones start of the
2023 texts) and one episode of a policy, discounted from k = 0, in the env the caller made and reset here.
They are bound only for a second reading, after the student's own functions gave a verdict short of full
marks (`grader.lab.checks.base.SecondReading`). Stdlib and numpy only: the child imports it.
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


def policy_improvement(
    P: Table, nS: int, nA: int, V: Any, beta: float = 1.0, *_: Any, **__: Any
) -> np.ndarray:
    """The greedy policy for V: in each state the first action of best `sum p * (r + beta * V[s'])`.

    The parameters are the template's (2024 on); arguments a student's own version took beyond them are
    accepted and unused, so a call written for that version still reaches the lab's algorithm.
    """
    values = np.asarray(V, dtype=np.float64).reshape(-1)
    look = np.zeros((nS, nA))
    for state in range(nS):
        for action in range(nA):
            for probability, next_state, reward, _terminal in P[state][action]:
                look[state, action] += probability * (reward + beta * values[next_state])
    greedy: np.ndarray = np.argmax(look, axis=1).astype(np.int64)
    return greedy


def extract_policy(P: Table, nS: int, nA: int, v: Any, beta: float = 1.0, *_: Any, **__: Any) -> np.ndarray:
    """`policy_improvement` under the 2018-2023 name and parameters (`v`)."""
    return policy_improvement(P, nS, nA, v, beta)


def iter_policy_eval(
    P: Table, nS: int, nA: int, policy: Any, beta: float = 1.0, tol: float = 1e-8, *_: Any, **__: Any
) -> np.ndarray:
    """The policy's values: sweeps of its own Bellman equation from zeros until a sweep changes V by < tol.

    Same parameters under the 2018-2023 name, `compute_policy_v`; extra arguments are accepted and unused.
    """
    actions = np.asarray(policy).reshape(-1).astype(np.int64)
    values = np.zeros(nS)
    while True:
        updated = np.zeros(nS)
        for state in range(nS):
            for probability, next_state, reward, _terminal in P[state][int(actions[state])]:
                updated[state] += probability * (reward + beta * values[next_state])
        change = float(np.max(np.abs(updated - values)))
        values = updated
        if change < tol:
            return values


def value_iteration(
    P: Table, nS: int, nA: int, beta: float = 1.0, tol: float = 1e-8, maxiter: int = 3000, *_: Any, **__: Any
) -> tuple[np.ndarray, int]:
    """The lab's value iteration: Bellman optimality sweeps from V = 0 until a sweep changes V by < tol;
    `(V, sweeps made)`, the last sweep counted."""
    values = np.zeros(nS)
    for sweep in range(1, maxiter + 1):
        look = np.zeros((nS, nA))
        for state in range(nS):
            for action in range(nA):
                for probability, next_state, reward, _terminal in P[state][action]:
                    look[state, action] += probability * (reward + beta * values[next_state])
        updated = look.max(axis=1)
        change = float(np.max(np.abs(updated - values)))
        values = updated
        if change < tol:
            return values, sweep
    return values, maxiter


def policy_iteration(
    P: Table, nS: int, nA: int, beta: float = 1.0, tol: float = 1e-8, maxiter: int = 200, *_: Any, **__: Any
) -> tuple[np.ndarray, np.ndarray, int]:
    """The lab's policy iteration from the all-ones start: evaluate, improve, until the policy stays;
    `(V, policy, iterations)`."""
    policy = np.ones(nS, dtype=np.int64)
    values = np.zeros(nS)
    for iteration in range(1, maxiter + 1):
        values = iter_policy_eval(P, nS, nA, policy, beta, tol)
        improved = policy_improvement(P, nS, nA, values, beta)
        if np.array_equal(improved, policy):
            return values, policy, iteration
        policy = improved
    return values, policy, maxiter


def run_simulation(env: Any, policy: Any, *args: Any, **kwargs: Any) -> float:
    """One episode of `policy` in `env`, reset here and left open: `sum beta**k * r_k` from k = 0.

    Takes 2019-2022's `(env, policy, render=True, beta=1.0)` and the other editions' `(env, policy,
    beta=1.0)`: a bool third argument is `render` (nothing is drawn). Whichever API the env serves its
    caller (the classic observation and four results of a step, or gym 0.26's pairs and five), the episode
    runs until it ends (terminated, or truncated by a time limit).
    """
    rest = [value for value in args if type(value) is not bool]
    beta = float(kwargs.get("beta", rest[0] if rest else 1.0))
    actions = np.asarray(policy).reshape(-1)
    started = env.reset()
    state = started[0] if isinstance(started, tuple) else started
    total, weight, ended = 0.0, 1.0, False
    while not ended:
        result = env.step(int(actions[int(state)]))
        state, reward = result[0], float(result[1])
        ended = bool(result[2]) or (len(result) == 5 and bool(result[3]))
        total += weight * reward
        weight *= beta
    return total


PROVIDED: dict[str, Callable[..., Any]] = {
    "epsilon_decay": epsilon_decay,
    "policy_improvement": policy_improvement,
    "extract_policy": extract_policy,
    "iter_policy_eval": iter_policy_eval,
    "compute_policy_v": iter_policy_eval,
    "value_iteration": value_iteration,
    "policy_iteration": policy_iteration,
    "run_simulation": run_simulation,
}
"""The names a call may provide, and the grader's definition of each."""
