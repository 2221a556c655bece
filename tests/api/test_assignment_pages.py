"""The pages of any assignment of any course (``/ui/courses/{course}/assignments/{assignment}/...``): two
courses, the second with two assignments; an upload through an assignment's page lands on that assignment,
its report and gradebook are that assignment's, another course's staff and students find nothing, and
what a teaching assistant or a student may do there is what the API lets them do."""

from __future__ import annotations

import re
from typing import Any

import pytest
from api_testing import INSTRUCTOR_TOKEN, add_student, bearer
from fastapi.testclient import TestClient

PAGES = "/ui/courses/rl-b/assignments/{}"
SOLUTION = b"x = 1\n"


def _post(client: TestClient, path: str, body: dict[str, Any], token: str = INSTRUCTOR_TOKEN) -> Any:
    response = client.post(path, json=body, headers=bearer(token))
    assert response.status_code == 201, response.text
    return response.json()


@pytest.fixture
def course_b(client: TestClient) -> dict[str, str]:
    """Course rl-b with assignments lab-1 (the first lab) and lab-2 (the second), an instructor, a TA and a
    student; their tokens."""
    _post(client, "/courses", {"slug": "rl-b", "title": "Reinforcement Learning B"})
    tokens = {
        role: _post(client, "/courses/rl-b/staff", {"name": f"{role} of B", "role": role})["token"]
        for role in ("instructor", "ta")
    }
    _post(client, "/courses/rl-b/assignments", {"slug": "lab-1", "title": "First lab"}, tokens["instructor"])
    second = {"slug": "lab-2", "title": "Second lab", "edition": "v2026"}
    _post(client, "/courses/rl-b/assignments", second, tokens["instructor"])
    tokens["student"] = _post(client, "/courses/rl-b/students", {"name": "bea"}, tokens["instructor"])[
        "token"
    ]
    return tokens


def _sign_in(client: TestClient, token: str) -> str:
    client.cookies.clear()
    response = client.post("/ui/sign-in", data={"token": token}, follow_redirects=False)
    assert response.status_code == 303
    return str(response.headers["location"])


def _upload(client: TestClient, pages: str) -> int:
    """Upload through the page's form and grade it as a worker would; the submission's id."""
    response = client.post(
        pages + "/submissions", files={"file": ("opengym.py", SOLUTION)}, follow_redirects=False
    )
    assert response.status_code == 303, response.text
    found = re.fullmatch(re.escape(pages) + r"/submissions/(\d+)", response.headers["location"])
    assert found is not None, response.headers["location"]
    submission_id = int(found.group(1))
    jobs = client.app.state.context.jobs  # type: ignore[attr-defined]
    job = jobs.claim("test-worker")
    assert job is not None and job.submission_id == submission_id
    report = {
        "score": 1.0,
        "max_score": 1.0,
        "problems": [{"id": "blackjack", "score": 1.0, "max_score": 1.0}],
    }
    assert jobs.complete(submission_id, "test-worker", report)
    return submission_id


def test_a_student_reaches_their_course_assignments_and_uploads_to_the_one_whose_page_it_is(
    client: TestClient, course_b: dict[str, str]
) -> None:
    assert _sign_in(client, course_b["student"]) == "/ui/courses"
    course = client.get("/ui/courses/rl-b").text
    for slug in ("lab-1", "lab-2"):
        assert f'href="{PAGES.format(slug)}"' in course
    home = client.get(PAGES.format("lab-2"))
    assert home.status_code == 200 and 'id="upload"' in home.text
    assert f'action="{PAGES.format("lab-2")}/submissions"' in home.text and "Second lab" in home.text
    submission_id = _upload(client, PAGES.format("lab-2"))
    listed = client.get("/courses/rl-b/assignments/lab-2/submissions", headers=bearer(course_b["student"]))
    assert [item["id"] for item in listed.json()] == [submission_id]
    assert (
        client.get("/courses/rl-b/assignments/lab-1/submissions", headers=bearer(course_b["student"])).json()
        == []
    )
    report = client.get(f"{PAGES.format('lab-2')}/submissions/{submission_id}")
    assert report.status_code == 200
    assert f'data-src="{PAGES.format("lab-2")}/submissions/{submission_id}/live"' in report.text
    assert client.get(f"{PAGES.format('lab-2')}/submissions/{submission_id}/live").status_code == 200
    assert client.get(f"{PAGES.format('lab-1')}/submissions/{submission_id}").status_code == 404
    assert client.get(f"/ui/submissions/{submission_id}").status_code == 404  # the default course's
    start = client.get("/", follow_redirects=False)  # the start page: their course's assignments
    assert (start.status_code, start.headers["location"]) == (303, "/ui/courses")
    assert client.get("/ui/courses/default/assignments/default").status_code == 404
    assert client.get("/ui/courses/rl-b/assignments/lab-3").status_code == 404


