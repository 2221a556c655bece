"""Reading what a student function returned: numbers, win rates as fractions or percentages."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np

Scale = Literal["fraction", "percentage"]
_SCALES: tuple[tuple[Scale, float], ...] = (("fraction", 1.0), ("percentage", 100.0))


def as_number(value: Any) -> float | None:
    """The value as a float when it is a real number (not a bool), else None."""
    if isinstance(value, bool) or not isinstance(value, int | float):
        return None
    return float(value)


def describe(value: Any) -> str:
    """A short readable rendering of a returned value for feedback."""
    if isinstance(value, float):
        return f"{value:.6g}"
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


def same_number(returned: float, recomputed: float) -> bool:
    """Whether a returned number is the recomputed one, allowing float rounding and rounding to >= 2 decimals.

    A student may return ``round(100 * wins / n, 2)`` or the result in single precision
    (``np.float32(wins / n)``, a numpy array's sum or mean); that is still the replayed result. Any
    rounding coarser than two decimals, or any other difference, is not.
    """
    if math.isclose(returned, recomputed, rel_tol=1e-9, abs_tol=1e-12):
        return True
    if returned == float(np.float32(recomputed)):
        return True
    return any(math.isclose(returned, round(recomputed, digits), abs_tol=1e-12) for digits in range(2, 16))


def chance_text(probability: float) -> str:
    """A false-fail probability as readable odds ("the 1-in-1,090,000 chance")."""
    if probability <= 0:
        return "a practically impossible chance"
    return f"the 1-in-{1 / probability:,.0f} chance"


@dataclass(frozen=True)
class GameCounts:
    """Results of a set of replayed games with rewards +1 (win), 0 (draw), -1 (loss).

    Attributes:
        games: Number of games.
        wins: Games with a positive total reward.
        draws: Games with total reward 0.
        reward_total: Sum of all games' total rewards.
    """

    games: int
    wins: int
    draws: int
    reward_total: float

    @property
    def win_fraction(self) -> float:
        """Share of games won."""
        return self.wins / self.games if self.games else 0.0


def read_rate(returned: float, counts: GameCounts) -> Scale | None:
    """Whether the returned win rate is the replayed one as a fraction or as a percentage, or neither."""
    for scale, factor in _SCALES:
        if same_number(returned, factor * counts.win_fraction):
            return scale
    return None


def rate_mismatch_cause(returned: float, counts: GameCounts) -> str:
    """The likely cause of a returned win rate that the replayed games do not support."""
    games = max(counts.games, 1)
    for scale, factor in _SCALES:
        candidates = (
            (
                counts.reward_total / games,
                "the average reward (wins minus losses per game), not the win rate",
            ),
            ((counts.wins + counts.draws) / games, "draws counted as wins"),
            (counts.wins, "the number of wins, not the share of games won"),
            (1 - counts.win_fraction, "the share of games NOT won"),
        )
        for candidate, cause in candidates:
            if same_number(returned, factor * candidate):
                return f"it equals {cause}" + (" (as a percentage)" if scale == "percentage" else "")
    if returned > 100 or returned < 0:
        return "a win rate is a number between 0 and 1 (or 0 and 100 as a percentage)"
    return "no count of the replayed games gives this number: return the wins divided by the games played"


def step_count_mismatch_cause(returned: float, steps: int, wall_time: float) -> str:
    """The likely cause of a returned step count that differs from the replayed episode length."""
    if returned == steps + 1 or returned == steps - 1:
        return "it is off by one: count one step per env.step() call, starting from 0 after reset()"
    if not float(returned).is_integer():
        if 0 <= returned <= max(10 * wall_time, 1.0):
            return (
                f"it looks like elapsed time in seconds (the call ran {wall_time:.3g} s), not a number of steps: "  # noqa: E501
                "count the env.step() calls instead of timing them"
            )
        return "a number of steps is a whole number: count the env.step() calls"
    return "it is not the length of the episode the call played: return the number of env.step() calls made"
