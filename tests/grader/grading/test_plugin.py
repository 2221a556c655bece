"""Tests of grader/grading/plugin.py through real pytest sessions: ordering, node ids, 2 workers versus 1,
seeds."""

from __future__ import annotations

import contextlib
import dataclasses
import io
import os
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from _pytest.assertion.rewrite import AssertionRewritingHook
from grading_support import CLASSIC_COMPLETE, FAST_OVERRIDES, write_config

from grader.grading.grade import grade_files
from grader.grading.plan import GradingPlan
from grader.grading.plugin import (
    CASE_OUTCOME,
    GraderFailure,
    ProblemCase,
    SessionPlan,
    outcome_json,
    read_outcome,
)
from grader.grading.session import (
    ACCEPTANCE_DIR,
    SessionEnd,
    acceptance_args,
    case_paths,
    session_environment,
)
from grader.lab.assignment import DEFAULT_CONFIG_PATH, load_config
from grader.lab.editions import EDITIONS
from grader.lab.editions.choice import edition_config
from grader.report import ProblemResult, ProblemRun, Report
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


class Collected:
    """A plugin object that keeps the node ids of a collection."""

    def __init__(self) -> None:
        self.node_ids: list[str] = []

    def pytest_collection_finish(self, session: pytest.Session) -> None:
        self.node_ids = [item.nodeid for item in session.items]


def test_collection_runs_the_longest_expected_checks_first_under_the_planned_ids(fast_config: Path) -> None:
    grading = GradingPlan.load(fast_config, None)
    plan = SessionPlan(
        grading=grading,
        submissions=(CLASSIC_COMPLETE, CLASSIC_COMPLETE),
        seed=0,
        policy=IsolationPolicy.ALLOW_FALLBACK,
    )
    collected = Collected()
    with session_environment({}), contextlib.redirect_stdout(io.StringIO()):
        exit_code = pytest.main(
            [*acceptance_args(plan, workers=1), "-n", "0", "--collect-only"], plugins=[collected]
        )
    assert exit_code == pytest.ExitCode.OK
    problems = load_config(fast_config).problems
    expected = sorted(grading.problems, key=lambda problem: -problems[problem].expected_seconds)
    assert collected.node_ids == [
        ProblemCase(index, CLASSIC_COMPLETE, problem).node_id for problem in expected for index in range(2)
    ]


class CollectedModules:
    """A plugin object that keeps the modules a collection imported and the assertion hooks it ran under."""

    def __init__(self) -> None:
        self.modules: list[str] = []
        self.rewriting_hooks: list[object] = []

    def pytest_collectreport(self, report: pytest.CollectReport) -> None:
        if report.nodeid.endswith(".py"):
            self.modules.append(report.nodeid)

    def pytest_collection_finish(self, session: pytest.Session) -> None:
        self.rewriting_hooks = [hook for hook in sys.meta_path if isinstance(hook, AssertionRewritingHook)]


@pytest.mark.parametrize("problems", [("car",), ("taxi", "random_blackjack")], ids=["one", "two"])
def test_a_session_collects_only_the_planned_problems_modules_without_rewriting_asserts(
    fast_config: Path, problems: tuple[str, ...]
) -> None:
    plan = SessionPlan(
        grading=GradingPlan.load(fast_config, problems),
        submissions=(CLASSIC_COMPLETE,),
        seed=0,
        policy=IsolationPolicy.ALLOW_FALLBACK,
    )
    callers_hooks = [hook for hook in sys.meta_path if isinstance(hook, AssertionRewritingHook)]
    collected = CollectedModules()
    with session_environment({}), contextlib.redirect_stdout(io.StringIO()):
        exit_code = pytest.main(
            [*acceptance_args(plan, workers=1), "-n", "0", "--collect-only"], plugins=[collected]
        )
    assert exit_code == pytest.ExitCode.OK
    assert sorted(collected.modules) == sorted(f"test_{problem}.py" for problem in problems)
    assert collected.rewriting_hooks == callers_hooks  # the caller's own, if any; none of the session's


