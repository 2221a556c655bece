"""The gymgrade pytest plugin: one acceptance test per (submission, problem), results to a JSON-lines file.

Load it with ``-p grader.plugin`` and point pytest at ``grader/acceptance``. Each acceptance test grades one
problem of one submission and attaches the structured result to its report (``user_properties`` travel from
xdist workers to the controller); the controller appends one line per result to ``--results-file`` as soon
as it arrives, which is what live progress reads. A student's failure is data in that line: the test itself
errors only when the grader fails, and then the line says so.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import IO

import pytest
from xdist.workermanage import parse_tx_spec_config

from grader.config import AssignmentConfig, load_config
from grader.execution import problem_seed
from grader.problems import PROBLEM_IDS, ProblemId
from grader.report import ProblemResult, ProblemRun
from grader.sandbox import IsolationPolicy
from grader.scheduling import LongestFirstScheduling, is_slot, with_slots

RESULT_PROPERTY = "gymgrade_result"
ERROR_PROPERTY = "gymgrade_internal_error"
GradeCase = Callable[["ProblemCase"], ProblemResult]
"""The acceptance tests' ``grade`` fixture: grade one case, attach the result to the report, return it."""
_CASE_ID = re.compile(r"::test_(?P<problem>\w+)\[(?P<index>\d+):")


@dataclass(frozen=True)
class ProblemCase:
    """One acceptance test's subject: a problem of a submission."""

    index: int
    submission: Path
    problem: ProblemId

    @property
    def test_id(self) -> str:
        """The parametrize id, also parsed back by the controller for crashed workers."""
        return f"{self.index}:{self.submission.name}"


@dataclass(frozen=True)
class GradingOptions:
    """The plugin's command-line options."""

    submissions: tuple[Path, ...]
    seed: int
    config_path: Path | None
    only: tuple[ProblemId, ...] | None
    results_file: Path | None
    policy: IsolationPolicy

    @classmethod
    def from_config(cls, config: pytest.Config) -> GradingOptions:
        """Read and validate the options; raise ``pytest.UsageError`` naming a bad value."""
        only_text: str | None = config.getoption("only")
        only: tuple[ProblemId, ...] | None = None
        if only_text:
            names = [name.strip() for name in only_text.split(",") if name.strip()]
            unknown = [name for name in names if name not in PROBLEM_IDS]
            if unknown:
                raise pytest.UsageError(
                    f"--only: unknown problem {', '.join(unknown)}; "
                    f"expected ids among {', '.join(PROBLEM_IDS)}"
                )
            only = tuple(problem for problem in PROBLEM_IDS if problem in names)
        config_path = config.getoption("assignment_config")
        results_file = config.getoption("results_file")
        return cls(
            submissions=tuple(Path(path) for path in config.getoption("submission")),
            seed=config.getoption("grading_seed"),
            config_path=Path(config_path) if config_path else None,
            only=only,
            results_file=Path(results_file) if results_file else None,
            policy=IsolationPolicy(config.getoption("isolation_policy")),
        )


def pytest_addoption(parser: pytest.Parser) -> None:
    group = parser.getgroup("gymgrade", "gymgrade acceptance tests")
    group.addoption(
        "--submission",
        action="append",
        default=[],
        metavar="PATH",
        help="Student file to grade (repeatable).",
    )
    group.addoption(
        "--grading-seed",
        type=int,
        default=0,
        metavar="N",
        help="Grading seed; each problem's sandbox seed derives from it.",
    )
    group.addoption(
        "--assignment-config",
        default=None,
        metavar="PATH",
        help="Assignment configuration TOML (default: the bundled grader/assignment.toml).",
    )
    group.addoption("--only", default=None, metavar="IDS", help="Comma-separated problem ids to grade.")
    group.addoption(
        "--results-file",
        default=None,
        metavar="PATH",
        help="JSON-lines file the controller appends one result per line to.",
    )
    group.addoption(
        "--isolation-policy",
        default=IsolationPolicy.REQUIRE_FULL.value,
        choices=[policy.value for policy in IsolationPolicy],
        help="Refuse weaker isolation (require_full) or run with what is available.",
    )


