"""Tests of grader/execution.py that need no sandbox: the per-problem seeds."""

from __future__ import annotations

import pytest

from grader.execution import problem_seed
from grader.problems import PROBLEM_IDS


@pytest.mark.parametrize(
    ("grading_seed", "problem", "expected"),
    [
        (0, "cartpole", 2777628367144785276),
        (1, "cartpole", 485058722580370561),
        (0, "taxi", 6027082271082110006),
    ],
    ids=["seed-0-cartpole", "seed-1-cartpole", "seed-0-taxi"],
)
def test_problem_seeds_never_change(grading_seed: int, problem: str, expected: int) -> None:
    """Pinned: changing the derivation would silently change every past grade's episodes."""
    assert problem_seed(grading_seed, problem) == expected


def test_problem_seeds_are_distinct_63_bit_numbers() -> None:
    seeds = {problem_seed(grading_seed, problem) for grading_seed in range(50) for problem in PROBLEM_IDS}
    assert len(seeds) == 50 * len(PROBLEM_IDS)
    assert all(0 <= seed < 2**63 for seed in seeds)