def test_a_plan_without_problems_collects_the_cases_folder_never_the_callers_directory() -> None:
    # Without a path, pytest would collect the working directory: the caller's own tests.
    grading = dataclasses.replace(GradingPlan.load(None, ["car"]), problems=())
    plan = SessionPlan(grading=grading, submissions=(), seed=0, policy=IsolationPolicy.ALLOW_FALLBACK)
    assert case_paths(plan) == [str(ACCEPTANCE_DIR)]


def test_the_plan_reaches_the_workers_whatever_the_files_are_called(fast_config: Path) -> None:
    names = (Path(os.fsdecode(b"/srv/caf\xe9.py")), Path("/home/zoë/[final] = opengym.py"))
    grading = GradingPlan.load(fast_config, ["car"])
    plan = SessionPlan(grading=grading, submissions=names, seed=7, policy=IsolationPolicy.REQUIRE_FULL)
    name, value = plan.option().split("=", 1)
    assert name == "--gymgrade-plan"
    assert SessionPlan.from_option(value) == plan


@pytest.mark.parametrize("edition", sorted(EDITIONS))
def test_the_plan_carries_its_configuration_as_data_not_as_a_path(edition: str, tmp_path: Path) -> None:
    source = edition_config(edition)
    copy = tmp_path / "assignment.toml"
    copy.write_text((source or DEFAULT_CONFIG_PATH).read_text(encoding="utf-8"), encoding="utf-8")
    grading = GradingPlan.load(copy, None)
    option = SessionPlan(
        grading=grading, submissions=(), seed=1, policy=IsolationPolicy.ALLOW_FALLBACK
    ).option()
    copy.write_text(
        "this file changed after the plan was made = [", encoding="utf-8"
    )  # nobody reads it again
    carried = SessionPlan.from_option(option.split("=", 1)[1]).grading
    assert carried == grading
    assert (carried.edition, carried.registry, carried.config_sha256) == (
        grading.edition,
        grading.registry,
        grading.config_sha256,
    )


def test_a_case_is_known_by_an_ascii_id_whatever_the_file_is_called() -> None:
    case = ProblemCase(3, Path("/home/zoë/[final] opengym.py"), "taxi")
    assert case.node_id == "test_taxi.py::test_taxi[submission3]"


def _result(status: str = "passed") -> ProblemResult:
    return ProblemResult(id="car", title="Car", status=status, score=1.0, max_score=1.0, feedback="ok")  # type: ignore[arg-type]


@pytest.mark.parametrize(
    ("outcome", "expected"),
    [
        (
            ProblemRun(submission="/tmp/a.py", result=_result()),
            ProblemRun(submission="/tmp/a.py", result=_result()),
        ),
        (
            GraderFailure(kind="isolation_unavailable", detail="no bwrap"),
            GraderFailure(kind="isolation_unavailable", detail="no bwrap"),
        ),
        (
            GraderFailure(kind="grader_error", detail="OSError: \udcff"),
            GraderFailure(kind="grader_error", detail="OSError: ?"),
        ),
    ],
    ids=["run", "isolation-unavailable", "unencodable-detail"],
)
def test_an_outcome_travels_as_json_and_back(outcome: Any, expected: Any) -> None:
    assert read_outcome(outcome_json(outcome)) == expected


@pytest.mark.parametrize(
    "carried", ['{"kind": "grader_error"}', "not json", 42], ids=["partial", "text", "int"]
)
def test_an_unreadable_outcome_is_the_graders_own_failure(carried: object) -> None:
    outcome = read_outcome(carried)
    assert isinstance(outcome, GraderFailure) and outcome.kind == "grader_error"
    assert outcome.detail.startswith("the result of this check could not be read back (")
    assert CASE_OUTCOME.validate_json(outcome_json(outcome)) == outcome


@pytest.mark.xdist_group("plugin-reports")  # one worker grades `reports` for all
@pytest.mark.slow  # grades through pytest-xdist sessions
def test_serial_and_parallel_runs_give_the_same_report(reports: dict[str, Report]) -> None:
    serial, parallel = reports["serial"], reports["parallel"]
    assert [problem.id for problem in serial.problems] == list(PROBLEMS)
    assert serial.grader_errors == []
    assert serial.graded_view() == parallel.graded_view()


