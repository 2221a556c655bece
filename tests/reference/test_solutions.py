"""Tests for reference/solutions.py: the model answers do what the lab asks, on the real environments."""

from __future__ import annotations

import math

import numpy as np
import pytest

from grader.compat import register_envs
from reference import solutions
from reference.errors import InvalidParameterError, InvalidQTableError
from reference.oracles.blackjack import random_policy_outcome, threshold_policy_outcome
from reference.oracles.guessing_game import midpoint_guess_counts
from reference.oracles.taxi import greedy_policy_return, optimal_q_table, random_policy_return

Z_LIMIT = 5.0
"""Two-sided P(|Z| > 5) = 5.7e-7 for one (asymptotically) normal statistic."""


def _win_z(fraction: float, games: int, probability: float) -> float:
    return (fraction - probability) / math.sqrt(probability * (1 - probability) / games)


def test_random_blackjack_wins_as_often_as_the_oracle_says(seed: int) -> None:
    # One z-test at 5 sigma over 5000 games: false-fail probability 5.7e-7.
    fraction = solutions.random_blackjack(5_000, seed=seed)
    assert abs(_win_z(fraction, 5_000, random_policy_outcome().win)) < Z_LIMIT


@pytest.mark.slow
@pytest.mark.parametrize("n", [4, 11, 13, 17, 20], ids=lambda n: f"n={n}")
def test_blackjack_wins_as_often_as_the_oracle_says(n: int, seed: int) -> None:
    # One z-test at 5 sigma over 5000 games: false-fail probability 5.7e-7 per n.
    fraction = solutions.blackjack(n, games=5_000, seed=seed)
    assert abs(_win_z(fraction, 5_000, threshold_policy_outcome(n).win)) < Z_LIMIT


@pytest.mark.slow
def test_blackjack_returns_a_fraction_of_10000_games() -> None:
    fraction = solutions.blackjack(seed=7)
    assert 0.0 <= fraction <= 1.0
    assert (fraction * 10_000) == pytest.approx(round(fraction * 10_000), abs=1e-6)


def test_blackjack_that_always_hits_never_wins(seed: int) -> None:
    assert solutions.blackjack(21, games=500, seed=seed) == 0.0


def test_same_seed_same_result(seed: int) -> None:
    assert solutions.random_blackjack(300, seed=seed) == solutions.random_blackjack(300, seed=seed)
    assert solutions.cartpole(seed=seed) == solutions.cartpole(seed=seed)


@pytest.mark.slow
def test_cartpole_meets_the_labs_bar_on_every_seed() -> None:
    # The lab: "at least 120 and on average about 180" (CartPole-v0 stops at 200).
    steps = [solutions.cartpole(seed=seed) for seed in range(300)]
    assert min(steps) >= 120
    assert 170 <= np.mean(steps) <= 195
    assert max(steps) == 200


@pytest.mark.slow
def test_car_reaches_the_goal_in_fewer_than_180_steps_on_every_seed() -> None:
    # MountainCar-v0 truncates at 200, so fewer than 180 steps means the flag was reached.
    steps = [solutions.car(seed=seed) for seed in range(300)]
    assert max(steps) < 180


def test_plain_calls_work() -> None:
    assert 0.0 <= solutions.random_blackjack(20) <= 1.0
    assert 1 <= solutions.cartpole() <= 200
    assert solutions.car() < 180


@pytest.mark.slow  # trains a Q-table, seconds
def test_find_qvalues_learns_something(seed: int) -> None:
    q_table = solutions.find_qvalues("Taxi-v4", episodes=2_000, seed=seed)
    assert q_table.shape == (500, 6)
    assert q_table.dtype == np.float64
    assert greedy_policy_return(q_table).mean > random_policy_return().mean + 300
    assert np.array_equal(q_table, solutions.find_qvalues("Taxi-v4", episodes=2_000, seed=seed))


@pytest.mark.slow
def test_taxi_with_a_given_q_table_matches_the_oracles(seed: int) -> None:
    # Two z-tests at 5 sigma over 400 episodes each: false-fail probability 1.2e-6.
    q_table = optimal_q_table()
    random_mean, greedy_mean = solutions.taxi(q_table, episodes=400, seed=seed)
    for mean, exact in [(random_mean, random_policy_return()), (greedy_mean, greedy_policy_return(q_table))]:
        assert abs(mean - exact.mean) < Z_LIMIT * exact.std / math.sqrt(400), (mean, exact)


@pytest.mark.slow
def test_taxi_trains_its_own_q_table_when_none_is_given(seed: int) -> None:
    # 100 000 training episodes (about 10 s of CPU) learn the optimal greedy policy (exact return 7.93 for
    # each of the 3 seeds in bench/RESULTS.md); the bound also allows one wasted step per episode on
    # average, then a z-test at 5 sigma over 200 episodes (false-fail probability 2.9e-7 given the table).
    random_mean, greedy_mean = solutions.taxi(episodes=200, seed=seed)
    assert greedy_mean > 7.93 - 1.0 - Z_LIMIT * 2.59 / math.sqrt(200)
    assert random_mean < -500


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (
            lambda: solutions.random_blackjack(0),
            "expected n as a positive integer (a number of games), found 0",
        ),
        (
            lambda: solutions.blackjack(11, games=2.5),
            "expected games as a positive integer (a number of games), found 2.5",
        ),
        (
            lambda: solutions.taxi(np.zeros((500, 6)), episodes=-3),
            "expected episodes as a positive integer (a number of games), found -3",
        ),
    ],
    ids=["no-games", "fractional-games", "negative-episodes"],
)
def test_bad_counts_are_refused(call: object, message: str) -> None:
    with pytest.raises(InvalidParameterError) as raised:
        call()  # type: ignore[operator]
    assert str(raised.value) == message


def test_taxi_refuses_a_q_table_of_the_wrong_shape() -> None:
    with pytest.raises(InvalidQTableError, match=r"found shape \(500, 4\)"):
        solutions.taxi(np.zeros((500, 4)), episodes=1)


def test_blackjack_is_the_labs_game_not_the_registered_default() -> None:
    with solutions.make_blackjack() as env:
        assert (env.unwrapped.natural, env.unwrapped.sab) == (False, False)  # type: ignore[attr-defined]
    with solutions.make_cartpole() as env:
        assert env.spec is not None
        assert env.spec.max_episode_steps == 200


def test_guessing_game_finds_the_target_within_8_guesses_as_often_as_the_oracle_says() -> None:
    # One z-test at 5 sigma over 2000 seeds: false-fail probability 5.7e-7.
    register_envs()
    counts = [solutions.guessing_game(seed=seed) for seed in range(2_000)]
    oracle = midpoint_guess_counts()
    assert min(counts) >= 1 and max(counts) <= oracle.most
    z = (np.mean(counts) - oracle.mean) / math.sqrt(oracle.variance / len(counts))
    assert abs(z) < Z_LIMIT
    assert solutions.guessing_game(seed=7) == solutions.guessing_game(seed=7)
