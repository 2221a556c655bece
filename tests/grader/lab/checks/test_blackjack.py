"""blackjack(n): naming how replayed decisions deviate from 'draw while sum <= n', and the exact curve."""

from fractions import Fraction
from functools import cache

import pytest

from grader.lab.checks.blackjack import _Decision, exact_best_n, exact_curve, policy_deviation
from reference.oracles import random_policy_outcome

from .support import grade, on_low_deck, small_config


def _decisions(*rows: tuple[int, int, int, bool]) -> list[_Decision]:
    return [_Decision(*row) for row in rows]


@pytest.mark.parametrize(
    ("rows", "expected"),
    [
        ([(0, 0, 12, True), (0, 1, 15, False)], None),
        (
            [(0, 0, 12, False), (1, 0, 11, True), (1, 1, 16, False)],
            "your games stood on a sum of exactly 12 in 1 hands, so they follow 'draw while the sum is < "
            "12': "
            "check `<` versus `<=`",
        ),
        (
            [(0, 0, 13, True), (0, 1, 18, False)],
            "your games drew on a sum of 13 in 1 hands, so they follow 'draw while the sum is <= 13': the "
            "threshold "
            "is off by one",
        ),
        (
            [(0, 0, 18, True), (1, 0, 10, True), (1, 1, 15, False)],
            "in 1 games the first decision drew a card before looking at the dealt hand; every later "
            "decision "
            "followed 'draw while the sum is <= 12'. Read the player's sum from the observation reset() "
            "returns "
            "before the first decision",
        ),
        (
            [(0, 0, 8, False), (1, 0, 10, True), (1, 1, 11, True), (1, 2, 19, False)],
            "in 1 games the first decision stood before looking at the dealt hand; every later decision "
            "followed "
            "'draw while the sum is <= 12'. Read the player's sum from the observation reset() returns "
            "before the "
            "first decision",
        ),
        (
            [(0, 0, 18, True), (1, 0, 8, False), (2, 0, 10, True), (2, 1, 15, False)],
            "in 2 games the first decision decided with a stale hand (e.g. the previous game's sum) instead "
            "of the "
            "one reset() dealt; every later decision followed 'draw while the sum is <= 12'. Read the "
            "player's sum "
            "from the observation reset() returns before the first decision",
        ),
        (
            [(0, 0, 10, True), (0, 1, 14, True), (0, 2, 17, False)],
            "your games follow 'draw while the sum is <= 14' whatever n is: use the parameter n, not a fixed "
            "number",
        ),
        (
            [(0, 0, 13, False), (1, 0, 5, True), (1, 1, 14, True), (1, 2, 20, True)],
            "2 of 4 decisions broke 'draw while the sum is <= 12' (e.g. game 2, decision 2: sum 14, you "
            "drew)",
        ),
    ],
    ids=[
        "follows",
        "less-than",
        "off-by-one-up",
        "draws-before-looking",
        "stands-before-looking",
        "stale-hand",
        "fixed-threshold",
        "other",
    ],
)
def test_policy_deviation_is_named(rows: list[tuple[int, int, int, bool]], expected: str | None) -> None:
    assert policy_deviation(_decisions(*rows), 12) == expected


_CARDS = {card: Fraction(4 if card == 10 else 1, 13) for card in range(1, 11)}


def _score(hard: int, ace: bool) -> int:
    return hard + 10 if ace and hard + 10 <= 21 else hard


@cache
def _final_scores(hard: int, ace: bool, draw_below: int, coin: bool) -> dict[int, Fraction]:
    """Final score law (0: bust) of a hand that draws while its score is below `draw_below` (`coin`: draws
    with probability 1/2 at each decision instead, until it stops or busts). Written here from the
    rules in gymnasium's blackjack.py, independently of `reference.oracles.blackjack`."""
    if hard > 21:
        return {0: Fraction(1)}
    score = _score(hard, ace)
    stops = Fraction(1, 2) if coin else Fraction(int(score >= draw_below))
    law: dict[int, Fraction] = {score: stops} if stops else {}
    if stops < 1:
        for card, probability in _CARDS.items():
            for final, weight in _final_scores(hard + card, ace or card == 1, draw_below, coin).items():
                law[final] = law.get(final, Fraction(0)) + (1 - stops) * probability * weight
    return law


