"""What students see of their reports: no grading seeds unless released, no withheld problem's details."""

from __future__ import annotations

import json
from datetime import UTC, datetime, timedelta
from typing import Any

import pytest
from api_testing import INSTRUCTOR_TOKEN, SettingsFactory, add_student, bearer, instructor_headers
from fastapi.testclient import TestClient

from api.auth import Principal
from api.courses import default_values
from api.disclosure import FULL, Disclosure, disclosure_for, problem_view, report_view
from api.main import create_app
from api.models import Assignment, Student
from grader.report import ProblemResult, Report, Visibility

DUE = datetime(2026, 12, 1, 12, 0, tzinfo=UTC)
GRADING_SEED = 1_234_567
HIDDEN_NOTE = (
    "This problem's result is hidden from students (your instructor sees it); the total score is hidden "
    "with it."
)
LATER_NOTE = (
    "This problem's result is shown after the due date (2026-12-01 12:00 UTC); your instructor already "
    "sees it. The total score is shown then too."
)


def _problem(problem_id: str, visibility: Visibility, score: float) -> dict[str, Any]:
    return ProblemResult(
        id=problem_id,
        title=f"Problem {problem_id}",
        status="passed" if score else "failed",
        score=score,
        max_score=1.0,
        feedback=f"feedback of {problem_id}",
        measurements={f"{problem_id}_mean_length": 12.5},
        output=f"output of {problem_id}",
        compat_events=[{"kind": "seed_replaced", "env_id": "CartPole-v0", "detail": "your seed 3"}],
        seed=GRADING_SEED + len(problem_id),
        visibility=visibility,
    ).model_dump(mode="json")


def _report() -> dict[str, Any]:
    problems = [_problem("cartpole", "visible", 1.0), _problem("car", "after_due_date", 0.0)]
    problems.append(_problem("taxi", "hidden", 1.0))
    return Report(
        submission="opengym.py",
        sha256="0" * 64,
        seed=GRADING_SEED,
        gymnasium_version="1.4.0",
        grader_version="test",
        score=2.0,
        max_score=3.0,
        problems=[ProblemResult.model_validate(problem) for problem in problems],
    ).model_dump(mode="json")


STUDENT = Principal(name="ada", student=Student(name="ada", token_sha256="0" * 64))
INSTRUCTOR = Principal(name="instructor", student=None)


@pytest.mark.parametrize(
    ("caller", "settings", "now", "seeds", "shown"),
    [
        (INSTRUCTOR, {}, DUE, True, {"visible", "after_due_date", "hidden"}),
        (STUDENT, {}, DUE, False, {"visible"}),
        (STUDENT, {"due_date": DUE}, DUE - timedelta(seconds=1), False, {"visible"}),
        (STUDENT, {"due_date": DUE}, DUE, False, {"visible", "after_due_date"}),
        (STUDENT, {"release_seeds": True}, DUE, True, {"visible"}),
    ],
    ids=["instructor", "student-no-due-date", "before-due", "at-due", "seeds-released"],
)
def test_what_each_caller_may_see(
    make_settings: SettingsFactory,
    caller: Principal,
    settings: dict[str, Any],
    now: datetime,
    seeds: bool,
    shown: set[str],
) -> None:
    assignment = Assignment(**default_values(make_settings(**settings)))
    disclosure = disclosure_for(caller, assignment, now)
    assert (disclosure.seeds, set(disclosure.shown)) == (seeds, shown)


def test_the_instructor_sees_the_stored_report_unchanged() -> None:
    assert report_view(_report(), FULL) == _report()