class GradingSession:
    """Per-process state: the options and the assignment configuration they select."""

    def __init__(self, options: GradingOptions) -> None:
        self.options = options
        self.assignment: AssignmentConfig = load_config(options.config_path)

    def selected(self, problem: ProblemId) -> bool:
        """Whether a problem is enabled and chosen by --only."""
        enabled = self.assignment.problem(problem).enabled
        return enabled and (self.options.only is None or problem in self.options.only)

    def cases(self, problem: ProblemId) -> list[ProblemCase]:
        """The acceptance cases of one problem, one per submission."""
        return [ProblemCase(index, path, problem) for index, path in enumerate(self.options.submissions)]

    def run(self, case: ProblemCase) -> ProblemRun:
        """Grade one case (imported lazily so collection stays fast)."""
        from grader.execution import run_problem

        return run_problem(
            case.submission,
            case.problem,
            config=self.assignment,
            grading_seed=self.options.seed,
            policy=self.options.policy,
        )


_SESSION_KEY = pytest.StashKey[GradingSession]()


def grading_session(config: pytest.Config) -> GradingSession:
    """The plugin's state for this pytest process."""
    return config.stash[_SESSION_KEY]


def pytest_configure(config: pytest.Config) -> None:
    options = GradingOptions.from_config(config)
    config.stash[_SESSION_KEY] = GradingSession(options)
    if options.results_file is not None and not hasattr(config, "workerinput"):
        writer = ResultsWriter(grading_session(config), options.results_file)
        config.pluginmanager.register(writer, "gymgrade-results")


def pytest_generate_tests(metafunc: pytest.Metafunc) -> None:
    if "problem_case" not in metafunc.fixturenames:
        return
    problem: ProblemId = metafunc.module.PROBLEM
    cases = grading_session(metafunc.config).cases(problem)
    metafunc.parametrize("problem_case", cases, ids=[case.test_id for case in cases])


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    session = grading_session(config)
    chosen: list[pytest.Item] = []
    deselected: list[pytest.Item] = []
    for item in items:
        case = _case_of(item)
        (chosen if case is None or session.selected(case.problem) else deselected).append(item)
    if deselected:
        config.hook.pytest_deselected(items=deselected)

    def longest_first(item: pytest.Item) -> tuple[float, int, int]:
        case = _case_of(item)
        if case is None:
            return (0.0, 0, 0)
        expected = session.assignment.problem(case.problem).expected_seconds
        return (-expected, PROBLEM_IDS.index(case.problem), case.index)

    chosen.sort(key=longest_first)
    items[:] = with_slots(chosen) if hasattr(config, "workerinput") else chosen


@pytest.hookimpl(tryfirst=True, optionalhook=True)
def pytest_xdist_make_scheduler(config: pytest.Config, log: object) -> LongestFirstScheduling | None:
    if not grading_session(config).options.submissions:
        return None
    return LongestFirstScheduling(len(parse_tx_spec_config(config)), log)  # type: ignore[arg-type]


def _case_of(item: pytest.Item) -> ProblemCase | None:
    callspec = getattr(item, "callspec", None)
    if callspec is None:
        return None
    case = callspec.params.get("problem_case")
    return case if isinstance(case, ProblemCase) else None


class ResultsWriter:
    """Controller side: appends every acceptance result to the results file as it arrives."""

    def __init__(self, session: GradingSession, results_file: Path) -> None:
        self.session = session
        self.options = session.options
        self.stream: IO[str] = results_file.open("a", encoding="utf-8")
        self.written: set[str] = set()

    def pytest_runtest_logreport(self, report: pytest.TestReport) -> None:
        if is_slot(report.nodeid) or report.nodeid in self.written:
            return
        properties = dict(report.user_properties)
        if RESULT_PROPERTY in properties and report.when == "call":
            self._write(report.nodeid, str(properties[RESULT_PROPERTY]))
        elif report.failed:
            self._write_internal_error(report, properties.get(ERROR_PROPERTY))

    def pytest_unconfigure(self) -> None:
        self.stream.close()

    def _write_internal_error(self, report: pytest.TestReport, error: object) -> None:
        match = _CASE_ID.search(report.nodeid)
        if match is None or match["problem"] not in PROBLEM_IDS:
            return
        index = int(match["index"])
        problem: ProblemId = match["problem"]  # type: ignore[assignment]
        submission = self.options.submissions[index]
        detail = str(error) if error is not None else (report.longreprtext.strip().splitlines() or ["?"])[-1]
        settings = self.session.assignment.problem(problem)
        run = ProblemRun.grader_failure(
            str(submission),
            problem,
            title=settings.title,
            points=settings.points,
            seed=problem_seed(self.options.seed, problem),
            detail=detail,
            visibility=settings.visibility,
        )
        self._write(report.nodeid, run.to_json())

    def _write(self, nodeid: str, line: str) -> None:
        self.written.add(nodeid)
        self.stream.write(line + "\n")
        self.stream.flush()
