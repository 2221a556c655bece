"""The 2026 template (`policy_function_iteration.py`): the 2024 names, six results, no `model_comparison`."""

from __future__ import annotations

from reference.rl2.solutions import (
    frozen_lake,
    iter_policy_eval,
    policy_improvement,
    policy_iteration,
    run_simulation,
    value_iteration,
)

__all__ = [
    "frozen_lake",
    "iter_policy_eval",
    "policy_improvement",
    "policy_iteration",
    "run_simulation",
    "value_iteration",
]
