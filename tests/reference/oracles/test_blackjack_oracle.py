"""Tests for reference/oracles/blackjack.py: exact identities, Monte-Carlo runs of gymnasium's Blackjack."""

from __future__ import annotations

import math
from collections import Counter

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.envs.toy_text import blackjack as gymnasium_blackjack

from reference.errors import InvalidProbabilityError, ThresholdOutOfRangeError
from reference.oracles.blackjack import (
    CARD_PROBABILITIES,
    HitProbability,
    Outcome,
    dealer_final_scores,
    dealer_natural_probability,
    evaluate_policy,
    random_policy_outcome,
    threshold_policy_outcome,
    threshold_start_outcome,
)

Z_LIMIT = 5.0
"""Two-sided P(|Z| > 5) = 5.7e-7 for one normal statistic."""

NEVER_AND_ALWAYS = "n = 0 never hits and n = 21 always hits until the hand busts"
LARGEST_SUM = "pass the largest player sum on which the player still hits"


def _hit_on_soft_hands_and_strong_dealers(player_sum: int, dealer_card: int, usable_ace: bool) -> float:
    if player_sum >= 20:
        return 0.0
    if usable_ace:
        return 0.9
    return 0.7 if dealer_card in (1, 7, 8, 9, 10) else 0.25


POLICIES: dict[str, tuple[HitProbability, bool]] = {
    "random": (lambda _s, _d, _a: 0.5, False),
    "random-sab": (lambda _s, _d, _a: 0.5, True),
    "never-hit": (lambda _s, _d, _a: 0.0, False),
    "threshold-13": (lambda s, _d, _a: float(s <= 13), False),
    "threshold-17-sab": (lambda s, _d, _a: float(s <= 17), True),
    "threshold-20": (lambda s, _d, _a: float(s <= 20), False),
    "state-dependent-random": (_hit_on_soft_hands_and_strong_dealers, False),
}


def _play(hit_probability: HitProbability, sab: bool, games: int, seed: int) -> Counter[float]:
    env = gym.make("Blackjack-v1", natural=False, sab=sab)
    choice = np.random.default_rng(seed + 1)
    rewards: Counter[float] = Counter()
    for game in range(games):
        observation, _ = env.reset(seed=seed if game == 0 else None)
        terminated = False
        while not terminated:
            player_sum, dealer_card, usable_ace = observation
            action = int(choice.random() < hit_probability(player_sum, dealer_card, bool(usable_ace)))
            observation, reward, terminated, _, _ = env.step(action)
        rewards[float(reward)] += 1
    return rewards


def _z(successes: int, trials: int, probability: float) -> float:
    if probability in (0.0, 1.0):
        return 0.0 if successes == probability * trials else math.inf
    return (successes / trials - probability) / math.sqrt(probability * (1 - probability) / trials)


@pytest.mark.slow
@pytest.mark.parametrize("name", POLICIES, ids=POLICIES)
def test_outcome_matches_monte_carlo_on_the_real_environment(name: str, seed: int) -> None:
    # 3 z-tests (win, draw, loss) at 5 sigma over 20 000 games: false-fail probability <= 1.8e-6.
    hit_probability, sab = POLICIES[name]
    outcome = evaluate_policy(hit_probability, sab=sab)
    games = 20_000
    rewards = _play(hit_probability, sab, games, seed)
    assert set(rewards) <= {-1.0, 0.0, 1.0}
    for count, probability in [
        (rewards[1.0], outcome.win),
        (rewards[0.0], outcome.draw),
        (rewards[-1.0], outcome.loss),
    ]:
        assert abs(_z(count, games, probability)) < Z_LIMIT, (name, dict(rewards), outcome)


@pytest.mark.slow
@pytest.mark.parametrize("showing_card", range(1, 11), ids=lambda card: f"showing-{card}")
def test_dealer_final_scores_match_the_dealer_hands_of_the_real_environment(
    showing_card: int, seed: int
) -> None:
    # The env deals with its own np_random; we deal the dealer's hand through gymnasium's own draw_card and
    # play it out with gymnasium's sum_hand/score, so the rules are gymnasium's.  6 z-tests at 5 sigma over
    # 20 000 hands: false-fail probability <= 3.4e-6.
    generator = np.random.default_rng(seed)
    hands = 20_000
    scores: Counter[int] = Counter()
    for _ in range(hands):
        dealer = [showing_card, gymnasium_blackjack.draw_card(generator)]
        while gymnasium_blackjack.sum_hand(dealer) < 17:
            dealer.append(gymnasium_blackjack.draw_card(generator))
        scores[gymnasium_blackjack.score(dealer)] += 1
    exact = dealer_final_scores(showing_card)
    assert set(scores) <= set(exact)
    for score, probability in exact.items():
        assert abs(_z(scores[score], hands, probability)) < Z_LIMIT, (score, scores, exact)


def test_the_deck_is_gymnasiums_deck() -> None:
    deck = Counter(gymnasium_blackjack.deck)
    assert {card: count / len(gymnasium_blackjack.deck) for card, count in deck.items()} == CARD_PROBABILITIES


@pytest.mark.parametrize(
    "outcome",
    [random_policy_outcome(), random_policy_outcome(sab=True)]
    + [threshold_policy_outcome(n, sab=sab) for n in range(22) for sab in (False, True)],
    ids=["random", "random-sab"]
    + [f"n={n}{'-sab' if sab else ''}" for n in range(22) for sab in (False, True)],
)
def test_probabilities_sum_to_one(outcome: Outcome) -> None:
    assert outcome.win + outcome.draw + outcome.loss == pytest.approx(1.0, abs=1e-12)
    assert min(outcome.win, outcome.draw, outcome.loss) >= -1e-15