def _win_probability(draw_below: int, *, coin: bool = False) -> float:
    """P(player's score > dealer's) for two-card starts; the dealer shows one card and draws below 17."""
    player: dict[int, Fraction] = {}
    dealer: dict[int, Fraction] = {}
    for first, p_first in _CARDS.items():
        for second, p_second in _CARDS.items():
            start = (first + second, 1 in (first, second))
            for law, draw_below_, coin_ in ((player, draw_below, coin), (dealer, 17, False)):
                for final, weight in _final_scores(*start, draw_below_, coin_).items():
                    law[final] = law.get(final, Fraction(0)) + p_first * p_second * weight
    win = sum(
        p_player * sum((p for score, p in dealer.items() if score < final), Fraction(0))
        for final, p_player in player.items()
        if final > 0
    )
    return float(win)


def test_exact_curve_and_best_n() -> None:
    """The oracle's curve against an independent exact computation (fractions, written from the rules)."""
    curve = exact_curve()
    assert list(curve) == list(range(22))
    assert curve == pytest.approx({n: _win_probability(n + 1) for n in range(22)}, abs=1e-12)
    assert exact_best_n() == 13


def test_the_random_policy_win_probability_is_derived_independently() -> None:
    assert random_policy_outcome().win == pytest.approx(_win_probability(0, coin=True), abs=1e-12)


@pytest.mark.slow
def test_fixed_threshold_student_is_told_to_use_n(seed: int) -> None:
    def blackjack(lab, n, games=1000):  # type: ignore[no-untyped-def]
        env = lab.make("Blackjack-v0")
        wins = 0
        for _ in range(games):
            observation, _ = env.reset()
            done = False
            while not done:
                observation, reward, terminated, truncated, _ = env.step(int(observation[0] <= 16))
                done = terminated or truncated
            wins += reward > 0
        return wins / games

    verdict = grade("blackjack", {"blackjack": blackjack}, seed)
    assert verdict.status == "failed"
    assert "follow 'draw while the sum is <= 16' whatever n is: use the parameter n" in verdict.feedback


def test_too_few_games_fail_with_the_lab_number(seed: int) -> None:
    from grader.simulated_students.behaviours import blackjack

    settings = small_config("blackjack")
    verdict = grade("blackjack", {"blackjack": lambda lab, n: blackjack(lab, n, games=100)}, seed, settings)
    assert verdict.status == "failed"
    assert verdict.feedback.startswith(
        "blackjack(12) must play 1000 games (the lab's number); the replay shows 100."
    )


@pytest.mark.slow
def test_measurements_hold_both_curves(seed: int) -> None:
    from grader.simulated_students.behaviours import REFERENCE

    verdict = grade("blackjack", REFERENCE["blackjack"], seed)
    assert verdict.status == "passed"
    assert set(verdict.measurements["curve"]) == {"12", "13", "14", "20"}  # type: ignore[arg-type]
    assert verdict.measurements["exact_best_n"] == 13
    assert len(verdict.measurements["exact_curve"]) == 22  # type: ignore[arg-type]


@pytest.mark.slow
def test_a_failing_student_still_gets_the_whole_curve(seed: int) -> None:
    from grader.simulated_students.behaviours import MISTAKES

    (less_than,) = [mistake for mistake in MISTAKES if mistake.name == "blackjack_less_than"]
    verdict = grade("blackjack", less_than.functions, seed)
    assert verdict.status == "failed"
    assert verdict.feedback.startswith("blackjack(12) returned")
    assert set(verdict.measurements["curve"]) == {"12", "13", "14", "20"}  # type: ignore[arg-type]


