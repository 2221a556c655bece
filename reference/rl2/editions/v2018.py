"""The 2018 edition: `extract_policy`, `compute_policy_v`, and `frozenlake` returning five results."""

from __future__ import annotations

from reference.rl2.solutions import (
    FloatArray,
    IntArray,
    frozen_lake,
    policy_iteration,
    run_simulation,
    value_iteration,
)
from reference.rl2.solutions import iter_policy_eval as compute_policy_v
from reference.rl2.solutions import policy_improvement as extract_policy

__all__ = [
    "compute_policy_v",
    "extract_policy",
    "frozenlake",
    "policy_iteration",
    "run_simulation",
    "value_iteration",
]


def frozenlake(basic_case: bool = True, M: int = 1000) -> tuple[IntArray, float, FloatArray, IntArray, float]:
    """Problems 5 and 6: (vi_policy, vi_total_rewards, pi_value_func, pi_policy, pi_total_rewards)."""
    _, vi_policy, vi_mean, pi_values, pi_policy, pi_mean = frozen_lake(basic_case, M)
    return vi_policy, vi_mean, pi_values, pi_policy, pi_mean
