"""Tests of grader/report.py: JSON round trip, the deterministic view, plain-data conversion."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from pydantic import ValidationError

from grader.report import (
    OUTPUT_CAP_CHARS,
    GradingTimings,
    IsolationSummary,
    ProblemResult,
    ProblemRun,
    Report,
    Timings,
    cap_output,
    plain_json,
)
from grader.sandbox import CompatEventRecord

ISOLATION = {
    "full": True,
    "layers": [
        {"name": "bubblewrap", "active": True, "required": True, "detail": "namespaces", "remedy": ""},
        {
            "name": "landlock",
            "active": False,
            "required": False,
            "detail": "kernel 5.10",
            "remedy": "Linux 5.13+",
        },
    ],
    "summary": "[x] bubblewrap: namespaces\n[ ] landlock: kernel 5.10 -- Linux 5.13+",
}
"""`Report.isolation` as stored since before it was a model (the JSON must stay this)."""


def _report(wall: float) -> Report:
    problem = ProblemResult(
        id="cartpole",
        title="Problem 3: CartPole",
        status="failed",
        score=0.0,
        max_score=1.0,
        feedback="expected a mean of at least 170 steps; measured 95.2",
        output="step 1\n",
        measurements={"mean_steps": 95.2, "lengths": [90, 101], "replayed": {"mismatches": 0}},
        compat_events=[{"kind": "step_after_done", "env_id": "CartPole-v0", "detail": "1 step"}],
        seed=12345,
        timings=Timings(wall_seconds=wall, student_seconds=wall / 2, overhead_seconds=wall / 2),
    )
    return Report(
        submission="opengym.py",
        sha256="ab" * 32,
        seed=7,
        gymnasium_version="1.4.0",
        grader_version="0.1.0",
        isolation=ISOLATION,
        score=0.0,
        max_score=1.0,
        problems=[problem],
        execution_time=wall,
        timings=GradingTimings(
            elapsed_seconds=wall,
            workers=2,
            check_seconds=wall,
            student_seconds=wall / 2,
            overhead_seconds=wall / 2,
        ),
    )


def test_json_round_trip_is_exact() -> None:
    report = _report(3.5)
    again = Report.model_validate_json(report.to_json())
    assert again == report
    assert again.to_json() == report.to_json()


def test_isolation_and_compat_events_are_models_with_the_json_of_before() -> None:
    report = _report(1.0)
    data = json.loads(report.to_json())

    assert isinstance(report.isolation, IsolationSummary)
    assert isinstance(report.problems[0].compat_events[0], CompatEventRecord)
    assert data["isolation"] == ISOLATION
    assert list(data["isolation"]) == ["full", "layers", "summary"]
    assert data["problems"][0]["compat_events"] == [
        {"kind": "step_after_done", "env_id": "CartPole-v0", "detail": "1 step"}
    ]


@pytest.mark.parametrize("stored", [{}, None], ids=["empty-dict", "absent"])
def test_a_report_without_a_sandbox_keeps_an_empty_isolation(stored: object) -> None:
    fields = {} if stored is None else {"isolation": stored}
    report = Report(
        submission="x.py",
        sha256="0" * 64,
        seed=1,
        gymnasium_version="1.4.0",
        grader_version="0",
        score=0.0,
        max_score=0.0,
        **fields,
    )

    assert report.isolation is None
    assert json.loads(report.to_json())["isolation"] == {}
    assert Report.model_validate_json(report.to_json()) == report


@pytest.mark.parametrize(
    "isolation",
    [{"full": True}, {**ISOLATION, "extra": 1}, {**ISOLATION, "layers": ["bubblewrap", "cgroup"]}],
    ids=["missing-fields", "extra-field", "layers-as-names"],
)
def test_a_malformed_isolation_summary_is_refused(isolation: dict[str, object]) -> None:
    with pytest.raises(ValidationError):
        ProblemRun.model_validate(
            {"submission": "x.py", "result": _report(1.0).problems[0], "isolation": isolation}
        )


def test_graded_view_ignores_only_the_timings() -> None:
    fast, slow = _report(1.0), _report(9.0)
    assert fast.to_json() != slow.to_json()
    assert fast.graded_view() == slow.graded_view()
    assert "execution_time" not in fast.graded_view()
    assert "timings" not in fast.graded_view()["problems"][0]


@pytest.mark.parametrize(
    ("statuses", "submission_error", "full"),
    [
        (["passed", "passed"], None, True),
        (["passed", "failed"], None, False),
        (["passed", "timeout"], None, False),
        (["passed", "skipped"], None, True),
        ([], "opengym.py is empty", False),
    ],
    ids=["all-passed", "one-failed", "one-timeout", "one-skipped", "unreadable-file"],
)
def test_full_marks(statuses: list[str], submission_error: str | None, full: bool) -> None:
    problems = [
        ProblemResult(id="car", title="car", status=status, score=0.0, max_score=1.0, feedback="")  # type: ignore[arg-type]
        for status in statuses
    ]
    report = _report(1.0).model_copy(update={"problems": problems, "submission_error": submission_error})
    assert report.full_marks is full


@pytest.mark.parametrize(
    ("value", "expected"),
    [
        (np.float64(0.25), 0.25),
        (np.int64(3), 3),
        (np.array([[1, 2], [3, 4]]), [[1, 2], [3, 4]]),
        (math.nan, "nan"),
        (-math.inf, "-inf"),
        ((1, "a", None, True), [1, "a", None, True]),
        ({"n": {1: np.bool_(True)}}, {"n": {"1": True}}),
    ],
    ids=["numpy-float", "numpy-int", "numpy-array", "nan", "minus-inf", "tuple", "nested-dict"],
)
def test_plain_json(value: object, expected: object) -> None:
    assert plain_json(value) == expected


def test_plain_json_refuses_objects() -> None:
    with pytest.raises(TypeError, match="found object"):
        plain_json(object())


def test_cap_output_keeps_the_start_and_says_how_much_was_cut() -> None:
    text = "x" * (OUTPUT_CAP_CHARS + 25)
    capped = cap_output(text)
    assert capped.startswith("x" * OUTPUT_CAP_CHARS)
    assert capped.endswith("[... 25 more characters of output not shown]")
    assert cap_output("short") == "short"


def test_a_run_holding_a_lone_surrogate_still_serialises_as_that_problem_s_error() -> None:
    result = ProblemResult(
        id="car",
        title="Problem 4",
        status="passed",
        score=1.0,
        max_score=1.0,
        feedback="ok",
        seed=1,
        output="printed \ud800 by the student",
    )
    line = ProblemRun(submission="s.py", result=result).to_json()
    parsed = ProblemRun.model_validate_json(line)
    assert parsed.result.status == "error"
    assert parsed.result.score == 0.0
    assert parsed.result.output == "printed \ufffd by the student"
    assert "cannot be stored" in parsed.result.feedback
