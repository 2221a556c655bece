"""The gradebook CSV: one row per student, their latest or best graded submission, a column per problem."""

from __future__ import annotations

import csv
import io

import pytest
from api_testing import (
    BOTH_DATABASES,
    SettingsFactory,
    add_student,
    bearer,
    instructor_headers,
    recorded_statements,
)
from fastapi.testclient import TestClient

from api.main import create_app


def _graded(client: TestClient, token: str, scores: dict[str, float]) -> int:
    response = client.post("/submissions", files={"file": ("opengym.py", b"x = 1\n")}, headers=bearer(token))
    submission_id: int = response.json()["id"]
    jobs = client.app.state.context.jobs  # type: ignore[attr-defined]
    job = jobs.claim("test-worker")
    assert job is not None and job.submission_id == submission_id
    problems = [{"id": name, "score": score, "max_score": 1.0} for name, score in scores.items()]
    report = {"score": sum(scores.values()), "max_score": float(len(scores)), "problems": problems}
    assert jobs.complete(submission_id, "test-worker", report)
    return submission_id


def _rows(client: TestClient) -> list[dict[str, str]]:
    response = client.get("/gradebook.csv", headers=instructor_headers())
    assert response.status_code == 200
    assert response.headers["content-type"].startswith("text/csv")
    return list(csv.DictReader(io.StringIO(response.text)))


@BOTH_DATABASES
@pytest.mark.parametrize(
    ("policy", "expected_cartpole", "expected_total"),
    [("latest", "0", "1"), ("best", "1", "2")],
    ids=["latest", "best"],
)
def test_one_row_per_student_by_policy(
    make_settings: SettingsFactory, policy: str, expected_cartpole: str, expected_total: str
) -> None:
    with TestClient(create_app(make_settings(gradebook_policy=policy), run_workers=False)) as client:
        ada, bob = add_student(client, "ada"), add_student(client, "bob")
        add_student(client, "=cmd|' /C calc'!A0")
        best = _graded(client, ada, {"random_blackjack": 1.0, "cartpole": 1.0})
        latest = _graded(client, ada, {"random_blackjack": 1.0, "cartpole": 0.0})
        _graded(client, bob, {"random_blackjack": 0.0, "cartpole": 0.0})
        rows = _rows(client)
    assert [row["student"] for row in rows] == ["'=cmd|' /C calc'!A0", "ada", "bob"]
    ada_row = rows[1]
    assert ada_row["submission_id"] == str(best if policy == "best" else latest)
    assert (ada_row["cartpole"], ada_row["score"], ada_row["max_score"]) == (
        expected_cartpole,
        expected_total,
        "2",
    )
    assert rows[0]["score"] == "", "a student without a graded submission has empty cells"
    assert list(rows[0]) == [
        "student",
        "submission_id",
        "submitted_at",
        "sha256",
        "random_blackjack",
        "cartpole",
        "score",
        "max_score",
        "note",
    ]


def test_ungraded_submissions_are_not_in_the_gradebook(client: TestClient) -> None:
    ada = add_student(client, "ada")
    client.post("/submissions", files={"file": ("opengym.py", b"x = 1\n")}, headers=bearer(ada))
    assert _rows(client) == [
        {
            "student": "ada",
            "submission_id": "",
            "submitted_at": "",
            "sha256": "",
            "score": "",
            "max_score": "",
            "note": "",
        }
    ]


@pytest.mark.parametrize(
    ("gradebook_format", "header"),
    [
        ("canvas", ["Student", "ID", "SIS User ID", "SIS Login ID", "Section", "OpenGym lab (77)"]),
        ("gradescope", ["Name", "SID", "Email", "Total Score", "Max Points", "Status", "random_blackjack"]),
        ("github-classroom", ["github_username", "roster_identifier", "points_awarded", "points_available"]),
    ],
    ids=["canvas", "gradescope", "github-classroom"],
)
def test_the_export_offers_the_formats_of_gymgrade_grade(
    make_settings: SettingsFactory, gradebook_format: str, header: list[str]
) -> None:
    with TestClient(create_app(make_settings(), run_workers=False)) as client:
        ada = add_student(client, "1234")
        add_student(client, "octocat")
        _graded(client, ada, {"random_blackjack": 1.0})
        response = client.get(
            "/gradebook.csv",
            params={"format": gradebook_format, "assignment_id": "77", "assignment_title": "OpenGym lab"},
            headers=instructor_headers(),
        )
    assert response.status_code == 200, response.text
    rows = list(csv.reader(io.StringIO(response.text)))
    assert rows[0] == header
    if gradebook_format == "canvas":
        assert rows[1:] == [["    Points Possible", "", "", "", "", "1"], ["1234", "1234", "", "", "", "1"]]
    elif gradebook_format == "gradescope":
        assert rows[1:] == [
            ["1234", "1234", "", "1", "1", "Graded", "1"],
            ["octocat", "octocat", "", "", "", "Missing", ""],
        ]
    else:
        assert rows[1:] == [["1234", "", "1", "1"], ["octocat", "", "", "1"]]


def test_a_canvas_export_without_the_assignment_id_is_refused(client: TestClient) -> None:
    response = client.get("/gradebook.csv", params={"format": "canvas"}, headers=instructor_headers())
    assert response.status_code == 422
    assert "format=canvas needs assignment_id" in response.text


@pytest.mark.parametrize(
    ("lab", "column"),
    [(None, "OpenGym AI lab (77)"), ("rl2", "Policy Function Iteration lab (77)")],
    ids=["first-lab-unchanged", "second-lab"],
)
def test_a_canvas_export_names_the_services_lab_unless_given_a_title(
    make_settings: SettingsFactory, lab: str | None, column: str
) -> None:
    with TestClient(create_app(make_settings(lab=lab), run_workers=False)) as client:
        ada = add_student(client, "1234")
        _graded(client, ada, {"random_blackjack": 1.0})
        response = client.get(
            "/gradebook.csv", params={"format": "canvas", "assignment_id": "77"}, headers=instructor_headers()
        )
    assert response.status_code == 200, response.text
    assert next(csv.reader(io.StringIO(response.text)))[-1] == column


def _gradebook_statements(client: TestClient) -> list[tuple[str, object]]:
    with recorded_statements(client) as statements:
        _rows(client)
    return statements


def test_the_gradebook_reads_in_as_many_queries_for_any_class_and_only_the_kept_reports(
    client: TestClient,
) -> None:
    kept = []
    for number in range(2):
        token = add_student(client, f"s{number}")
        _graded(client, token, {"car": 0.0})
        kept.append(_graded(client, token, {"car": 1.0}))
    few = _gradebook_statements(client)
    for number in range(2, 6):
        token = add_student(client, f"s{number}")
        _graded(client, token, {"car": 0.0})
        kept.append(_graded(client, token, {"car": 1.0}))
    many = _gradebook_statements(client)
    assert len(many) == len(few), "no query per student"
    (reports,) = [(sql, parameters) for sql, parameters in many if "submissions.report" in sql]
    assert sorted(reports[1]) == sorted(kept), "the reports of the kept uploads only (latest policy)"