def test_a_student_sees_no_seed_and_nothing_of_withheld_problems() -> None:
    student = Disclosure(seeds=False, shown=frozenset({"visible"}), due_date=DUE)
    view = report_view(_report(), student)
    assert (view["seed"], view["score"], view["max_score"]) == (None, None, 3.0)
    visible, later, hidden = view["problems"]
    assert visible == {**_problem("cartpole", "visible", 1.0), "seed": None}
    for problem, note in [(later, LATER_NOTE), (hidden, HIDDEN_NOTE)]:
        assert (problem["status"], problem["score"], problem["max_score"], problem["feedback"]) == (
            "withheld",
            None,
            1.0,
            note,
        )
        assert (problem["measurements"], problem["output"], problem["compat_events"]) == ({}, "", [])
        assert problem["seed"] is None
    serialised = str(view)
    assert "feedback of taxi" not in serialised and str(GRADING_SEED) not in serialised


def test_after_the_due_date_only_hidden_problems_stay_withheld() -> None:
    after_due = Disclosure(seeds=True, shown=frozenset({"visible", "after_due_date"}), due_date=DUE)
    view = report_view(_report(), after_due)
    assert [problem["status"] for problem in view["problems"]] == ["passed", "failed", "withheld"]
    assert view["seed"] == GRADING_SEED and view["score"] is None


def _varied_report(visibility: Visibility, outcome: int) -> dict[str, Any]:
    """cartpole shown, taxi ``visibility``: taxi's outcome, the time and the errors follow ``outcome``."""
    report = _report()
    problems = [_problem("cartpole", "visible", 1.0), _problem("taxi", visibility, [1.0, 0.0, 0.5][outcome])]
    problems[1].update(
        feedback=f"taxi outcome {outcome}",
        output="x" * outcome,
        timings={"wall_seconds": 3.0 + outcome, "student_seconds": 1.0 + outcome, "overhead_seconds": 2.0},
    )
    elapsed = 10.0 + 7 * outcome
    report.update(
        problems=problems,
        score=1.0 + problems[1]["score"],
        max_score=2.0,
        execution_time=elapsed,
        timings={"elapsed_seconds": elapsed, "workers": 2, "check_seconds": elapsed,
                 "student_seconds": 1.0 + outcome, "overhead_seconds": 9.0 + 6 * outcome},
        grader_errors=[f"taxi: failed {outcome}"] if outcome else [],
    )  # fmt: skip
    return report


@pytest.mark.parametrize("visibility", ["hidden", "after_due_date"])
def test_nothing_a_student_sees_varies_with_a_withheld_problem(visibility: Visibility) -> None:
    student = Disclosure(seeds=False, shown=frozenset({"visible"}), due_date=DUE)
    views = [json.dumps(report_view(_varied_report(visibility, outcome), student)) for outcome in range(3)]
    assert views[0] == views[1] == views[2]
    view = report_view(_varied_report(visibility, 1), student)
    assert (view["score"], view["execution_time"], view["timings"], view["grader_errors"]) == (
        None,
        None,
        None,
        [],
    )
    assert view["problems"][0]["timings"] == _problem("cartpole", "visible", 1.0)["timings"]


def test_a_shown_problems_grader_error_is_still_shown() -> None:
    report = {**_varied_report("hidden", 1), "grader_errors": ["cartpole: broke", "taxi: broke"]}
    view = report_view(report, Disclosure(seeds=False, shown=frozenset({"visible"})))
    assert view["grader_errors"] == ["cartpole: broke"]


def test_an_unset_due_date_is_named_in_the_note() -> None:
    view = problem_view(_problem("car", "after_due_date", 1.0), Disclosure(False, frozenset({"visible"})))
    assert view["feedback"].startswith(
        "This problem's result is shown after the due date (a date your instructor sets)"
    )


def _graded(client: TestClient, token: str, report: dict[str, Any] | None = None) -> int:
    response = client.post("/submissions", files={"file": ("opengym.py", b"x = 1\n")}, headers=bearer(token))
    submission_id: int = response.json()["id"]
    jobs = client.app.state.context.jobs  # type: ignore[attr-defined]
    job = jobs.claim("test-worker")
    assert job is not None and job.submission_id == submission_id
    report = report if report is not None else _report()
    for problem in report["problems"]:
        assert jobs.add_progress(submission_id, "test-worker", problem)
    assert jobs.complete(submission_id, "test-worker", report)
    return submission_id


