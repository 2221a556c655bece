"""Tests of grader/plugin.py through real pytest runs: ordering, -n 2 versus -n 0, reproducibility."""

from __future__ import annotations

import subprocess
from pathlib import Path
from typing import Any

import pytest
from grading_support import CLASSIC_COMPLETE, FAST_OVERRIDES, write_config

from grader.config import load_config
from grader.grading import (
    GradingPlan,
    acceptance_command,
    acceptance_environment,
    grade_files,
    run_acceptance,
)
from grader.report import Report
from grader.sandbox import IsolationPolicy

PROBLEMS = ("random_blackjack", "cartpole", "car")


@pytest.fixture(scope="module")
def fast_config(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return write_config(tmp_path_factory.mktemp("config") / "assignment.toml", FAST_OVERRIDES)


@pytest.fixture(scope="module")
def plan(fast_config: Path) -> GradingPlan:
    return GradingPlan.load(fast_config, PROBLEMS)


def _grade(plan: GradingPlan, *, seed: int, workers: int) -> Report:
    return grade_files(
        [CLASSIC_COMPLETE], plan, seed=seed, workers=workers, policy=IsolationPolicy.ALLOW_FALLBACK
    )[0]


@pytest.fixture(scope="module")
def reports(plan: GradingPlan) -> dict[str, Report]:
    """Three gradings of the lab solution: seed 1 serially and on 2 workers, seed 2 on 2 workers."""
    return {
        "serial": _grade(plan, seed=1, workers=1),
        "parallel": _grade(plan, seed=1, workers=2),
        "other-seed": _grade(plan, seed=2, workers=2),
    }


def test_collection_runs_the_longest_expected_checks_first(fast_config: Path, tmp_path: Path) -> None:
    plan = GradingPlan.load(fast_config, None)
    run = acceptance_command(
        [CLASSIC_COMPLETE, CLASSIC_COMPLETE],
        plan,
        seed=0,
        workers=1,
        policy=IsolationPolicy.ALLOW_FALLBACK,
        results=tmp_path / "results.jsonl",
    )
    environment = acceptance_environment()
    output = subprocess.run(
        [*run, "--collect-only"], capture_output=True, text=True, cwd=tmp_path, check=True, env=environment
    ).stdout
    collected = [line.split("::")[1].split("[")[0] for line in output.splitlines() if "::" in line]
    problems = load_config(fast_config).problems
    enabled = [problem for problem in problems if problems[problem].enabled]
    expected = sorted(enabled, key=lambda problem: -problems[problem].expected_seconds)
    assert collected == [f"test_{problem}" for problem in expected for _ in range(2)]


def test_serial_and_parallel_runs_give_the_same_report(reports: dict[str, Report]) -> None:
    serial, parallel = reports["serial"], reports["parallel"]
    assert [problem.id for problem in serial.problems] == list(PROBLEMS)
    assert serial.grader_errors == []
    assert serial.graded_view() == parallel.graded_view()


def test_a_grading_is_a_function_of_bytes_and_seed(reports: dict[str, Report]) -> None:
    def seeds_and_measurements(report: Report) -> list[tuple[int, dict[str, Any]]]:
        return [(problem.seed, problem.measurements) for problem in report.problems]

    first, second = seeds_and_measurements(reports["parallel"]), seeds_and_measurements(reports["other-seed"])
    assert all(seed_1 != seed_2 for (seed_1, _), (seed_2, _) in zip(first, second, strict=True))
    assert first != second, "a different grading seed must play different episodes"


def test_every_check_reports_its_timings_apart_from_the_verdict(reports: dict[str, Report]) -> None:
    report = reports["parallel"]
    assert report.timings is not None and report.timings.workers == 2
    for problem in report.problems:
        assert problem.timings is not None
        assert problem.timings.student_seconds <= problem.timings.wall_seconds


def test_a_grader_failure_is_reported_as_such(plan: GradingPlan, tmp_path: Path) -> None:
    vanished = tmp_path / "vanished.py"  # validated, then deleted before its check runs
    single = GradingPlan.load(plan.config, ["car"])
    runs = run_acceptance(
        [vanished], single, seed=0, workers=1, policy=IsolationPolicy.ALLOW_FALLBACK, on_result=None
    )
    [run] = runs[str(vanished)]
    assert run.internal_error is not None and run.internal_error.startswith("FileNotFoundError")
    assert run.result.status == "error"
    assert run.result.feedback.startswith(
        "The grader failed while checking this problem (not your code's fault)"
    )


def test_a_grader_failure_keeps_the_problems_visibility(tmp_path: Path) -> None:
    config = write_config(tmp_path / "assignment.toml", {"car": {"visibility": "hidden"}})
    vanished = tmp_path / "vanished.py"
    runs = run_acceptance(
        [vanished],
        GradingPlan.load(config, ["car"]),
        seed=0,
        workers=1,
        policy=IsolationPolicy.ALLOW_FALLBACK,
        on_result=None,
    )
    [run] = runs[str(vanished)]
    assert (run.result.status, run.result.visibility) == ("error", "hidden")
