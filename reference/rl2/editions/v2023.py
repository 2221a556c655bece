"""The 2023 edition (gymnasium): the 2018 names, `frozen_lake` with five results, `run_simulation(env, policy,
beta)`."""

from __future__ import annotations

from reference.rl2.editions.v2019 import frozen_lake
from reference.rl2.solutions import iter_policy_eval as compute_policy_v
from reference.rl2.solutions import policy_improvement as extract_policy
from reference.rl2.solutions import policy_iteration, run_simulation, value_iteration

__all__ = [
    "compute_policy_v",
    "extract_policy",
    "frozen_lake",
    "policy_iteration",
    "run_simulation",
    "value_iteration",
]
