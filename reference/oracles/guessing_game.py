"""Exact distribution of the number of guesses a midpoint search takes in GuessingGame-v0.

The game (classic gym's `GuessingGame-v0`, registered by gymgrade): the target is drawn uniformly from
[-1000, 1000); a guess is answered 1 (below the target), 2 (equal) or 3 (above); the game is won, and
ends, when a guess lies strictly within 10 of the target; it ends anyway after the 200th guess.

The lab's strategy keeps the interval where the target lies, starting from [-1000, 1000], and always
guesses its midpoint; an answer 1 moves the lower end to the guess, an answer 3 the upper end. Given the
target, the guesses and so their number are fixed, so the distribution of the number of guesses is a sum
of lengths of target intervals: computed here in exact rational arithmetic, interval by interval.
The target is a float64 drawn as `-1000 + 2000 * u` with a 53-bit `u`; treating it as continuous changes
no probability by more than 2**-40.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from fractions import Fraction
from functools import cache

from reference.errors import InvalidParameterError

TARGET_LOW = -1000
TARGET_HIGH = 1000
"""The target is uniform on [TARGET_LOW, TARGET_HIGH) (`range = 1000` in the game's source)."""
TOLERANCE = 10
"""A guess wins when it is strictly within this distance of the target (1% of `range`)."""
MAX_GUESSES = 200
"""The game ends (truncated) after this many guesses."""


@dataclass(frozen=True)
class GuessCounts:
    """The distribution of the number of guesses one game takes.

    Attributes:
        probabilities: `probabilities[k - 1]` is the probability that the game takes exactly k guesses,
            for k = 1 .. MAX_GUESSES at most (trailing zeros dropped); they sum to 1.
    """

    probabilities: tuple[float, ...]

    @property
    def mean(self) -> float:
        """Expected number of guesses."""
        return math.fsum(count * p for count, p in enumerate(self.probabilities, 1))

    @property
    def variance(self) -> float:
        """Variance of the number of guesses."""
        second = math.fsum(count * count * p for count, p in enumerate(self.probabilities, 1))
        return max(second - self.mean**2, 0.0)

    @property
    def most(self) -> int:
        """The largest number of guesses with a positive probability."""
        return len(self.probabilities)

    def probability(self, count: int) -> float:
        """The probability that a game takes exactly `count` guesses (0 outside 1 .. `most`)."""
        return self.probabilities[count - 1] if 1 <= count <= self.most else 0.0


@cache
def midpoint_guess_counts(low: float = TARGET_LOW, high: float = TARGET_HIGH) -> GuessCounts:
    """The exact distribution of the number of guesses of a midpoint search starting from [low, high].

    The lab's strategy is the default, [-1000, 1000]; another start (e.g. the guess space's
    [-10000, 10000]) gives the distribution of that search in the same game.

    Args:
        low: Lower end of the first interval.
        high: Upper end of the first interval, greater than `low`.

    Returns:
        The distribution (exact rationals rounded once to floats).

    Raises:
        InvalidParameterError: `low` and `high` are not finite numbers with low < high.
    """
    if not (math.isfinite(low) and math.isfinite(high) and low < high):
        raise InvalidParameterError(
            f"expected a first interval [low, high] of finite numbers with low < high, found [{low}, {high}]"
        )
    weights = _count_weights(Fraction(low), Fraction(high))
    width = Fraction(TARGET_HIGH - TARGET_LOW)
    most = max(count for count, weight in weights.items() if weight > 0)
    return GuessCounts(tuple(float(weights.get(count, 0) / width) for count in range(1, most + 1)))


def _count_weights(low: Fraction, high: Fraction) -> dict[int, Fraction]:
    """Length of the set of targets that take each number of guesses (exact)."""
    weights: dict[int, Fraction] = {}
    tolerance = Fraction(TOLERANCE)
    # (search interval, targets still in play within it, guesses made): targets within the tolerance of
    # an end that was a guess have already won, so the targets in play are a sub-interval.
    pending = [(low, high, Fraction(TARGET_LOW), Fraction(TARGET_HIGH), 0)]
    while pending:
        low, high, first, last, made = pending.pop()
        if last <= first:
            continue
        if made == MAX_GUESSES:
            weights[made] = weights.get(made, Fraction(0)) + last - first
            continue
        guess = (low + high) / 2
        won = min(last, guess + tolerance) - max(first, guess - tolerance)
        if won > 0:
            weights[made + 1] = weights.get(made + 1, Fraction(0)) + won
        pending.append((guess, high, max(first, guess + tolerance), last, made + 1))
        pending.append((low, guess, first, min(last, guess - tolerance), made + 1))
    return weights
