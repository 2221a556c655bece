"""Fixtures of the acceptance tests: grade a case and hand the result to the plugin's controller."""

from __future__ import annotations

from collections.abc import Callable

import pytest

from grader.plugin import ERROR_PROPERTY, RESULT_PROPERTY, GradeCase, ProblemCase, grading_session
from grader.report import ProblemResult


@pytest.fixture
def grade(request: pytest.FixtureRequest, record_property: Callable[[str, object], None]) -> GradeCase:
    """Grade a case and attach the result (or the grader's own failure) to the test's report.

    The returned result is the grade, whatever the student's code did; only a failure of the grader
    itself propagates and errors the test.
    """
    session = grading_session(request.config)

    def grade_case(case: ProblemCase) -> ProblemResult:
        try:
            run = session.run(case)
            line = run.to_json()
        except Exception as error:
            record_property(ERROR_PROPERTY, f"{type(error).__name__}: {error}")
            raise
        record_property(RESULT_PROPERTY, line)
        return run.result

    return grade_case
