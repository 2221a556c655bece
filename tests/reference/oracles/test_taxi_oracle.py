"""Tests for reference/oracles/taxi.py: exact identities and Monte-Carlo runs of gymnasium's Taxi-v4."""

from __future__ import annotations

import math
from collections.abc import Callable

import gymnasium as gym
import numpy as np
import numpy.typing as npt
import pytest

from reference.errors import InvalidParameterError, InvalidQTableError
from reference.oracles.taxi import (
    ReturnMoments,
    checked_q_table,
    greedy_policy_return,
    optimal_q_table,
    optimal_return,
    random_policy_return,
    taxi_model,
)
from reference.solutions import find_qvalues

Z_LIMIT = 5.0
"""Two-sided P(|Z| > 5) = 5.7e-7 for one (asymptotically) normal statistic."""


def _returns(
    policy: Callable[[int, np.random.Generator], int], episodes: int, max_steps: int, seed: int
) -> npt.NDArray[np.float64]:
    env = gym.make("Taxi-v4", max_episode_steps=max_steps)
    choice = np.random.default_rng(seed + 1)
    totals = np.zeros(episodes)
    for episode in range(episodes):
        state, _ = env.reset(seed=seed if episode == 0 else None)
        terminated = truncated = False
        while not (terminated or truncated):
            state, reward, terminated, truncated, _ = env.step(policy(state, choice))
            totals[episode] += reward
    return totals


def _assert_moments_match(totals: npt.NDArray[np.float64], exact: ReturnMoments) -> None:
    episodes = len(totals)
    mean_z = (totals.mean() - exact.mean) / math.sqrt(exact.variance / episodes)
    assert abs(mean_z) < Z_LIMIT, (totals.mean(), exact)
    # The sample variance is asymptotically normal with variance (m4 - s^4) / N (m4: fourth central moment).
    centred = totals - totals.mean()
    variance_error = math.sqrt(max(np.mean(centred**4) - np.var(totals) ** 2, 1e-12) / episodes)
    assert abs(np.var(totals, ddof=1) - exact.variance) < Z_LIMIT * variance_error, (np.var(totals), exact)


def _random_action(_state: int, choice: np.random.Generator) -> int:
    return int(choice.integers(6))


@pytest.mark.slow
@pytest.mark.parametrize(
    ("episodes", "max_steps"), [(1_500, 200), (6_000, 25)], ids=["time-limit-200", "time-limit-25"]
)
def test_random_policy_return_matches_monte_carlo(episodes: int, max_steps: int, seed: int) -> None:
    # Mean and variance z-tests at 5 sigma: false-fail probability about 1.2e-6 (normal approximation).
    _assert_moments_match(
        _returns(_random_action, episodes, max_steps, seed), random_policy_return(max_steps)
    )


def _noise_q_table(seed: int) -> npt.NDArray[np.float64]:
    return np.random.default_rng(seed).normal(size=(500, 6))


Q_TABLES: dict[str, Callable[[int], npt.NDArray[np.float64]]] = {
    "optimal-gamma-0.6": lambda _seed: optimal_q_table(0.6),
    "noise": _noise_q_table,  # mostly wanders until the time limit, collecting -10 for illegal moves
    "briefly-trained": lambda seed: find_qvalues("Taxi-v4", episodes=1_500, seed=seed),
    "all-zero": lambda _seed: np.zeros((500, 6)),  # argmax 0 everywhere: drives south, -200
}


@pytest.mark.slow
@pytest.mark.parametrize("name", Q_TABLES, ids=Q_TABLES)
def test_greedy_policy_return_matches_monte_carlo(name: str, seed: int) -> None:
    # Mean and variance z-tests at 5 sigma over 1500 episodes: false-fail probability about 1.2e-6.
    q_table = Q_TABLES[name](seed)
    exact = greedy_policy_return(q_table)
    totals = _returns(lambda state, _choice: int(np.argmax(q_table[state])), 1_500, 200, seed)
    if exact.variance < 1e-9:
        assert totals == pytest.approx(np.full_like(totals, exact.mean))
    else:
        _assert_moments_match(totals, exact)


def test_random_policy_return_values() -> None:
    # Regression snapshots of the exact values: test_random_policy_return_matches_monte_carlo above checks
    # them independently, by playing gymnasium's Taxi.
    moments = random_policy_return()
    assert moments.mean == pytest.approx(-771.0910, abs=1e-4)
    assert moments.std == pytest.approx(101.8264, abs=1e-4)


