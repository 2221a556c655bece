"""Tests for reference/oracles/mdp.py and mdps.py: the second lab's exact oracles, checked independently.

The lab's example is checked against values worked out by hand (the lab text's own sweeps); FrozenLake's
tables against gymnasium's; the optimal values against a plain-Python value iteration and, for the 4x4
lake, against 14/17 solved in exact rational arithmetic; return moments against Monte-Carlo runs of
gymnasium's FrozenLake (a z-test at |Z| <= 5: false-fail probability 5.7e-7 per statistic).
"""

from __future__ import annotations

import re
from fractions import Fraction

import gymnasium as gym
import numpy as np
import pytest

from reference.errors import InvalidMdpError, InvalidParameterError, UnboundedValueError
from reference.oracles.mdp import (
    Mdp,
    greedy_gaps,
    judge_policy,
    lab_value_iteration,
    mdp_from_table,
    optimal_solution,
    policy_value,
    q_values,
    return_moments,
    terminal_states,
)
from reference.oracles.mdps import (
    TIME_LIMITS,
    frozen_lake,
    grading_cases,
    lab_example,
    windy_grid,
)

Z_LIMIT = 5.0
"""Two-sided P(|Z| > 5) = 5.7e-7 for one (asymptotically) normal statistic."""
CASES = grading_cases()


def test_the_example_by_hand() -> None:
    example = lab_example()
    # V1 from zeros, as the lab computes it: max{0, -1}, max{-1, 1}, max{0, 1}, 0.
    np.testing.assert_array_equal(q_values(example, np.zeros(4), 1.0).max(axis=1), [0, 1, 1, 0])
    assert lab_value_iteration(example, 1.0, maxiter=1)[0].tolist() == [0, 1, 1, 0]
    assert lab_value_iteration(example, 1.0, maxiter=2)[0].tolist() == [1, 1, 1, 0]
    values, sweeps = lab_value_iteration(example, 1.0)
    assert (values.tolist(), sweeps) == ([1, 1, 1, 0], 3)
    assert optimal_solution(example, 1.0).values.tolist() == [1, 1, 1, 0]
    # At 0.9: state 0 goes right for 0 + 0.9 * 1 (down costs -1 + 0.9).
    assert optimal_solution(example, 0.9).values.tolist() == pytest.approx([0.9, 1, 1, 0], abs=1e-15)
    assert policy_value(example, [2, 1, 2, 0], 1.0).tolist() == [1, 1, 1, 0]
    # All ones (the lab's start): 0 -> down to 2 (-1), 2's "down" is impossible (value 0).
    assert policy_value(example, [1, 1, 1, 1], 1.0).tolist() == [-1, 1, 0, 0]
    # State 2 ties right (1) and up (0 + V[0] = 1): both are greedy; left is not.
    assert greedy_gaps(example, [1, 1, 1, 0], [2, 1, 3, 0], 1.0).tolist() == [0, 0, 0, 0]
    # Down from 0 is worth -1 + V[2] = 0, right 0 + V[1] = 1.
    assert greedy_gaps(example, [1, 1, 1, 0], [1, 1, 2, 0], 1.0).tolist() == [1, 0, 0, 0]
    assert terminal_states(example).tolist() == [3]


@pytest.mark.parametrize(
    ("map_name", "slippery"), [("4x4", False), ("4x4", True), ("8x8", False), ("8x8", True)]
)
def test_frozen_lake_is_gymnasiums_table(map_name: str, slippery: bool) -> None:
    env = gym.make("FrozenLake-v1", map_name=map_name, is_slippery=slippery)
    expected = env.unwrapped.P  # type: ignore[attr-defined]
    env.close()
    ours = frozen_lake(map_name, slippery=slippery).as_dict()
    assert ours == {
        s: {a: [tuple(o) for o in outcomes] for a, outcomes in actions.items()}
        for s, actions in expected.items()
    }
    for env_id in ("FrozenLake-v1", "FrozenLake8x8-v1"):
        assert gym.spec(env_id).max_episode_steps == TIME_LIMITS[env_id]


def _plain_value_iteration(mdp: Mdp, beta: float) -> list[float]:
    """Value iteration written without numpy, Gauss-Seidel, until nothing moves by 1e-13."""
    values = [0.0] * mdp.n_states
    for _ in range(200_000):
        change = 0.0
        for state, actions in enumerate(mdp.table):
            best = max(sum(p * (r + beta * values[s]) for p, s, r, _ in outcomes) for outcomes in actions)
            change = max(change, abs(best - values[state]))
            values[state] = best
        if change < 1e-13:
            return values
    raise AssertionError("plain value iteration did not settle")