def test_another_course_s_report_and_pages_are_not_found(
    client: TestClient, course_b: dict[str, str]
) -> None:
    _sign_in(client, add_student(client, "ada"))
    default_upload = _upload(client, "/ui")
    _sign_in(client, course_b["student"])
    b_upload = _upload(client, PAGES.format("lab-1"))
    _sign_in(client, course_b["instructor"])
    assert client.get(f"{PAGES.format('lab-1')}/submissions/{b_upload}").status_code == 200
    assert client.get(f"/ui/submissions/{default_upload}").status_code == 404
    assert (
        client.get(f"/ui/courses/default/assignments/default/submissions/{default_upload}").status_code == 404
    )
    assert client.get(f"{PAGES.format('lab-1')}/submissions/{default_upload}").status_code == 404
    assert client.get("/ui/courses/default/assignments/default/gradebook.csv").status_code == 404
    _sign_in(client, INSTRUCTOR_TOKEN)  # the operator reaches both, the default's under both addresses
    for path in (
        f"/ui/submissions/{default_upload}",
        f"/ui/courses/default/assignments/default/submissions/{default_upload}",
        f"{PAGES.format('lab-1')}/submissions/{b_upload}",
    ):
        assert client.get(path).status_code == 200, path


def test_an_assignment_s_gradebook_holds_only_its_uploads_and_its_forms_follow_the_api_s_roles(
    client: TestClient, course_b: dict[str, str]
) -> None:
    _sign_in(client, add_student(client, "ada"))
    _upload(client, "/ui")
    _sign_in(client, course_b["student"])
    first = _upload(client, PAGES.format("lab-1"))
    second = _upload(client, PAGES.format("lab-2"))
    _sign_in(client, course_b["ta"])
    home = client.get(PAGES.format("lab-1")).text
    assert "All submissions" in home and f'href="{PAGES.format("lab-1")}/gradebook.csv"' in home
    assert (
        f'href="{PAGES.format("lab-1")}/submissions/{first}"' in home and f"/submissions/{second}" not in home
    )
    rows = client.get(PAGES.format("lab-1") + "/gradebook.csv").text.splitlines()
    assert rows[0].startswith("student,submission_id") and len(rows) == 2
    assert rows[1].startswith(f"bea,{first},"), rows
    api_rows = client.get("/courses/rl-b/assignments/lab-1/gradebook.csv", headers=bearer(course_b["ta"]))
    assert api_rows.text.splitlines() == rows
    override = {"student": "bea", "problem": "blackjack", "points": "0.5", "reason": "r"}
    kept = client.post(PAGES.format("lab-1") + "/overrides", data=override)  # a TA grades, as over the API
    assert kept.status_code == 200 and 'id="override-result"' in kept.text
    shown = client.get(
        "/courses/rl-b/assignments/lab-1/students/bea/overrides", headers=bearer(course_b["ta"])
    )
    assert len(shown.json()) == 1
    assert (
        client.get(
            "/courses/rl-b/assignments/lab-2/students/bea/overrides", headers=bearer(course_b["ta"])
        ).json()
        == []
    )
    other = _post(client, "/courses/default/staff", {"name": "Alan", "role": "instructor"})["token"]
    _sign_in(client, other)
    assert client.post(PAGES.format("lab-1") + "/overrides", data=override).status_code == 404
    assert client.get(PAGES.format("lab-1") + "/gradebook.csv").status_code == 404
    _sign_in(client, course_b["student"])
    assert client.post(PAGES.format("lab-1") + "/overrides", data=override).status_code == 403
    assert client.get(PAGES.format("lab-1") + "/gradebook.csv").status_code == 403
    _sign_in(client, course_b["instructor"])
    student_rows = client.get(PAGES.format("lab-2") + "/gradebook.csv").text.splitlines()
    assert len(student_rows) == 2 and student_rows[1].startswith(f"bea,{second},")
    assert client.get("/ui/gradebook.csv").status_code == 404  # the default course's, not theirs
