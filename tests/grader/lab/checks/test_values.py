"""Reading returned numbers: fractions, percentages, rounded values and the causes of mismatches."""

import numpy as np
import pytest

from grader.lab.checks.values import (
    GameCounts,
    as_number,
    chance_text,
    describe,
    rate_mismatch_cause,
    read_rate,
    same_number,
    step_count_mismatch_cause,
)

COUNTS = GameCounts(games=1000, wins=281, draws=43, reward_total=281 - 676)


@pytest.mark.parametrize(
    ("value", "expected"),
    [(1, 1.0), (0.5, 0.5), (True, None), ("0.5", None), (None, None), ([1], None)],
    ids=["int", "float", "bool", "str", "none", "list"],
)
def test_as_number(value: object, expected: float | None) -> None:
    assert as_number(value) == expected


@pytest.mark.parametrize(
    ("returned", "scale"),
    [
        (0.281, "fraction"),
        (28.1, "percentage"),
        (0.28, "fraction"),
        (28.0, None),
        (0.3, None),
        (-0.395, None),
    ],
    ids=["fraction", "percentage", "rounded-2-decimals", "rounded-too-coarsely", "other", "average-reward"],
)
def test_read_rate(returned: float, scale: str | None) -> None:
    assert read_rate(returned, COUNTS) == scale


@pytest.mark.parametrize(
    ("returned", "cause"),
    [
        (-0.395, "it equals the average reward (wins minus losses per game), not the win rate"),
        (
            -39.5,
            "it equals the average reward (wins minus losses per game), not the win rate (as a percentage)",
        ),
        (0.324, "it equals draws counted as wins"),
        (281, "it equals the number of wins, not the share of games won"),
        (0.719, "it equals the share of games NOT won"),
        (150.0, "a win rate is a number between 0 and 1 (or 0 and 100 as a percentage)"),
        (
            0.5,
            "no count of the replayed games gives this number: return the wins divided by the games played",
        ),
    ],
    ids=[
        "average-reward",
        "average-reward-percent",
        "draws-as-wins",
        "count",
        "not-won",
        "out-of-range",
        "unknown",
    ],
)
def test_rate_mismatch_cause(returned: float, cause: str) -> None:
    assert rate_mismatch_cause(returned, COUNTS) == cause


def test_same_number_accepts_float_rounding_only_to_two_decimals_or_finer() -> None:
    assert same_number(0.1 + 0.2, 0.3)
    assert same_number(41.29, 41.2903)
    assert not same_number(41.3, 41.2903)
    assert same_number(2_000_000 * (1 + 1e-11), 2_000_000.0)  # relative rounding of a large total


@pytest.mark.parametrize(
    ("returned", "steps", "wall_time", "cause"),
    [
        (
            188,
            187,
            0.01,
            "it is off by one: count one step per env.step() call, starting from 0 after reset()",
        ),
        (
            0.0123,
            187,
            0.0123,
            "it looks like elapsed time in seconds (the call ran 0.0123 s), not a number of "
            "steps: count the env.step() calls instead of timing them",
        ),
        (187.5, 187, 0.01, "a number of steps is a whole number: count the env.step() calls"),
        (
            200,
            187,
            0.01,
            "it is not the length of the episode the call played: return the number of env.step() calls made",
        ),
    ],
    ids=["off-by-one", "elapsed-time", "fractional", "other"],
)
def test_step_count_mismatch_cause(returned: float, steps: int, wall_time: float, cause: str) -> None:
    assert step_count_mismatch_cause(returned, steps, wall_time) == cause


def test_chance_text() -> None:
    assert chance_text(1e-6) == "the 1-in-1,000,000 chance"
    assert chance_text(0.0) == "a practically impossible chance"


@pytest.mark.parametrize("wins", [570, 1, 2806, 7413])
def test_a_single_precision_rate_is_the_replayed_rate(wins: int) -> None:
    rate = wins / 10_000
    assert same_number(float(np.float32(rate)), rate)
    assert not same_number(float(np.float32(rate + 1e-4)), rate)


@pytest.mark.parametrize(
    ("value", "shown"),
    [(0.1 + 0.2, "0.3"), (1 / 3, "0.333333"), (7, "7"), ("x" * 70, "'" + "x" * 56 + "..."), (None, "None")],
    ids=["float-rounding", "float-digits", "int", "long-text", "none"],
)
def test_describe(value: object, shown: str) -> None:
    assert describe(value) == shown
