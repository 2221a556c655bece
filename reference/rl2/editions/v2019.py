"""The 2019-2022 editions: the 2018 names, `frozen_lake(..., render)`, `run_simulation(..., render, beta)`."""

from __future__ import annotations

from typing import Any

import numpy.typing as npt

from reference.rl2 import solutions
from reference.rl2.solutions import FloatArray, IntArray, policy_iteration, value_iteration
from reference.rl2.solutions import iter_policy_eval as compute_policy_v
from reference.rl2.solutions import policy_improvement as extract_policy

__all__ = [
    "compute_policy_v",
    "extract_policy",
    "frozen_lake",
    "policy_iteration",
    "run_simulation",
    "value_iteration",
]


def frozen_lake(
    basic_case: bool = True, M: int = 1000, render: bool = False
) -> tuple[IntArray, float, FloatArray, IntArray, float]:
    """Problems 5 and 6: (vi_policy, vi_total_rewards, pi_value_func, pi_policy, pi_total_rewards)."""
    _, vi_policy, vi_mean, pi_values, pi_policy, pi_mean = solutions.frozen_lake(basic_case, M, render)
    return vi_policy, vi_mean, pi_values, pi_policy, pi_mean


def run_simulation(env: Any, policy: npt.ArrayLike, render: bool = True, beta: float = 1.0) -> float:
    """Problem 6: one episode's discounted return (`render` is the edition's flag; drawing is the env's)."""
    del render
    return solutions.run_simulation(env, policy, beta)
