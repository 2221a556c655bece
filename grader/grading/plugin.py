"""The gymgrade pytest plugin: one acceptance test per (submission, problem) case, its outcome typed.

`grader.grading.session` loads it (``-p grader.grading.plugin``) in the calling process, which is
pytest-xdist's controller, and every xdist worker loads it again from the same arguments. The plan of the
session travels as one option, ``--gymgrade-plan``: a `SessionPlan` validated once by the caller, serialised
as JSON, so the workers grade exactly the cases the controller expects and validate nothing twice. Each case's
node id is declared here (`ProblemCase.node_id`) and checked when the workers collect, so the controller knows
every report by an id it generated itself. An acceptance test grades its case and attaches the typed
`CaseOutcome` to its report (``user_properties`` travel from the worker to the controller): a student's
failure is a `ProblemRun` like any other verdict; a failure of the grader itself is a `GraderFailure`.
"""

from __future__ import annotations

import json
import os
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Literal

import pytest
from pydantic import BaseModel, ConfigDict, TypeAdapter, ValidationError
from xdist.workermanage import parse_tx_spec_config

from grader.grading.plan import GradingPlan
from grader.grading.scheduling import LongestFirstScheduling, with_slots
from grader.lab.assignment import AssignmentConfig
from grader.lab.registry import ProblemId, acceptance_module_name
from grader.report import ProblemResult, ProblemRun
from grader.sandbox import IsolationPolicy
from grader.sandbox.errors import IsolationUnavailable

PLAN_OPTION = "--gymgrade-plan"
OUTCOME_PROPERTY = "gymgrade_outcome"
"""The ``user_properties`` key under which an acceptance test's report carries its case's outcome (JSON)."""
GradeCase = Callable[["ProblemCase"], ProblemResult]
"""The ``grade`` fixture of the acceptance tests: grade a case, attach its outcome, return its result."""


@dataclass(frozen=True)
class ProblemCase:
    """One acceptance test's subject: a problem of a submission (its index in the plan)."""

    index: int
    submission: Path
    problem: ProblemId

    @property
    def test_id(self) -> str:
        """The parametrize id: ASCII whatever the file is called, so pytest keeps it as it is."""
        return f"submission{self.index}"

    @property
    def node_id(self) -> str:
        """The pytest node id of this case's acceptance test (rootdir ``grader/grading/cases``)."""
        module = acceptance_module_name(self.problem)
        return f"{module}.py::{module}[{self.test_id}]"


@dataclass(frozen=True)
class SessionPlan:
    """What one acceptance session grades: a grading's plan, the files, the seed and the isolation policy.

    The caller makes it; every process of the session reads the same one from ``--gymgrade-plan``, where
    it travels as JSON data (the configuration included), so no worker reads or validates a file again.
    """

    grading: GradingPlan
    submissions: tuple[Path, ...]
    seed: int
    policy: IsolationPolicy
    names: tuple[str, ...] = ()
    """Each submission's own name as shown (``grade_files``' ``names``), in ``submissions``' order; the
    sandbox's messages say it (its copy may be numbered). Empty: each file's own name."""

    @property
    def problems(self) -> tuple[ProblemId, ...]:
        """The problems graded, in the registry's order."""
        return self.grading.problems

    def cases(self) -> list[ProblemCase]:
        """Every (submission, problem) case of the session, problems in the plan's order."""
        return [
            ProblemCase(index, submission, problem)
            for problem in self.problems
            for index, submission in enumerate(self.submissions)
        ]

    def option(self) -> str:
        """This plan as the ``--gymgrade-plan`` argument of the session and its workers."""
        data = {
            "grading": self.grading.to_data(),
            "submissions": [str(path) for path in self.submissions],
            "seed": self.seed,
            "policy": self.policy.value,
            "names": list(self.names),
        }
        # json.dumps escapes the lone surrogates a file name that is not UTF-8 decodes to.
        return f"{PLAN_OPTION}={json.dumps(data)}"

    @classmethod
    def from_option(cls, text: str) -> SessionPlan:
        """The plan a ``--gymgrade-plan`` value holds."""
        data = json.loads(text)
        return cls(
            grading=GradingPlan.from_data(data["grading"]),
            submissions=tuple(Path(path) for path in data["submissions"]),
            seed=int(data["seed"]),
            policy=IsolationPolicy(data["policy"]),
            names=tuple(str(name) for name in data.get("names", ())),
        )


