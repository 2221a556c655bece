"""Exact oracles: what a lab policy achieves, computed without sampling."""

from reference.oracles.blackjack import (
    Outcome,
    evaluate_policy,
    random_policy_outcome,
    threshold_policy_outcome,
    threshold_start_outcome,
)
from reference.oracles.guessing_game import GuessCounts, midpoint_guess_counts
from reference.oracles.taxi import (
    ReturnMoments,
    greedy_policy_return,
    optimal_q_table,
    optimal_return,
    random_policy_return,
)

__all__ = [
    "GuessCounts",
    "Outcome",
    "ReturnMoments",
    "evaluate_policy",
    "greedy_policy_return",
    "midpoint_guess_counts",
    "optimal_q_table",
    "optimal_return",
    "random_policy_outcome",
    "random_policy_return",
    "threshold_policy_outcome",
    "threshold_start_outcome",
]
