"""Tests for reference/oracles/guessing_game.py: exact figures, the game's rules, Monte-Carlo play."""

from __future__ import annotations

import math

import gymnasium as gym
import numpy as np
import pytest

from grader.compat import GuessingGameEnv, register_envs
from reference.errors import InvalidParameterError
from reference.oracles.guessing_game import (
    MAX_GUESSES,
    TARGET_HIGH,
    TARGET_LOW,
    TOLERANCE,
    GuessCounts,
    midpoint_guess_counts,
)

Z_LIMIT = 5.0
"""Two-sided P(|Z| > 5) = 5.7e-7 for one (asymptotically) normal statistic."""


def test_the_oracle_states_the_rules_of_the_registered_game() -> None:
    env = GuessingGameEnv()
    assert (-env.range, env.range) == (TARGET_LOW, TARGET_HIGH)
    assert env.range * 0.01 == TOLERANCE
    assert env.guess_max == MAX_GUESSES


def test_the_labs_midpoint_search_takes_at_most_8_guesses() -> None:
    # Guess k hits a window of 20 in each of the 2**(k-1) intervals of width 2000 / 2**(k-1) until the
    # intervals are narrower than 40; the 8th guess is within 7.8 of every target left.
    counts = midpoint_guess_counts()
    # Guesses 1..6: 20 * 2**(k-1) targets of 2000 each, derived; 7 and 8: regression snapshots of the
    # remainder's split (they sum to what the first six leave).
    assert counts.probabilities[:6] == pytest.approx(
        [20 * 2 ** (k - 1) / 2000 for k in range(1, 7)], abs=1e-15
    )
    assert counts.probabilities[6:] == pytest.approx((0.364375, 0.005625), abs=1e-15)
    assert math.fsum(counts.probabilities) == pytest.approx(1.0, abs=1e-15)
    assert counts.mean == pytest.approx(
        math.fsum(k * p for k, p in enumerate(counts.probabilities, 1)), abs=1e-12
    )
    assert counts.most == 8
    assert counts.probability(0) == counts.probability(9) == 0.0


def test_a_search_from_the_guess_space_bounds_takes_three_more_guesses() -> None:
    # From [-10000, 10000] the 2nd to 4th guesses (+-5000, +-2500, +-1250) lie outside the targets.
    counts = midpoint_guess_counts(-10_000, 10_000)
    assert counts.probability(1) == pytest.approx(0.01)
    assert counts.probability(2) == counts.probability(3) == counts.probability(4) == 0.0
    assert counts.mean == pytest.approx(8.97, abs=1e-12)


def test_a_search_that_misses_the_targets_is_truncated_at_200_guesses() -> None:
    counts = midpoint_guess_counts(5_000, 6_000)
    assert counts.most == MAX_GUESSES
    assert counts.probability(MAX_GUESSES) == pytest.approx(1.0)


@pytest.mark.parametrize(
    ("low", "high"), [(1.0, 1.0), (2.0, 1.0), (math.nan, 1.0), (-math.inf, 0.0)], ids=str
)
def test_an_empty_or_infinite_interval_is_refused(low: float, high: float) -> None:
    with pytest.raises(InvalidParameterError, match="low < high"):
        midpoint_guess_counts(low, high)


def _played_counts(low: float, high: float, games: int, seed: int) -> np.ndarray:
    register_envs()
    env = gym.make("GuessingGame-v0")
    counts = np.zeros(games)
    env.reset(seed=seed)
    for game in range(games):
        if game:
            env.reset()
        lower, upper, done = low, high, False
        while not done:
            guess = (lower + upper) / 2
            observation, _, terminated, truncated, _ = env.step(np.array([guess]))
            counts[game] += 1
            lower, upper = (guess, upper) if observation == 1 else (lower, guess)
            done = terminated or truncated
    return counts


@pytest.mark.parametrize(("low", "high"), [(-1000, 1000), (-10_000, 10_000)], ids=["lab", "guess-space"])
def test_the_real_game_takes_as_many_guesses_as_the_oracle_says(low: float, high: float, seed: int) -> None:
    # One z-test at 5 sigma over 3000 games: false-fail probability 5.7e-7 per start interval.
    counts = _played_counts(low, high, 3_000, seed)
    oracle: GuessCounts = midpoint_guess_counts(low, high)
    z = (counts.mean() - oracle.mean) / math.sqrt(oracle.variance / len(counts))
    assert abs(z) < Z_LIMIT
    assert counts.max() <= oracle.most