def test_a_win_count_off_the_exact_law_fails_on_the_win_count_alone(seed: int) -> None:
    """The reference's rule on games dealt from ace to five only, judged as played: every decision follows
    the rule, the counts and returned rates are right, so only the exact two-sided binomial test of each
    call's win count can fail it (every call is judged; the first failure is reported).

    Statistic: wins in 1000 games per call against Binomial(1000, exact win probability of the rule),
    n = 12 accepted 341..493 (alpha 1e-6 per call, exact false-fail 8.8e-7; 13, 14, 20 alike). The low
    deck wins 0.0816 at n = 12, accepted with probability 6.2e-119 (0.0956, 0.1386, 0.4190 at 13, 14, 20:
    at most 6.7e-42), bench/verdict_power.py, bench/RESULTS.md.
    """
    from grader.simulated_students.behaviours import blackjack

    verdict = grade("blackjack", {"blackjack": on_low_deck(blackjack)}, seed, fast=True)
    assert verdict.status == "failed", verdict.feedback
    assert verdict.feedback.startswith(
        "blackjack(12): a player drawing on sums <= 12 wins 0.4162 of games (341..493 of 1000); "
        "your replayed games won "
    ), verdict.feedback
    assert verdict.feedback.endswith(
        # 1 / 8.8e-7, the exact false-fail probability of the interval 341..493 (bench/verdict_power.py)
        "The decisions followed the rule, so this is the 1-in-1,138,454 chance or not the lab's game: "
        "regrade once."
    ), verdict.feedback
    assert set(verdict.measurements["curve"]) == {"12", "13", "14", "20"}  # type: ignore[arg-type]


def _text(lab, n, games=1000):  # type: ignore[no-untyped-def]
    return "x"


def _same_seed(lab, n, games=1000):  # type: ignore[no-untyped-def]
    env = lab.make("Blackjack-v0")
    wins = 0
    for _ in range(games):
        observation, _ = env.reset(seed=42)
        done = False
        while not done:
            observation, reward, terminated, truncated, _ = env.step(int(observation[0] <= n))
            done = terminated or truncated
        wins += reward > 0
    return wins / games


def _average_reward(lab, n, games=1000):  # type: ignore[no-untyped-def]
    from grader.simulated_students.behaviours import _play_blackjack

    env = lab.make("Blackjack-v0")
    return (
        sum(_play_blackjack(env, lambda observation, _step: int(observation[0] <= n)) for _ in range(games))
        / games
    )


def _reset_options(lab, n, games=1000):  # type: ignore[no-untyped-def]
    from grader.simulated_students.behaviours import blackjack

    lab.make("Blackjack-v0").reset(options={"x": 1})
    return blackjack(lab, n, games)


@pytest.mark.slow
@pytest.mark.parametrize(
    ("function", "diagnosis"),
    [
        (_text, "blackjack(12) returned 'x'; expected the win rate as a number."),
        (
            _same_seed,
            "blackjack(12): 1000 episodes were reset with the same seed (42), so outside the grader they are "
            "the same game played 1000 times",
        ),
        (
            _average_reward,
            "blackjack(12) returned -0.",  # then the replay's win count, named as the average reward
        ),
        (
            _reset_options,
            "blackjack: 4 reset(s) passed options (e.g. reset 1: options={'x': 1}), which choose the start "
            "of the game",
        ),
    ],
    ids=["not-a-number", "repeated-seed", "average-reward", "integrity"],
)
def test_each_diagnosis_fails_a_sample_of_its_own(function, diagnosis: str, seed: int) -> None:  # type: ignore[no-untyped-def]
    verdict = grade("blackjack", {"blackjack": function}, seed)
    assert verdict.status == "failed"
    assert verdict.feedback.startswith(diagnosis), verdict.feedback
    if function is _average_reward:
        assert verdict.feedback.endswith(
            "it equals the average reward (wins minus losses per game), not the win rate."
        )
