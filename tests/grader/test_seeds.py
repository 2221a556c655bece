"""Tests of grader/seeds.py: held-out and per-upload seeds; tapes memorised for the practice seed fail."""

from __future__ import annotations

from pathlib import Path

import pytest
from grading_support import SUBMISSIONS, write_config

from grader.grading.grade import grade_submission
from grader.sandbox import IsolationPolicy
from grader.seeds import PRACTICE_SEED, held_out_seed, new_secret, upload_seed

MEMORISED = SUBMISSIONS / "hostile" / "memorised_tapes.py"
HELD_OUT = 20261124
"""Any seed other than the practice seed: the sample's tapes fit none of its starts (deterministic)."""
SECRET = "5e" * 32


@pytest.mark.parametrize("limit", [2, 3, 2**31, 2**63], ids=["smallest", "three", "int32", "default"])
def test_held_out_seeds_are_in_range_and_never_the_practice_seed(limit: int) -> None:
    seeds = {held_out_seed(limit) for _ in range(200)}
    assert PRACTICE_SEED not in seeds
    assert all(1 <= seed < limit for seed in seeds)


def test_held_out_seeds_differ_between_draws() -> None:
    assert len({held_out_seed() for _ in range(20)}) == 20


@pytest.mark.parametrize(
    ("other", "same"),
    [
        (("gradescope", "77", "2026-11-25T10:00:00-08:00", "5"), True),
        (("gradescope", "78", "2026-11-25T10:00:00-08:00", "5"), False),
        (("gradescope", "77", "2026-11-25T10:00:01-08:00", "5"), False),
        (("gradescope", "77", "2026-11-25T10:00:00-08:00", "6"), False),
        (("gradescope", "77", "2026-11-25T10:00:00-08:00", "5", "6"), False),
    ],
    ids=["same-upload", "other-id", "other-time", "other-student", "with-a-partner"],
)
def test_every_upload_gets_its_own_seed(other: tuple[str, ...], same: bool) -> None:
    upload = ("gradescope", "77", "2026-11-25T10:00:00-08:00", "5")
    assert (upload_seed(SECRET, upload) == upload_seed(SECRET, other)) is same
    assert upload_seed(SECRET, upload) != upload_seed("6f" * 32, upload), "the secret decides the seed"
    assert 1 <= upload_seed(SECRET, other) < 2**63


def test_a_secret_that_is_not_the_bundles_is_refused() -> None:
    with pytest.raises(ValueError, match="a seed secret must be at least 64 hex digits; found 6 characters"):
        upload_seed("abcdef", ("gradescope", "1"))


def test_every_secret_is_new() -> None:
    assert len({new_secret() for _ in range(20)}) == 20 and len(new_secret()) == 64


@pytest.fixture(scope="module")
def five_calls(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return write_config(tmp_path_factory.mktemp("config") / "assignment.toml", {"cartpole": {"calls": 5}})


@pytest.mark.slow  # a grading through the sandbox
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
