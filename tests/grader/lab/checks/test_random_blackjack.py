"""random_blackjack(n): every diagnosis fails a sample of its own, the exact win-count decision included."""

from typing import Any

import pytest

from grader.simulated_students.behaviours import _play_blackjack, random_blackjack
from grader.simulated_students.simulation import Lab, StudentFunction

from .support import grade, on_low_deck


def _text(lab: Lab, n: int) -> Any:
    return "0.28"


def _abandons_one_game(lab: Lab, n: int) -> float:
    env = lab.make("Blackjack-v0")
    env.reset()
    env.step(1)  # then the reference's games, on the same env's next reset: the first game is abandoned
    return random_blackjack(lab, n)


def _one_game_short(lab: Lab, n: int) -> float:
    return random_blackjack(lab, n - 1) * (n - 1) / n


def _draws_on_even_sums(lab: Lab, n: int) -> float:
    # About half of the decisions draw, so the frequency test passes; the share depends on the sum.
    env = lab.make("Blackjack-v0")
    rewards = [
        _play_blackjack(env, lambda observation, _step: int(observation[0] % 2 == 0)) for _ in range(n)
    ]
    return sum(reward > 0 for reward in rewards) / n


@pytest.mark.parametrize(
    ("function", "diagnosis"),
    [
        (_text, "random_blackjack(2000) returned '0.28'; expected the win rate as a number."),
        (
            _abandons_one_game,
            "random_blackjack(2000): 1 game(s) were abandoned before they ended (e.g. episode 1 of call 1 "
            "stopped after 1 steps without terminating)",
        ),
        (
            _one_game_short,
            "random_blackjack(2000) must play 2000 games; the replay shows 1999. Play exactly n games "
            "(one reset per game).",
        ),
        (
            _draws_on_even_sums,
            "random_blackjack(2000): random actions draw half the time whatever the hand, but your share of "
            "draws depends on the player's sum (sum<=11: ",
        ),
    ],
    ids=["not-a-number", "integrity", "game-count", "sum-dependence"],
)
def test_each_diagnosis_fails_a_sample_of_its_own(
    function: StudentFunction, diagnosis: str, seed: int
) -> None:
    verdict = grade("random_blackjack", {"random_blackjack": function}, seed)
    assert verdict.status == "failed"
    assert verdict.feedback.startswith(diagnosis), verdict.feedback


def test_a_win_count_off_the_exact_law_fails_on_the_win_count_alone(seed: int) -> None:
    """Truly random actions on games dealt from ace to five only, judged as played: every rule before the
    decision holds (complete games, the right count, the returned rate, random actions), so only the exact
    two-sided binomial test of the win count can fail it.

    Statistic: wins in n = 2000 games against Binomial(2000, 0.2806), accepted 465..661 (alpha 1e-6,
    exact false-fail 9.2e-7). The low deck wins 0.0850 of games: the probability that it is accepted
    (a false pass of this test) is 3.4e-88 (bench/verdict_power.py, bench/RESULTS.md).
    """
    verdict = grade("random_blackjack", {"random_blackjack": on_low_deck(random_blackjack)}, seed, fast=True)
    assert verdict.status == "failed", verdict.feedback
    assert verdict.feedback.startswith(
        "random_blackjack(2000): a random player wins 0.2806 of games of Blackjack-v0"
    ), verdict.feedback
    assert "so 2000 games win between 465 and 661 times; your replayed games won" in verdict.feedback
    assert "or not the lab's game: regrade once." in verdict.feedback
    assert verdict.measurements["wins"] < 465  # type: ignore[operator]
