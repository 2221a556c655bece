"""Simulated `epsilon_decay` students (edition rl1): an honest one and the typical mistakes.

Each is run by `grader.simulated_students.simulation` (first argument: the simulated `Lab`, unused by a pure
function). A student is a decay formula of `(episode, N, epsilon_start, epsilon_end)` given the lab's
signature by `student` (or `student_with_exp`, which also takes `decay_type`). `MISTAKES` maps a name to
the function and the words its feedback must contain; `submissions/editions/` holds the same mistakes as
real student files.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

Decay = Callable[[int, int, float, float], float]
"""A decay formula: epsilon for `(episode, N, epsilon_start, epsilon_end)`."""


def student(decay: Decay) -> Callable[..., float]:
    """`decay` as the lab's `epsilon_decay(episode, N, epsilon_start=1.0, epsilon_end=1e-6)`."""

    def epsilon_decay(
        _lab: Any, episode: int, N: int, epsilon_start: float = 1.0, epsilon_end: float = 1e-6
    ) -> float:
        return decay(episode, N, epsilon_start, epsilon_end)

    return epsilon_decay


def student_with_exp(linear: Decay, exp: Decay) -> Callable[..., float]:
    """`linear`, and `exp` for `decay_type="exp"` (the additional materials' optional parameter)."""

    def epsilon_decay(
        _lab: Any,
        episode: int,
        N: int,
        epsilon_start: float = 1.0,
        epsilon_end: float = 1e-6,
        decay_type: str = "linear",
    ) -> float:
        decay = exp if decay_type == "exp" else linear
        return decay(episode, N, epsilon_start, epsilon_end)

    return epsilon_decay


def _lab_formula(episode: int, n: int, start: float, end: float) -> float:
    delta = (start - end) / n
    return start - (episode - 1) * delta


def _linear(episode: int, n: int, start: float, end: float) -> float:
    return start - (episode - 1) * (start - end) / n


def _exponential(episode: int, n: int, start: float, end: float) -> float:
    return float(start * (end / start) ** (episode / n))


def _fraction_of_the_way(episode: int, n: int, start: float, end: float) -> float:
    fraction = (episode - 1) / n
    return (1 - fraction) * start + fraction * end


def _loop(episode: int, n: int, start: float, end: float) -> float:
    delta = (start - end) / n
    epsilon = start
    for _ in range(episode - 1):
        epsilon -= delta
    return epsilon


def _end_at_last(episode: int, n: int, start: float, end: float) -> float:
    return end if episode >= n else _linear(episode, n, start, end)


def _exp_from_zero(episode: int, n: int, start: float, end: float) -> float:
    return float(start * (end / start) ** ((episode - 1) / n))


honest = student_with_exp(_lab_formula, _exponential)
"""The lab's linear decay, and the additional materials' exponential one."""
honest_rewritten = student(_fraction_of_the_way)
"""The same decay written another way (a fraction of the way from start to end): equal up to rounding."""
honest_loop = student(_loop)
"""The decay applied once per episode: rounding accumulates, within the check's tolerance."""

HONEST = {"formula": honest, "rewritten": honest_rewritten, "loop": honest_loop}
"""Honest ways to write the linear decay: each must pass."""

zero_based = student(lambda episode, n, start, end: start - episode * (start - end) / n)
divides_by_n_minus_1 = student(lambda episode, n, start, end: start - (episode - 1) * (start - end) / (n - 1))
end_at_last = student(_end_at_last)
ignores_bounds = student(lambda episode, n, _start, _end: _linear(episode, n, 1.0, 1e-6))
decays_to_zero = student(lambda episode, n, start, _end: start - (episode - 1) * start / n)
exponential = student(_exponential)
floor_division = student(lambda episode, n, start, end: start - (episode - 1) * ((start - end) // n))
exp_off_by_one = student_with_exp(_linear, _exp_from_zero)
"""Right linear decay; the optional exponential one counts episodes from 0."""
returns_nan = student(
    lambda episode, n, start, end: math.nan if episode == n else _linear(episode, n, start, end)
)

MISTAKES: dict[str, tuple[Any, str]] = {
    "zero_based": (zero_based, "0-based episodes"),
    "divides_by_n_minus_1": (divides_by_n_minus_1, "divide by N - 1"),
    "end_at_last": (end_at_last, "where you return epsilon_end"),
    "ignores_bounds": (ignores_bounds, "ignore the epsilon_start and epsilon_end passed in"),
    "decays_to_zero": (decays_to_zero, "decay to 0 rather than to epsilon_end"),
    "exponential": (exponential, "decay exponentially"),
    "floor_division": (floor_division, "expected epsilon_start - (episode - 1) * delta"),
    "returns_nan": (returns_nan, "returned no finite number"),
}
"""Mistakes of the linear decay: (the function, words its feedback must contain). Each must fail."""