@pytest.mark.parametrize(
    ("settings", "statuses", "seed_shown"),
    [
        ({}, ["passed", "withheld", "withheld"], False),
        ({"due_date": datetime.now(UTC) - timedelta(days=1)}, ["passed", "failed", "withheld"], False),
        ({"release_seeds": True}, ["passed", "withheld", "withheld"], True),
    ],
    ids=["default", "past-due-date", "seeds-released"],
)
def test_students_get_their_view_over_the_api(
    make_settings: SettingsFactory, settings: dict[str, Any], statuses: list[str], seed_shown: bool
) -> None:
    with TestClient(create_app(make_settings(**settings), run_workers=False)) as client:
        token = add_student(client, "ada")
        submission_id = _graded(client, token)
        own = client.get(f"/submissions/{submission_id}", headers=bearer(token)).json()
        listed = client.get("/submissions", headers=bearer(token)).json()
        full = client.get(f"/submissions/{submission_id}", headers=instructor_headers()).json()
    assert [problem["status"] for problem in own["report"]["problems"]] == statuses
    assert [problem["status"] for problem in own["progress"]] == statuses
    assert (own["score"], own["report"]["score"], listed[0]["score"]) == (None, None, None)
    assert (own["seed"] is not None, own["report"]["seed"] is not None) == (seed_shown, seed_shown)
    assert [problem["status"] for problem in full["report"]["problems"]] == ["passed", "failed", "passed"]
    assert (full["report"]["seed"], full["seed"] is not None) == (GRADING_SEED, True)
    assert own["seed"] == (full["seed"] if seed_shown else None)
    assert (full["score"], full["report"]["problems"][2]["feedback"]) == (2.0, "feedback of taxi")


def _sign_in(client: TestClient, token: str) -> None:
    client.cookies.clear()
    assert client.post("/ui/sign-in", data={"token": token}, follow_redirects=False).status_code == 303


def test_the_web_page_shows_students_their_view_and_the_instructor_everything(
    make_settings: SettingsFactory,
) -> None:
    with TestClient(create_app(make_settings(), run_workers=False)) as client:
        token = add_student(client, "ada")
        submission_id = _graded(client, token)
        _sign_in(client, token)
        student_page = client.get(f"/ui/submissions/{submission_id}").text
        student_home = client.get("/").text
        _sign_in(client, INSTRUCTOR_TOKEN)
        instructor_page = client.get(f"/ui/submissions/{submission_id}").text
    assert "feedback of cartpole" in student_page and "output of cartpole" in student_page
    for secret in ["feedback of taxi", "output of taxi", "feedback of car<", "taxi_mean_length", "seed "]:
        assert secret not in student_page, secret
    assert "This problem&#39;s result is hidden from students" in student_page
    assert "Score: withheld (out of 3)" in student_page and "withheld" in student_home
    assert "feedback of taxi" in instructor_page and "output of taxi" in instructor_page
    assert "Score: 2 / 3" in instructor_page and " · seed " in instructor_page


def test_the_students_pages_and_json_do_not_vary_with_a_withheld_problem(
    make_settings: SettingsFactory,
) -> None:
    seen = []
    with TestClient(create_app(make_settings(), run_workers=False)) as client:
        for outcome in range(3):
            token = add_student(client, f"student{outcome}")
            submission_id = _graded(client, token, _varied_report("hidden", outcome))
            own = client.get(f"/submissions/{submission_id}", headers=bearer(token)).json()
            _sign_in(client, token)
            fragment = client.get(f"/ui/submissions/{submission_id}/live").text
            seen.append((json.dumps([own["score"], own["report"], own["progress"]]), fragment))
    assert seen[0] == seen[1] == seen[2]
