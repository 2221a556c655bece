"""The grader's own definitions a call may put in place of the submission's (`Call.provided`).

Edition rl1's `sarsa0` calls the module's `epsilon_decay`; a configuration that grades sarsa0 with the
grader's decay instead of the student's (so a wrong decay is counted only in its own problem) has the
child bind these for the duration of the call. Stdlib only: the child imports it.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any


def epsilon_decay(
    episode: int, N: int, epsilon_start: float = 1.0, epsilon_end: float = 1e-6, decay_type: str = "linear"
) -> float:
    """The lab's decay: episode i (1-based) of N gets `start - (i - 1) * (start - end) / N` (or "exp")."""
    if decay_type == "exp":
        return float(epsilon_start * (epsilon_end / epsilon_start) ** (episode / N))
    return epsilon_start - (episode - 1) * (epsilon_start - epsilon_end) / N


PROVIDED: dict[str, Callable[..., Any]] = {"epsilon_decay": epsilon_decay}
"""The names a call may provide, and the grader's definition of each."""