@pytest.mark.parametrize("case", CASES, ids=[case.key for case in CASES])
def test_optimal_values_match_an_independent_value_iteration(case) -> None:  # type: ignore[no-untyped-def]
    solution = optimal_solution(case.mdp, case.beta)
    np.testing.assert_allclose(
        solution.values, _plain_value_iteration(case.mdp, case.beta), rtol=0, atol=1e-9
    )
    assert judge_policy(case.mdp, solution.policy, case.beta).optimal
    np.testing.assert_allclose(
        policy_value(case.mdp, solution.policy, case.beta), solution.values, atol=1e-12
    )


def _rational_policy_value(mdp: Mdp, policy: list[int], beta: Fraction) -> list[Fraction]:
    """Solve (I - beta T) v = r on the non-terminal states by Gauss-Jordan elimination in fractions."""
    terminal = set(terminal_states(mdp).tolist())
    live = [s for s in range(mdp.n_states) if s not in terminal]
    index = {s: i for i, s in enumerate(live)}
    rows = []
    for s in live:
        row = [Fraction(0)] * (len(live) + 1)
        row[index[s]] += 1
        for p, nxt, r, _ in mdp.table[s][policy[s]]:
            p_exact = Fraction(1, 3) if abs(p - 1 / 3) < 1e-12 else Fraction(p)
            row[-1] += p_exact * Fraction(r)
            if nxt in index:
                row[index[nxt]] -= beta * p_exact
        rows.append(row)
    for column in range(len(live)):
        pivot = next(i for i in range(column, len(live)) if rows[i][column] != 0)
        rows[column], rows[pivot] = rows[pivot], rows[column]
        rows[column] = [x / rows[column][column] for x in rows[column]]
        for i in range(len(live)):
            if i != column and rows[i][column] != 0:
                factor = rows[i][column]
                rows[i] = [a - factor * b for a, b in zip(rows[i], rows[column], strict=True)]
    values = [Fraction(0)] * mdp.n_states
    for s in live:
        values[s] = rows[index[s]][-1]
    return values


def test_the_4x4_lake_start_is_worth_14_17_exactly() -> None:
    lake = frozen_lake("4x4", slippery=True)
    solution = optimal_solution(lake, 1.0)
    exact = _rational_policy_value(lake, solution.policy.tolist(), Fraction(1))
    assert exact[0] == Fraction(14, 17)
    np.testing.assert_allclose(solution.values, [float(x) for x in exact], atol=1e-13)
    assert optimal_solution(frozen_lake("8x8", slippery=True), 1.0).values[0] == pytest.approx(1.0, abs=1e-12)


def test_ties_are_judged_by_value_not_by_the_list() -> None:
    lake = frozen_lake("8x8", slippery=True)
    solution = optimal_solution(lake, 1.0)
    look_ahead = q_values(lake, solution.values, 1.0)
    tied = np.sum(look_ahead >= look_ahead.max(axis=1, keepdims=True) - 1e-9, axis=1) > 1
    non_terminal = np.ones(lake.n_states, dtype=bool)
    non_terminal[terminal_states(lake)] = False
    assert int(np.sum(tied & non_terminal)) == 17  # RL2.md: 17 non-terminal states tie on 8x8 at discount 1
    alternatives = [
        np.where(np.arange(lake.n_states) == state, action, solution.policy)
        for state in np.flatnonzero(tied & non_terminal)
        for action in np.flatnonzero(look_ahead[state] >= look_ahead[state].max() - 1e-9)
        if action != solution.policy[state]
    ]
    verdicts = [judge_policy(lake, policy, 1.0).optimal for policy in alternatives]
    assert any(verdicts)  # another list, the same value: optimal
    not_greedy = solution.policy.copy()
    decisive = int(np.argmax(np.ptp(look_ahead, axis=1)))  # the state whose actions differ most
    not_greedy[decisive] = int(np.argmin(look_ahead[decisive]))
    assert not judge_policy(lake, not_greedy, 1.0).optimal


def test_a_policy_that_loops_through_rewards_has_no_value() -> None:
    # On the lab's example, right from state 0 and left from state 1 walk 0 -> 1 -> 0 at a cost of 1 a lap.
    looping = [2, 0, 2, 0]
    with pytest.raises(UnboundedValueError, match="loops forever through nonzero rewards"):
        policy_value(lab_example(), looping, 1.0)
    judgement = judge_policy(lab_example(), looping, 1.0)
    assert not judgement.optimal and np.isinf(judgement.shortfall[:2]).all()
    assert policy_value(lab_example(), looping, 0.5).tolist() == pytest.approx([-2 / 3, -4 / 3, 1, 0])


def test_a_zero_reward_loop_is_worth_nothing_at_discount_1() -> None:
    # Always left on the deterministic lake: state 0 bumps into the wall forever with reward 0.
    assert policy_value(frozen_lake("4x4", slippery=False), [0] * 16, 1.0).tolist() == [0.0] * 16


