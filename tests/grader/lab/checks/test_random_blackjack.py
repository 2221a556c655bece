"""random_blackjack(n): the exact win-count decision fails a sample whose only fault is its win count."""

from grader.simulated_students.behaviours import random_blackjack

from .support import grade, on_low_deck


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
