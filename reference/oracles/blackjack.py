"""Exact win/draw/loss probabilities of Blackjack policies under gymnasium's `BlackjackEnv` rules.

The rules, read from `gymnasium/envs/toy_text/blackjack.py` (gymnasium 1.4):

* Cards come from an infinite deck: 1 (ace) to 9 with probability 1/13 each, 10 with probability 4/13
  (ten, jack, queen, king).
* The dealer and the player get two cards each; the observation is
  `(player_sum, dealer_showing_card, usable_ace)` where `player_sum` counts one ace as 11 whenever that
  does not take the hand over 21 (that ace is then "usable").
* Hit (action 1): the player takes a card; above 21 the game ends at once with reward -1.
* Stick (action 0): the dealer draws while their sum (usable ace counted as 11) is below 17, then the
  higher score wins (a busted dealer scores 0); equal scores draw.
* `natural=False` (the lab's game): a natural pays like any other win. With `sab=True` (Sutton and
  Barto's rules, the registered default of `Blackjack-v1`), a player who sticks on a natural (an ace and
  a ten-card as the two first cards) wins unless the dealer also holds a natural, which is a draw.

Policies are evaluated by exact recursion over the player's hand (hard sum, holds an ace) for each
dealer card; the only error is floating-point rounding (about 1e-15).
"""

from __future__ import annotations

import math
import operator
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from functools import cache

from reference.errors import InvalidProbabilityError, ThresholdOutOfRangeError

CARD_PROBABILITIES: dict[int, float] = {card: (4 if card == 10 else 1) / 13 for card in range(1, 11)}
"""Probability of each card value in gymnasium's infinite deck."""

BLACKJACK = 21
DEALER_STANDS_AT = 17
LARGEST_THRESHOLD = 21
"""`threshold_policy_outcome(21)` hits on every sum up to 21, so it always busts."""

HitProbability = Callable[[int, int, bool], float]
"""`hit_probability(player_sum, dealer_card, usable_ace)`: the probability of drawing another card."""

_Probabilities = tuple[float, float, float]
"""(win, draw, loss) while a game is being evaluated."""

_LOSS: _Probabilities = (0.0, 0.0, 1.0)


@dataclass(frozen=True)
class Outcome:
    """Probabilities that one game ends in a win, a draw or a loss for the player.

    Attributes:
        win: probability of reward +1.
        draw: probability of reward 0.
        loss: probability of reward -1.
    """

    win: float
    draw: float
    loss: float

    @property
    def expected_reward(self) -> float:
        """Expected reward of one game (natural=False pays +1 for every win)."""
        return self.win - self.loss


def evaluate_policy(hit_probability: HitProbability, *, sab: bool = False) -> Outcome:
    """Exact outcome probabilities of a (possibly random) Blackjack policy.

    Args:
        hit_probability: `hit_probability(player_sum, dealer_card, usable_ace)` returns the probability
            of hitting when the observation is `(player_sum, dealer_card, usable_ace)`. It must depend on
            the observation only: answers are memoised per hand.
        sab: evaluate the game `gym.make("Blackjack-v1", sab=True)` instead of the lab's
            `natural=False, sab=False` game.

    Returns:
        The win, draw and loss probabilities of one game from a fresh reset.

    Raises:
        InvalidProbabilityError: `hit_probability` returned something outside [0, 1].
    """
    total: _Probabilities = (0.0, 0.0, 0.0)
    for dealer_card, dealer_probability in CARD_PROBABILITIES.items():
        game = _PlayerGame(hit_probability, dealer_card, sab)
        for first, first_probability in CARD_PROBABILITIES.items():
            for second, second_probability in CARD_PROBABILITIES.items():
                weight = dealer_probability * first_probability * second_probability
                is_natural = {first, second} == {1, 10}
                total = _add(
                    total, _scale(game.start(first + second, 1 in (first, second), is_natural), weight)
                )
    return Outcome(*total)


def random_policy_outcome(*, sab: bool = False) -> Outcome:
    """Exact outcome of the lab's random player: hit with probability 1/2 at every decision.

    Args:
        sab: evaluate the `sab=True` game instead of the lab's.

    Returns:
        The win, draw and loss probabilities of one game.
    """
    return _random_policy_outcome(sab)