@pytest.mark.parametrize("beta", [1.0, 0.8])
def test_the_grid_policy_value_against_plain_iteration(beta: float) -> None:
    """Every policy of the windy grid ends, so plain iteration converges even at discount 1."""
    grid = windy_grid()
    policy = [3, 0, 3, 0, 0, 0]  # up and left, against the wind: only the wind ends the walk
    values = [0.0] * grid.n_states
    for _ in range(5_000):
        values = [
            sum(p * (r + beta * values[s]) for p, s, r, _ in grid.table[state][policy[state]])
            for state in range(grid.n_states)
        ]
    np.testing.assert_allclose(policy_value(grid, policy, beta), values, atol=1e-12)


def _monte_carlo(
    map_name: str, policy: np.ndarray, beta: float, episodes: int, seed: int, *, limit: bool
) -> np.ndarray:
    made = gym.make("FrozenLake-v1", map_name=map_name, is_slippery=True)
    env = made if limit else made.unwrapped  # gym.make's TimeLimit, or none (the lab's values)
    returns = np.zeros(episodes)
    for episode in range(episodes):
        state, _ = env.reset(seed=seed if episode == 0 else None)
        done, step = False, 0
        while not done:
            state, reward, terminated, truncated, _ = env.step(int(policy[state]))
            returns[episode] += beta**step * float(reward)
            step += 1
            done = terminated or truncated
    env.close()
    return returns


@pytest.mark.slow
@pytest.mark.parametrize(
    ("beta", "limit"), [(1.0, False), (0.9, False), (1.0, True)], ids=["beta1", "beta0.9", "time-limit"]
)
def test_return_moments_match_gymnasiums_episodes(beta: float, limit: bool, seed: int) -> None:
    lake = frozen_lake("4x4", slippery=True)
    policy = optimal_solution(lake, 1.0).policy
    moments = return_moments(lake, policy, beta, steps=TIME_LIMITS["FrozenLake-v1"] if limit else None)
    returns = _monte_carlo("4x4", policy, beta, 4_000, seed, limit=limit)
    mean, variance = moments.mean[0], moments.variance[0]
    assert abs(returns.mean() - mean) / np.sqrt(variance / len(returns)) <= Z_LIMIT
    # The variance's own estimate: sd of (G - mean)^2 over sqrt(n).
    spread = (returns - mean) ** 2
    assert abs(spread.mean() - variance) / (spread.std() / np.sqrt(len(returns))) <= Z_LIMIT


def test_the_time_limit_lowers_the_4x4_mean() -> None:
    lake = frozen_lake("4x4", slippery=True)
    policy = optimal_solution(lake, 1.0).policy
    limited = return_moments(lake, policy, 1.0, steps=100).mean[0]
    assert 0.70 < limited < 0.76 < 14 / 17  # RL2.md: about 0.74 with gym.make's 100 steps
    deterministic = frozen_lake("4x4", slippery=False)
    plan = optimal_solution(deterministic, 0.8).policy
    moments = return_moments(deterministic, plan, 0.8)
    assert (moments.mean[0], moments.variance[0]) == (
        pytest.approx(0.8**5, abs=1e-15),
        pytest.approx(0, abs=1e-15),
    )


@pytest.mark.parametrize(
    ("table", "message"),
    [
        ({0: {0: [(1.0, 1, 0, False)]}}, "leads outside the states 0..0"),
        ({0: {0: [(0.5, 0, 0, False)]}}, "probabilities sum to 0.5"),
        ({0: {0: [(-1.0, 0, 0, False), (2.0, 0, 0, False)]}}, "negative probability"),
        ({0: {}}, "P[0] has no entry for action 0"),
        ({}, "P has no entry for state 0"),
    ],
    ids=["next-state", "sum", "negative", "action", "state"],
)
def test_invalid_tables_are_named(table: dict, message: str) -> None:  # type: ignore[type-arg]
    with pytest.raises(InvalidMdpError, match=re.escape(message)):
        mdp_from_table("t", table, 1, 1)


def test_invalid_policies_and_discounts_are_named() -> None:
    with pytest.raises(InvalidParameterError, match=r"beta must lie in \[0, 1\], found 1.5"):
        policy_value(lab_example(), [0, 0, 0, 0], 1.5)
    with pytest.raises(InvalidParameterError, match=re.escape("actions lie in 0..3")):
        policy_value(lab_example(), [0, 0, 0, 4], 1.0)
    with pytest.raises(InvalidParameterError, match="a policy is 4 whole action numbers"):
        policy_value(lab_example(), [0.5, 0, 0, 0], 1.0)


def test_the_table_round_trips() -> None:
    example = lab_example()
    assert mdp_from_table(example.name, example.as_dict(), 4, 4) == example
