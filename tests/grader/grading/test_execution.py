"""Tests of grader/grading/execution.py that need no sandbox: the per-problem seeds, plans without calls."""

from __future__ import annotations

from pathlib import Path
from types import TracebackType

import pytest

import grader.grading.execution
from grader.grading.execution import problem_seed, run_problem
from grader.lab.assignment import load_config
from grader.lab.problems import PROBLEM_IDS
from grader.sandbox import Call, CallOutcome, FunctionInfo, IsolationPolicy, IsolationReport


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


class ChildlessSandbox:
    """Stands in for `Sandbox`: fails the test if the child would start (functions read or a call made)."""

    opened = 0

    def __init__(self, submission: Path, **settings: object) -> None:
        ChildlessSandbox.opened += 1
        self.isolation = IsolationReport(layers=())

    def __enter__(self) -> ChildlessSandbox:
        return self

    def __exit__(
        self, kind: type[BaseException] | None, error: BaseException | None, traceback: TracebackType | None
    ) -> None:
        """Nothing to close."""

    @property
    def functions(self) -> dict[str, FunctionInfo]:
        raise AssertionError("the plan read the functions: the child would have started")

    def call(self, call: Call) -> CallOutcome:
        raise AssertionError(f"{call.function} was called")


def test_a_plan_without_calls_starts_no_child(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    monkeypatch.setattr(grader.grading.execution, "Sandbox", ChildlessSandbox)
    run = run_problem(
        tmp_path / "opengym.py",
        "find_qvalues",
        config=load_config(),
        grading_seed=0,
        policy=IsolationPolicy.ALLOW_FALLBACK,
    )
    assert ChildlessSandbox.opened == 1
    assert (run.result.status, run.result.score, run.result.max_score) == ("skipped", 0.0, 0.0)
    assert run.result.feedback.startswith("Not run: find_qvalues is worth 0 points")