@pytest.mark.parametrize("showing_card", range(1, 11), ids=lambda card: f"showing-{card}")
def test_dealer_scores_are_a_distribution_over_bust_and_17_to_21(showing_card: int) -> None:
    scores = dealer_final_scores(showing_card)
    assert set(scores) <= {0, 17, 18, 19, 20, 21}
    assert sum(scores.values()) == pytest.approx(1.0, abs=1e-12)


def test_thresholds_below_6_are_the_same_game() -> None:
    # Hitting on 4 or 5 reaches at most 16 (5 + an ace counted as 11), and every sum <= 16 wins exactly
    # when the dealer busts, so thresholds 0..5 all play the same game; 6 can reach 17.
    assert len({threshold_policy_outcome(n) for n in range(6)}) == 1
    assert threshold_policy_outcome(6) != threshold_policy_outcome(5)


def test_always_hitting_always_busts() -> None:
    outcome = threshold_policy_outcome(21)
    assert (outcome.win, outcome.draw, outcome.loss) == pytest.approx((0.0, 0.0, 1.0), abs=1e-12)


def test_best_threshold_is_13() -> None:
    wins = {n: threshold_policy_outcome(n).win for n in range(22)}
    assert max(wins, key=wins.__getitem__) == 13


def test_constant_half_policy_is_the_random_policy() -> None:
    assert evaluate_policy(lambda _s, _d, _a: 0.5) == random_policy_outcome()


def test_sab_turns_a_players_natural_against_a_non_natural_21_into_a_win() -> None:
    # Standing on everything: sab only changes games where the player holds a natural and the dealer
    # ends on 21 without one; those move from draw to win.  Nothing else may change.
    never_hit = threshold_policy_outcome(0)
    never_hit_sab = threshold_policy_outcome(0, sab=True)
    player_natural = 2 * CARD_PROBABILITIES[1] * CARD_PROBABILITIES[10]
    moved = player_natural * sum(
        probability * (dealer_final_scores(card).get(21, 0.0) - dealer_natural_probability(card))
        for card, probability in CARD_PROBABILITIES.items()
    )
    assert moved > 0.003
    assert never_hit_sab.win - never_hit.win == pytest.approx(moved, abs=1e-14)
    assert never_hit.draw - never_hit_sab.draw == pytest.approx(moved, abs=1e-14)
    assert never_hit_sab.loss == pytest.approx(never_hit.loss, abs=1e-14)


def test_sab_changes_nothing_for_a_player_who_never_sticks_on_21() -> None:
    assert threshold_policy_outcome(21, sab=True) == threshold_policy_outcome(21)


def test_policy_sees_gymnasiums_observations() -> None:
    seen: set[tuple[int, int, bool]] = set()

    def record(player_sum: int, dealer_card: int, usable_ace: bool) -> float:
        seen.add((player_sum, dealer_card, usable_ace))
        return 0.5

    evaluate_policy(record)
    assert {dealer for _, dealer, _ in seen} == set(range(1, 11))
    assert {total for total, _, ace in seen if ace} == set(range(12, 22))
    assert {total for total, _, ace in seen if not ace} == set(range(4, 22))


@pytest.mark.parametrize(
    ("n", "message"),
    [
        (
            -1,
            "expected a threshold n in 0..21, found -1; " + NEVER_AND_ALWAYS,
        ),
        (
            22,
            "expected a threshold n in 0..21, found 22; " + NEVER_AND_ALWAYS,
        ),
        (
            1.5,
            "expected a threshold n as an integer in 0..21, found 1.5; " + LARGEST_SUM,
        ),
        (
            True,
            "expected a threshold n as an integer in 0..21, found True; " + LARGEST_SUM,
        ),
        (
            "11",
            "expected a threshold n as an integer in 0..21, found '11'; " + LARGEST_SUM,
        ),
    ],
    ids=["negative", "above-21", "float", "bool", "string"],
)
def test_threshold_out_of_range_is_refused(n: object, message: str) -> None:
    with pytest.raises(ThresholdOutOfRangeError) as raised:
        threshold_policy_outcome(n)  # type: ignore[arg-type]
    assert str(raised.value) == message


def test_threshold_accepts_numpy_integers() -> None:
    assert threshold_policy_outcome(np.int64(13)) == threshold_policy_outcome(13)


@pytest.mark.parametrize(
    "value", [1.5, -0.1, float("nan"), "yes", None], ids=["above-1", "negative", "nan", "string", "none"]
)
def test_hit_probability_outside_0_1_is_refused(value: object) -> None:
    with pytest.raises(InvalidProbabilityError) as raised:
        evaluate_policy(lambda _s, _d, _a: value)  # type: ignore[arg-type, return-value]
    assert str(raised.value).endswith(
        f"returned {value!r}; expected a probability in [0, 1]: "
        "return 1.0 to always hit and 0.0 to always stick"
    )
    assert str(raised.value).startswith("hit_probability(")


@pytest.mark.parametrize("sab", [False, True], ids=["lab", "sab"])
@pytest.mark.parametrize("n", [0, 12, 13, 20])
def test_start_outcomes_average_to_the_policy_outcome(n: int, sab: bool) -> None:
    win = 0.0
    for dealer, dealer_probability in CARD_PROBABILITIES.items():
        for first, first_probability in CARD_PROBABILITIES.items():
            for second, second_probability in CARD_PROBABILITIES.items():
                usable = 1 in (first, second) and first + second + 10 <= 21
                player_sum = first + second + (10 if usable else 0)
                start = threshold_start_outcome((player_sum, dealer, usable), n, sab=sab)
                win += dealer_probability * first_probability * second_probability * start.win
    assert win == pytest.approx(threshold_policy_outcome(n, sab=sab).win, abs=1e-12)