@pytest.mark.xdist_group("plugin-reports")  # one worker grades `reports` for all
@pytest.mark.slow  # grades through pytest-xdist sessions
def test_a_grading_is_a_function_of_bytes_and_seed(reports: dict[str, Report]) -> None:
    def seeds_and_measurements(report: Report) -> list[tuple[int, dict[str, Any]]]:
        return [(problem.seed, problem.measurements) for problem in report.problems]

    first, second = seeds_and_measurements(reports["parallel"]), seeds_and_measurements(reports["other-seed"])
    assert all(seed_1 != seed_2 for (seed_1, _), (seed_2, _) in zip(first, second, strict=True))
    assert first != second, "a different grading seed must play different episodes"


@pytest.mark.xdist_group("plugin-reports")  # one worker grades `reports` for all
@pytest.mark.slow  # grades through pytest-xdist sessions
def test_every_check_reports_its_timings_apart_from_the_verdict(reports: dict[str, Report]) -> None:
    report = reports["parallel"]
    assert report.timings is not None and report.timings.workers == 2
    for problem in report.problems:
        assert problem.timings is not None
        assert problem.timings.student_seconds <= problem.timings.wall_seconds


@contextlib.contextmanager
def _deleted_when_the_session_starts(path: Path) -> Iterator[None]:
    """Delete ``path`` once the plan is made and the files validated, as the session starts."""
    import grader.grading.grade

    start = grader.grading.grade.run_session

    def delete_then_start(*args: Any, **kwargs: Any) -> SessionEnd:
        path.unlink()
        return start(*args, **kwargs)

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(grader.grading.grade, "run_session", delete_then_start)
        yield


@contextlib.contextmanager
def _imported_copy_deleted_when_the_session_starts() -> Iterator[None]:
    """Delete the files the session imports (the grader's private copies of the submissions, made after
    the files were read and validated) as the session starts."""
    import grader.grading.grade

    start = grader.grading.grade.run_session

    def delete_then_start(session: SessionPlan, *args: Any, **kwargs: Any) -> SessionEnd:
        for module in session.submissions:
            module.unlink()
        return start(session, *args, **kwargs)

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(grader.grading.grade, "run_session", delete_then_start)
        yield


def _vanished_report(plan: GradingPlan, tmp_path: Path) -> Report:
    """The report of a file whose imported copy vanished after it was validated, before its check ran (a
    grader failure: the student's own file is read once, and never again)."""
    vanished = tmp_path / "vanished.py"
    vanished.write_text("import math\n")
    with _imported_copy_deleted_when_the_session_starts():
        [report] = grade_files([vanished], plan, seed=0, workers=1, policy=IsolationPolicy.ALLOW_FALLBACK)
    return report


@pytest.mark.slow  # grades through pytest-xdist sessions
def test_a_grader_failure_is_reported_as_such(plan: GradingPlan, tmp_path: Path) -> None:
    report = _vanished_report(GradingPlan.load(plan.config, ["car"]), tmp_path)
    [result] = report.problems
    assert report.grader_errors and report.grader_errors[0].startswith("car: FileNotFoundError")
    assert result.status == "error"
    assert result.feedback.startswith("The grader failed while checking this problem (not your code's fault)")


@pytest.mark.slow  # grades through pytest-xdist sessions
def test_a_grader_failure_keeps_the_problems_visibility(tmp_path: Path) -> None:
    config = write_config(tmp_path / "assignment.toml", {"car": {"visibility": "hidden"}})
    [result] = _vanished_report(GradingPlan.load(config, ["car"]), tmp_path).problems
    assert (result.status, result.visibility) == ("error", "hidden")


@pytest.mark.slow  # grades through pytest-xdist sessions
def test_the_workers_grade_with_the_plans_configuration_even_if_its_file_is_gone(tmp_path: Path) -> None:
    config = write_config(tmp_path / "assignment.toml", {"car": {"points": 3.0, "visibility": "hidden"}})
    plan = GradingPlan.load(config, ["car"])
    with _deleted_when_the_session_starts(config):  # no process of the session may read it again
        [report] = grade_files(
            [CLASSIC_COMPLETE], plan, seed=0, workers=1, policy=IsolationPolicy.ALLOW_FALLBACK
        )
    assert not config.exists() and report.grader_errors == []
    [result] = report.problems
    assert (result.status, result.max_score, result.visibility) == ("passed", 3.0, "hidden")
    assert report.config_sha256 == plan.config_sha256
