"""Fixtures of the acceptance tests: grade a case and hand its typed outcome to the controller."""

from __future__ import annotations

import pytest

from grader.grading.plugin import (
    OUTCOME_PROPERTY,
    GradeCase,
    GraderFailure,
    ProblemCase,
    grading_session,
    outcome_json,
)
from grader.report import ProblemResult


class GraderFailed(Exception):
    """Raised when the grader itself failed on a case, to error its test (the outcome is already attached)."""


@pytest.fixture
def grade(request: pytest.FixtureRequest) -> GradeCase:
    """Grade a case and attach its outcome (a result, or the grader's own failure) to the test's report.

    The returned result is the grade, whatever the student's code did; only a failure of the grader
    itself errors the test, so the session's log shows it.
    """
    session = grading_session(request.config)

    def grade_case(case: ProblemCase) -> ProblemResult:
        outcome = session.grade(case)
        request.node.user_properties.append((OUTCOME_PROPERTY, outcome_json(outcome)))
        if isinstance(outcome, GraderFailure):
            raise GraderFailed(f"{outcome.kind}: {outcome.detail}")
        return outcome.result

    return grade_case