def test_zero_steps_return_nothing() -> None:
    assert random_policy_return(0) == ReturnMoments(0.0, 0.0)
    assert greedy_policy_return(optimal_q_table(), 0) == ReturnMoments(0.0, 0.0)


@pytest.mark.parametrize("gamma", [0.0, 0.6, 0.9, 0.99], ids=lambda gamma: f"gamma={gamma}")
def test_optimal_q_table_satisfies_the_bellman_equation(gamma: float) -> None:
    model = taxi_model()
    q_table = optimal_q_table(gamma)
    bootstrap = np.where(model.terminates, 0.0, q_table.max(axis=1)[model.next_state])
    assert np.max(np.abs(q_table - (model.reward + gamma * bootstrap))) < 1e-11


@pytest.mark.parametrize("gamma", [0.6, 0.9, 0.99], ids=lambda gamma: f"gamma={gamma}")
def test_greedy_on_the_optimal_q_table_is_optimal_and_beats_random(gamma: float) -> None:
    greedy = greedy_policy_return(optimal_q_table(gamma))
    assert greedy.mean == pytest.approx(optimal_return().mean, abs=1e-9)
    assert greedy.mean > random_policy_return().mean + 700


def test_optimal_return_is_a_shortest_delivery() -> None:
    # Every episode needs at least a move, a pick-up, a move and a drop-off: at most 20 - 3 = 17.
    best = optimal_return()
    assert best.mean == pytest.approx(7.93, abs=1e-9)  # a regression snapshot; the bound below is derived
    assert best.mean + best.std < 17


def test_model_reset_distribution_is_uniform_over_300_start_states() -> None:
    initial = taxi_model().initial_distribution
    assert np.count_nonzero(initial) == 300
    assert np.allclose(initial[initial > 0], 1 / 300)


def test_q_table_is_not_modified() -> None:
    q_table = optimal_q_table()
    before = q_table.copy()
    greedy_policy_return(q_table)
    assert np.array_equal(q_table, before)


def test_checked_q_table_accepts_lists_and_integers() -> None:
    assert checked_q_table([[0] * 6] * 500).dtype == np.float64


@pytest.mark.parametrize(
    ("q_table", "message"),
    [
        (
            np.zeros((500,)),
            "expected a Taxi Q-table with shape (500, 6) (one row per state, one column per action), "
            "found shape (500,); build it as np.zeros((env.observation_space.n, env.action_space.n))",
        ),
        (
            np.zeros((6, 500)),
            "expected a Taxi Q-table with shape (500, 6) (one row per state, one column per action), "
            "found shape (6, 500); build it as np.zeros((env.observation_space.n, env.action_space.n))",
        ),
        (
            None,
            "expected a Taxi Q-table with shape (500, 6) (one row per state, one column per action), "
            "found shape (); build it as np.zeros((env.observation_space.n, env.action_space.n))",
        ),
        (
            np.full((500, 6), "x"),
            "expected a Taxi Q-table of real numbers, found dtype <U1; store the action values as floats",
        ),
        (
            np.zeros((500, 6), dtype=complex),
            "expected a Taxi Q-table of real numbers, found dtype complex128; "
            "store the action values as floats",
        ),
    ],
    ids=["1-d", "transposed", "none", "strings", "complex"],
)
def test_bad_q_table_is_refused(q_table: object, message: str) -> None:
    with pytest.raises(InvalidQTableError) as raised:
        greedy_policy_return(q_table)  # type: ignore[arg-type]
    assert str(raised.value) == message


def test_ragged_q_table_is_refused() -> None:
    with pytest.raises(InvalidQTableError) as raised:
        greedy_policy_return([[0.0] * 6] * 499 + [[0.0]])
    # numpy's own explanation follows in parentheses; its wording depends on the numpy version.
    assert str(raised.value).startswith(
        "expected a Taxi Q-table: an array of numbers with shape (500, 6); "
        "could not convert the list to an array ("
    )


@pytest.mark.parametrize("gamma", [1.0, -0.1, float("nan")], ids=["one", "negative", "nan"])
def test_gamma_outside_0_1_is_refused(gamma: float) -> None:
    with pytest.raises(InvalidParameterError, match=r"expected a discount factor gamma in \[0, 1\)"):
        optimal_q_table(gamma)


@pytest.mark.parametrize("max_steps", [-1, 2.5, True], ids=["negative", "float", "bool"])
def test_bad_step_limit_is_refused(max_steps: object) -> None:
    with pytest.raises(InvalidParameterError, match=r"expected max_steps as a non-negative integer"):
        random_policy_return(max_steps)  # type: ignore[arg-type]
