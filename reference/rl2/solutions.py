"""Model answers to the second lab (Policy Function Iteration / RL 2), written on gymnasium 1.4's API.

The names and signatures are those of the 2024 lab and the 2026 template; `reference.rl2.editions` gives
each edition its own names and return shapes on top of these. The algorithms are the lab's own (iterated
to a tolerance, sweeps counted as the lab counts them), not the exact oracles of `reference.oracles.mdp`
they are graded against. `P[s][a]` lists (probability, next state, reward, terminal) outcomes.

FrozenLake is played without `gym.make`'s time limit (the lab's values are those of whole episodes): the
episodes run on `env.unwrapped`, which is also where gymnasium 1.x keeps `P`.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import gymnasium as gym
import numpy as np
import numpy.typing as npt

Table = Mapping[int, Mapping[int, Sequence[tuple[float, int, float, bool]]]]
FloatArray = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.int64]

FROZEN_LAKE_ID = "FrozenLake-v1"


def _look_ahead(P: Table, nS: int, nA: int, V: FloatArray, beta: float) -> FloatArray:
    """`Q[s, a]`: every outcome of every move, weighted by its probability, added up (on Python floats)."""
    values = V.tolist()
    Q = np.zeros((nS, nA))
    for s in range(nS):
        for a in range(nA):
            total = 0.0
            for probability, next_state, reward, _ in P[s][a]:
                total += probability * (reward + beta * values[next_state])
            Q[s, a] = total
    return Q


def value_iteration(
    P: Table, nS: int, nA: int, beta: float = 1.0, tol: float = 1e-8, maxiter: int = 3000
) -> tuple[FloatArray, int]:
    """Problem 1: Bellman optimality sweeps from V = 0 until a sweep changes V by less than `tol`.

    Returns:
        (V, n): the values and the number of sweeps made, the last one included (the example: n = 3).
    """
    V = np.zeros(nS)
    for sweep in range(1, maxiter + 1):
        updated = _look_ahead(P, nS, nA, V, beta).max(axis=1)
        change = np.max(np.abs(updated - V))
        V = updated
        if change < tol:
            return V, sweep
    return V, maxiter


def policy_improvement(P: Table, nS: int, nA: int, V: npt.ArrayLike, beta: float = 1.0) -> IntArray:
    """Problem 2: the greedy policy for V (the first best action in each state)."""
    values = np.asarray(V, dtype=np.float64)
    policy: IntArray = np.argmax(_look_ahead(P, nS, nA, values, beta), axis=1).astype(np.int64)
    return policy


def iter_policy_eval(
    P: Table, nS: int, nA: int, policy: npt.ArrayLike, beta: float = 1.0, tol: float = 1e-8
) -> FloatArray:
    """Problem 3: the policy's value by sweeps of its own Bellman equation from V = 0 (one array)."""
    actions = np.asarray(policy).astype(np.int64).tolist()
    V = np.zeros(nS)
    while True:
        values = V.tolist()  # Python floats: the same sums, faster than numpy's scalars
        updated = np.zeros(nS)
        for s in range(nS):
            total = 0.0
            for probability, next_state, reward, _ in P[s][actions[s]]:
                total += probability * (reward + beta * values[next_state])
            updated[s] = total
        change = np.max(np.abs(updated - V))
        V = updated
        if change < tol:
            return V


def policy_iteration(
    P: Table, nS: int, nA: int, beta: float = 1.0, tol: float = 1e-8, maxiter: int = 200
) -> tuple[FloatArray, IntArray, int]:
    """Problem 4: evaluate, improve, until the policy stops changing; the lab starts from all ones.

    Returns:
        (V, policy, n): the last policy's values, the policy and the number of improvements made.
    """
    policy = np.ones(nS, dtype=np.int64)
    V = np.zeros(nS)
    for step in range(1, maxiter + 1):
        V = iter_policy_eval(P, nS, nA, policy, beta, tol)
        improved = policy_improvement(P, nS, nA, V, beta)
        if np.array_equal(improved, policy):
            return V, improved, step
        policy = improved
    return V, policy, maxiter


def run_simulation(env: Any, policy: npt.ArrayLike, beta: float = 1.0) -> float:
    """Problem 5 (6 before 2026): one episode from a reset, returning `sum beta**k * r_k` from k = 0.

    Plays any edition's env: `reset()` returning the observation alone (gym before 0.26) or with its info,
    `step()` returning four values or five. The env is left open: the caller made it and closes it.
    """
    actions = np.asarray(policy)
    observation = _reset(env)
    total, weight, done = 0.0, 1.0, False
    while not done:
        observation, reward, done = _step(env, int(actions[observation]))
        total += weight * float(reward)
        weight *= beta
    return total


def _reset(env: Any) -> int:
    result = env.reset()
    return int(result[0] if isinstance(result, tuple) else result)


def _step(env: Any, action: int) -> tuple[int, float, bool]:
    result = env.step(action)
    if len(result) == 5:
        observation, reward, terminated, truncated, _ = result
        return int(observation), float(reward), bool(terminated or truncated)
    observation, reward, done, _ = result
    return int(observation), float(reward), bool(done)


def frozen_lake(
    basic_case: bool = True, M: int = 1000, render: bool = False
) -> tuple[FloatArray, IntArray, float, FloatArray, IntArray, float]:
    """Problem 6: solve FrozenLake (4x4, or 8x8 when not `basic_case`), slippery, both ways; play each
    policy M times.

    Returns:
        (vi_value_func, vi_policy, vi_mean_return, pi_value_func, pi_policy, pi_mean_return).
    """
    env = make_frozen_lake(basic_case, render=render)
    try:
        lake = env.unwrapped
        nS, nA = lake.observation_space.n, lake.action_space.n
        vi_values, _ = value_iteration(lake.P, nS, nA)
        vi_policy = policy_improvement(lake.P, nS, nA, vi_values)
        pi_values, pi_policy, _ = policy_iteration(lake.P, nS, nA)
        vi_mean = float(np.mean([run_simulation(lake, vi_policy) for _ in range(M)]))
        pi_mean = float(np.mean([run_simulation(lake, pi_policy) for _ in range(M)]))
    finally:
        env.close()
    return vi_values, vi_policy, vi_mean, pi_values, pi_policy, pi_mean


def make_frozen_lake(basic_case: bool = True, *, render: bool = False) -> Any:
    """The lab's slippery FrozenLake, 4x4 or 8x8, drawn in a window when `render`."""
    return gym.make(
        FROZEN_LAKE_ID,
        map_name="4x4" if basic_case else "8x8",
        is_slippery=True,
        render_mode="human" if render else None,
    )
