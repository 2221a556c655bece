"""Tests of grader/seeds.py: held-out seeds, and a file memorised for the practice seed failing on them."""

from __future__ import annotations

from pathlib import Path

import pytest
from grading_support import SUBMISSIONS, write_config

from grader.grading import grade_submission
from grader.sandbox import IsolationPolicy
from grader.seeds import PRACTICE_SEED, held_out_seed

MEMORISED = SUBMISSIONS / "hostile" / "memorised_tapes.py"
HELD_OUT = 20261124
"""Any seed other than the practice seed: the sample's tapes fit none of its starts (deterministic)."""


@pytest.mark.parametrize("limit", [2, 3, 2**31, 2**63], ids=["smallest", "three", "int32", "default"])
def test_held_out_seeds_are_in_range_and_never_the_practice_seed(limit: int) -> None:
    seeds = {held_out_seed(limit) for _ in range(200)}
    assert PRACTICE_SEED not in seeds
    assert all(1 <= seed < limit for seed in seeds)


def test_held_out_seeds_differ_between_draws() -> None:
    assert len({held_out_seed() for _ in range(20)}) == 20


@pytest.fixture(scope="module")
def five_calls(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return write_config(tmp_path_factory.mktemp("config") / "assignment.toml", {"cartpole": {"calls": 5}})


@pytest.mark.parametrize(
    ("seed", "status"),
    [(PRACTICE_SEED, "passed"), (HELD_OUT, "failed")],
    ids=["practice-seed-passes", "held-out-seed-fails"],
)
def test_tapes_memorised_for_the_practice_seed_fail_on_a_held_out_seed(
    five_calls: Path, seed: int, status: str
) -> None:
    report = grade_submission(
        MEMORISED,
        seed=seed,
        workers=1,
        only=["cartpole"],
        policy=IsolationPolicy.ALLOW_FALLBACK,
        config=five_calls,
    )
    (result,) = report.problems
    assert (result.status, report.seed) == (status, seed), result.feedback