class GraderFailure(BaseModel):
    """A case the grader itself failed on: not the student's doing."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    kind: Literal["isolation_unavailable", "grader_error"]
    detail: str

    @classmethod
    def of(cls, error: Exception) -> GraderFailure:
        """The failure an exception raised while grading a case stands for."""
        if isinstance(error, IsolationUnavailable):
            return cls(kind="isolation_unavailable", detail=str(error))
        return cls(kind="grader_error", detail=f"{type(error).__name__}: {error}")


CaseOutcome = ProblemRun | GraderFailure
"""What the controller receives for each case."""
CASE_OUTCOME: TypeAdapter[CaseOutcome] = TypeAdapter(CaseOutcome)


def outcome_json(outcome: CaseOutcome) -> str:
    """An outcome as the JSON its report carries; never raises on text the student's code produced."""
    if isinstance(outcome, ProblemRun):
        return outcome.to_json()
    detail = outcome.detail.encode("utf-8", "replace").decode("utf-8")
    return outcome.model_copy(update={"detail": detail}).model_dump_json()


def read_outcome(carried: object) -> CaseOutcome:
    """The outcome a report carries; a value that is not one becomes the grader's own failure."""
    try:
        return CASE_OUTCOME.validate_json(carried if isinstance(carried, str | bytes) else "")
    except ValidationError as error:
        count = error.error_count()
        detail = f"the result of this check could not be read back ({count} validation errors)"
        return GraderFailure(kind="grader_error", detail=detail)


def pytest_addoption(parser: pytest.Parser) -> None:
    group = parser.getgroup("gymgrade", "gymgrade acceptance tests")
    group.addoption(
        PLAN_OPTION,
        dest="gymgrade_plan",
        default=None,
        metavar="JSON",
        help="The session's plan (a grader.grading.plugin.SessionPlan as JSON); grader.grading.session passes it.",  # noqa: E501
    )


class GradingSession:
    """Per-process state: the session's plan (its configuration decoded, never reloaded)."""

    def __init__(self, plan: SessionPlan) -> None:
        self.plan = plan
        self.assignment: AssignmentConfig = plan.grading.assignment

    def cases(self, problem: ProblemId) -> list[ProblemCase]:
        """The acceptance cases of one problem, one per submission (deselected unless planned)."""
        return [ProblemCase(index, path, problem) for index, path in enumerate(self.plan.submissions)]

    def grade(self, case: ProblemCase) -> CaseOutcome:
        """Grade one case (imported lazily so collection stays fast); a grader failure is an outcome too."""
        from grader.grading.execution import run_problem

        try:
            run = run_problem(
                case.submission,
                case.problem,
                config=self.assignment,
                grading_seed=self.plan.seed,
                policy=self.plan.policy,
                shown_name=self.plan.names[case.index] if case.index < len(self.plan.names) else "",
            )
        except Exception as error:
            return GraderFailure.of(error)
        printable = os.fsencode(case.submission).decode("utf-8", "replace")  # the file's name is not data
        return run.model_copy(update={"submission": printable})


_SESSION_KEY = pytest.StashKey[GradingSession]()


def grading_session(config: pytest.Config) -> GradingSession:
    """The plugin's state for this pytest process (its configuration loaded on first use)."""
    if _SESSION_KEY not in config.stash:
        text = config.getoption("gymgrade_plan")
        if not text:
            raise pytest.UsageError(
                f"grader.grading.plugin needs {PLAN_OPTION}; found none. Grade through grader.grading.grade "
                "(gymgrade check/grade), which passes it."
            )
        config.stash[_SESSION_KEY] = GradingSession(SessionPlan.from_option(text))
    return config.stash[_SESSION_KEY]


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
        if case is not None and case.problem in session.plan.problems:
            _check_node_id(item, case)
            chosen.append(item)
        else:
            deselected.append(item)
    if deselected:
        config.hook.pytest_deselected(items=deselected)

    def longest_first(item: pytest.Item) -> tuple[float, int, int]:
        case = _case_of(item)
        if case is None:
            return (0.0, 0, 0)
        expected = session.assignment.problem(case.problem).expected_seconds
        return (-expected, session.assignment.registry.ids.index(case.problem), case.index)

    chosen.sort(key=longest_first)
    items[:] = with_slots(chosen) if hasattr(config, "workerinput") else chosen


@pytest.hookimpl(tryfirst=True, optionalhook=True)
def pytest_xdist_make_scheduler(config: pytest.Config, log: object) -> LongestFirstScheduling:
    return LongestFirstScheduling(len(parse_tx_spec_config(config)), log)  # type: ignore[arg-type]


def _case_of(item: pytest.Item) -> ProblemCase | None:
    callspec = getattr(item, "callspec", None)
    if callspec is None:
        return None
    case = callspec.params.get("problem_case")
    return case if isinstance(case, ProblemCase) else None


def _check_node_id(item: pytest.Item, case: ProblemCase) -> None:
    if item.nodeid != case.node_id:
        module = acceptance_module_name(case.problem)
        raise pytest.UsageError(
            f"acceptance test {item.nodeid!r} grades {case.problem} but the controller expects its results "
            f"under {case.node_id!r}: "
            f"name the module {module}.py and its test {module}(problem_case, grade)."
        )
