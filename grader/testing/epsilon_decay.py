"""Simulated `epsilon_decay` students (edition rl1): an honest one and the typical mistakes.

Each is run by `grader.testing.simulation` (first argument: the simulated `Lab`, unused by a pure
function). `MISTAKES` maps a name to the function and the words its feedback must contain;
`submissions/editions/` holds the same mistakes as real student files.
"""

from __future__ import annotations

import math
from typing import Any


def honest(
    _lab: Any,
    episode: int,
    N: int,
    epsilon_start: float = 1.0,
    epsilon_end: float = 1e-6,
    decay_type: str = "linear",
) -> float:
    """The lab's linear decay, and the additional materials' exponential one."""
    if decay_type == "exp":
        return float(epsilon_start * (epsilon_end / epsilon_start) ** (episode / N))
    delta = (epsilon_start - epsilon_end) / N
    return epsilon_start - (episode - 1) * delta


def honest_rewritten(
    _lab: Any,
    episode: int,
    N: int,
    epsilon_start: float = 1.0,
    epsilon_end: float = 1e-6,
) -> float:
    """The same decay written another way (a fraction of the way from start to end): equal up to rounding."""
    fraction = (episode - 1) / N
    return (1 - fraction) * epsilon_start + fraction * epsilon_end


def honest_loop(
    _lab: Any,
    episode: int,
    N: int,
    epsilon_start: float = 1.0,
    epsilon_end: float = 1e-6,
) -> float:
    """The decay applied once per episode: rounding accumulates, within the check's tolerance."""
    delta = (epsilon_start - epsilon_end) / N
    epsilon = epsilon_start
    for _ in range(episode - 1):
        epsilon -= delta
    return epsilon


HONEST = {"formula": honest, "rewritten": honest_rewritten, "loop": honest_loop}
"""Honest ways to write the linear decay: each must pass."""


def _linear(episode: int, n: int, start: float, end: float) -> float:
    return start - (episode - 1) * (start - end) / n


def zero_based(
    _lab: Any, episode: int, N: int, epsilon_start: float = 1.0, epsilon_end: float = 1e-6
) -> float:
    return epsilon_start - episode * (epsilon_start - epsilon_end) / N


def divides_by_n_minus_1(
    _lab: Any,
    episode: int,
    N: int,
    epsilon_start: float = 1.0,
    epsilon_end: float = 1e-6,
) -> float:
    return epsilon_start - (episode - 1) * (epsilon_start - epsilon_end) / (N - 1)


def end_at_last(
    _lab: Any, episode: int, N: int, epsilon_start: float = 1.0, epsilon_end: float = 1e-6
) -> float:
    if episode >= N:
        return epsilon_end
    return _linear(episode, N, epsilon_start, epsilon_end)


def ignores_bounds(
    _lab: Any,
    episode: int,
    N: int,
    epsilon_start: float = 1.0,
    epsilon_end: float = 1e-6,
) -> float:
    return _linear(episode, N, 1.0, 1e-6)


def decays_to_zero(
    _lab: Any,
    episode: int,
    N: int,
    epsilon_start: float = 1.0,
    epsilon_end: float = 1e-6,
) -> float:
    return epsilon_start - (episode - 1) * epsilon_start / N


def exponential(
    _lab: Any, episode: int, N: int, epsilon_start: float = 1.0, epsilon_end: float = 1e-6
) -> float:
    return float(epsilon_start * (epsilon_end / epsilon_start) ** (episode / N))


def floor_division(
    _lab: Any,
    episode: int,
    N: int,
    epsilon_start: float = 1.0,
    epsilon_end: float = 1e-6,
) -> float:
    return epsilon_start - (episode - 1) * ((epsilon_start - epsilon_end) // N)


def exp_off_by_one(
    _lab: Any,
    episode: int,
    N: int,
    epsilon_start: float = 1.0,
    epsilon_end: float = 1e-6,
    decay_type: str = "linear",
) -> float:
    """Right linear decay; the optional exponential one counts episodes from 0."""
    if decay_type == "exp":
        return float(epsilon_start * (epsilon_end / epsilon_start) ** ((episode - 1) / N))
    return _linear(episode, N, epsilon_start, epsilon_end)


def returns_nan(
    _lab: Any, episode: int, N: int, epsilon_start: float = 1.0, epsilon_end: float = 1e-6
) -> float:
    return math.nan if episode == N else _linear(episode, N, epsilon_start, epsilon_end)


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