def threshold_policy_outcome(n: int, *, sab: bool = False) -> Outcome:
    """Exact outcome of the lab's naive player: hit while the observed player sum is <= n.

    Args:
        n: the threshold, 0..21; below 4 the player never hits, at 21 the player always busts.
        sab: evaluate the `sab=True` game instead of the lab's.

    Returns:
        The win, draw and loss probabilities of one game.

    Raises:
        ThresholdOutOfRangeError: `n` is not an integer in 0..21.
    """
    return _threshold_policy_outcome(_checked_threshold(n), sab)


def threshold_start_outcome(observation: tuple[int, int, bool], n: int, *, sab: bool = False) -> Outcome:
    """Exact outcome of the threshold player from one dealt start (the reset's observation).

    Args:
        observation: `(player_sum, dealer_card, usable_ace)` of a fresh reset (two cards each); a
            player sum of 21 with a usable ace is a natural.
        n: the threshold, 0..21 (hit while the observed player sum is <= n).
        sab: evaluate the `sab=True` game instead of the lab's.

    Returns:
        The win, draw and loss probabilities of the game from that start.

    Raises:
        ThresholdOutOfRangeError: `n` is not an integer in 0..21.
    """
    return Outcome(
        *_threshold_start(
            int(observation[0]), int(observation[1]), bool(observation[2]), _checked_threshold(n), sab
        )
    )


@cache
def _threshold_start(
    player_sum: int, dealer_card: int, usable_ace: bool, n: int, sab: bool
) -> _Probabilities:
    game = _threshold_game(dealer_card, n, sab)
    hard_sum = player_sum - 10 if usable_ace else player_sum
    return game.start(hard_sum, usable_ace, usable_ace and player_sum == BLACKJACK)


@cache
def _threshold_game(dealer_card: int, n: int, sab: bool) -> _PlayerGame:
    return _PlayerGame(lambda player_sum, _card, _ace: float(player_sum <= n), dealer_card, sab)


@cache
def _random_policy_outcome(sab: bool) -> Outcome:
    return evaluate_policy(lambda _sum, _card, _ace: 0.5, sab=sab)


@cache
def _threshold_policy_outcome(n: int, sab: bool) -> Outcome:
    return evaluate_policy(lambda player_sum, _card, _ace: float(player_sum <= n), sab=sab)


def _checked_threshold(n: object) -> int:
    try:
        if isinstance(n, bool):
            raise TypeError
        threshold = operator.index(n)  # type: ignore[arg-type]
    except TypeError:
        raise ThresholdOutOfRangeError(
            f"expected a threshold n as an integer in 0..{LARGEST_THRESHOLD}, found {n!r}; "
            f"pass the largest player sum on which the player still hits"
        ) from None
    if not 0 <= threshold <= LARGEST_THRESHOLD:
        raise ThresholdOutOfRangeError(
            f"expected a threshold n in 0..{LARGEST_THRESHOLD}, found {threshold}; "
            f"n = 0 never hits and n = {LARGEST_THRESHOLD} always hits until the hand busts"
        )
    return threshold


class _PlayerGame:
    """The player's decisions against one dealer showing card, memoised per hand."""

    def __init__(self, hit_probability: HitProbability, dealer_card: int, sab: bool) -> None:
        self._hit_probability = hit_probability
        self._dealer_card = dealer_card
        self._sab = sab
        self._dealer_scores = _dealer_final_scores(dealer_card)
        self._from_hand = cache(self._play)

    def start(self, hard_sum: int, has_ace: bool, is_natural: bool) -> _Probabilities:
        """Outcome from the two first cards (only there can a hand be a natural)."""
        if self._sab and is_natural:
            dealer_natural = dealer_natural_probability(self._dealer_card)
            return self._decide(hard_sum, has_ace, (1.0 - dealer_natural, dealer_natural, 0.0))
        return self._from_hand(hard_sum, has_ace)

    def _play(self, hard_sum: int, has_ace: bool) -> _Probabilities:
        return self._decide(hard_sum, has_ace, self._stick(_observed(hard_sum, has_ace)[0]))

    def _decide(self, hard_sum: int, has_ace: bool, stick: _Probabilities) -> _Probabilities:
        player_sum, usable_ace = _observed(hard_sum, has_ace)
        hit = _checked_probability(
            self._hit_probability(player_sum, self._dealer_card, usable_ace),
            (player_sum, self._dealer_card, usable_ace),
        )
        if hit == 0.0:
            return stick
        after_hit = _mix(
            (
                probability,
                _LOSS
                if hard_sum + card > BLACKJACK
                else self._from_hand(hard_sum + card, has_ace or card == 1),
            )
            for card, probability in CARD_PROBABILITIES.items()
        )
        return _mix([(hit, after_hit), (1.0 - hit, stick)])

    def _stick(self, player_score: int) -> _Probabilities:
        win = sum(p for dealer_score, p in self._dealer_scores.items() if dealer_score < player_score)
        draw = self._dealer_scores.get(player_score, 0.0)
        return (win, draw, 1.0 - win - draw)


def dealer_final_scores(showing_card: int) -> dict[int, float]:
    """Distribution of the dealer's final score given the showing card (0 stands for a bust).

    Args:
        showing_card: the dealer's face-up card, 1 (ace) to 10.

    Returns:
        `{score: probability}` over the scores 0 and 17..21.
    """
    return dict(_dealer_final_scores(showing_card))


@cache
def _dealer_final_scores(showing_card: int) -> dict[int, float]:
    return _dealer_scores_from(showing_card, showing_card == 1, cards_to_draw=1)


def dealer_natural_probability(showing_card: int) -> float:
    """Probability that the dealer's hidden card completes a natural (ace and ten-card)."""
    if showing_card == 1:
        return CARD_PROBABILITIES[10]
    if showing_card == 10:
        return CARD_PROBABILITIES[1]
    return 0.0


def _dealer_scores_from(hard_sum: int, has_ace: bool, cards_to_draw: int) -> dict[int, float]:
    dealer_sum, _ = _observed(hard_sum, has_ace)
    if cards_to_draw == 0 and dealer_sum >= DEALER_STANDS_AT:
        return {0 if dealer_sum > BLACKJACK else dealer_sum: 1.0}
    scores: dict[int, float] = {}
    for card, probability in CARD_PROBABILITIES.items():
        following = _dealer_scores_from(hard_sum + card, has_ace or card == 1, max(cards_to_draw - 1, 0))
        for score, score_probability in following.items():
            scores[score] = scores.get(score, 0.0) + probability * score_probability
    return scores


def _observed(hard_sum: int, has_ace: bool) -> tuple[int, bool]:
    """gymnasium's `sum_hand` and `usable_ace` for a hand summing to `hard_sum` with aces counted as 1."""
    usable_ace = has_ace and hard_sum + 10 <= BLACKJACK
    return (hard_sum + 10 if usable_ace else hard_sum), usable_ace


def _checked_probability(value: object, observation: tuple[int, int, bool]) -> float:
    try:
        probability = float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        probability = math.nan
    if not 0.0 <= probability <= 1.0:
        player_sum, dealer_card, usable_ace = observation
        raise InvalidProbabilityError(
            f"hit_probability({player_sum}, {dealer_card}, {usable_ace}) returned {value!r}; expected a "
            f"probability in [0, 1]: return 1.0 to always hit and 0.0 to always stick"
        )
    return probability


def _scale(probabilities: _Probabilities, weight: float) -> _Probabilities:
    return (probabilities[0] * weight, probabilities[1] * weight, probabilities[2] * weight)


def _add(left: _Probabilities, right: _Probabilities) -> _Probabilities:
    return (left[0] + right[0], left[1] + right[1], left[2] + right[2])


def _mix(weighted: Iterable[tuple[float, _Probabilities]]) -> _Probabilities:
    total: _Probabilities = (0.0, 0.0, 0.0)
    for weight, probabilities in weighted:
        total = _add(total, _scale(probabilities, weight))
    return total
