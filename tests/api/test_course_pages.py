"""The pages of courses: the operator creates a course and its first staff; a course's instructors add
assignments and staff; a teaching assistant sees and adds nothing; another course's staff find nothing."""

from __future__ import annotations

import re

from api_testing import INSTRUCTOR_TOKEN, add_student
from fastapi.testclient import TestClient

TOKEN = re.compile(r'<code id="staff-token">([^<]+)</code>')


def _sign_in(client: TestClient, token: str) -> str:
    response = client.post("/ui/sign-in", data={"token": token}, follow_redirects=False)
    assert response.status_code == 303
    return response.headers["location"]


def _course_with_staff(client: TestClient, slug: str, name: str, role: str = "instructor") -> str:
    """The operator makes course ``slug`` and its staff member ``name`` on the pages; their token."""
    client.cookies.clear()
    _sign_in(client, INSTRUCTOR_TOKEN)
    if client.get(f"/ui/courses/{slug}").status_code == 404:
        made = client.post(
            "/ui/courses", data={"slug": slug, "title": f"Course {slug}"}, follow_redirects=False
        )
        assert (made.status_code, made.headers["location"]) == (303, f"/ui/courses/{slug}")
    added = client.post(f"/ui/courses/{slug}/staff", data={"name": name, "role": role})
    assert added.status_code == 200 and added.headers["cache-control"] == "no-store"
    found = TOKEN.search(added.text)
    assert found is not None, added.text
    client.cookies.clear()
    return found.group(1)


def test_the_operator_lists_every_course_and_creates_one(client: TestClient) -> None:
    assert _sign_in(client, INSTRUCTOR_TOKEN) == "/"
    listed = client.get("/ui/courses")
    assert listed.status_code == 200 and 'id="new-course"' in listed.text
    assert '<a href="/ui/courses/default">' in listed.text
    made = client.post("/ui/courses", data={"slug": "rl-2026", "title": "RL <2026>"})
    assert made.status_code == 200 and made.url.path == "/ui/courses/rl-2026"
    assert "RL &lt;2026&gt;" in made.text and "No assignment yet." in made.text
    assert "No staff yet: add the course's first instructor below." in made.text
    assert '<a href="/ui/courses/rl-2026">' in client.get("/ui/courses").text


def test_a_refused_course_says_why_on_the_form(client: TestClient) -> None:
    _sign_in(client, INSTRUCTOR_TOKEN)
    bad = client.post("/ui/courses", data={"slug": "RL 2026", "title": "RL"})
    assert bad.status_code == 422
    assert "Short name: lower-case letters, digits and dashes" in bad.text
    assert 'value="RL 2026"' in bad.text
    taken = client.post("/ui/courses", data={"slug": "default", "title": "again"})
    assert taken.status_code == 409
    assert "a course with slug &#39;default&#39; exists already; choose another slug" in taken.text


def test_a_course_instructor_adds_an_assignment_of_the_second_lab_and_a_ta(client: TestClient) -> None:
    token = _course_with_staff(client, "rl-b", "Grace")
    assert _sign_in(client, token) == "/ui/courses"
    listed = client.get("/ui/courses")
    assert '<a href="/ui/courses/rl-b">' in listed.text and "/ui/courses/default" not in listed.text
    assert 'id="new-course"' not in listed.text
    added = client.post(
        "/ui/courses/rl-b/assignments",
        data={"slug": "pfi", "title": "Policy iteration", "edition": "v2026", "seed_policy": "fixed",
              "due_date": "2026-03-01T23:59", "gradebook_policy": "best"},
    )  # fmt: skip
    assert added.status_code == 200, added.text
    row = re.search(r'<tr id="assignment-pfi">.*?</tr>', added.text, re.S)
    assert row is not None
    assert "rl2" in row.group(0) and "2026-03-01 23:59" in row.group(0) and ">best<" in row.group(0)
    assert "<code>value_iteration</code>" in row.group(0)
    again = client.post("/ui/courses/rl-b/assignments", data={"slug": "pfi", "title": "again"})
    assert again.status_code == 409 and "has an assignment &#39;pfi&#39; already" in again.text
    ta = client.post("/ui/courses/rl-b/staff", data={"name": "Alan", "role": "ta"})
    assert "Alan added as teaching assistant" in ta.text


def test_a_teaching_assistant_sees_the_assignments_and_changes_nothing(client: TestClient) -> None:
    token = _course_with_staff(client, "rl-c", "Alan", role="ta")
    _sign_in(client, token)
    shown = client.get("/ui/courses/rl-c")
    assert shown.status_code == 200 and "Alan" in shown.text
    assert 'id="new-assignment"' not in shown.text and 'id="new-staff"' not in shown.text
    refused = client.post("/ui/courses/rl-c/assignments", data={"slug": "x", "title": "x"})
    assert refused.status_code == 403 and "a teaching assistant&#39;s was sent" in refused.text
    assert client.post("/ui/courses/rl-c/staff", data={"name": "Eve"}).status_code == 403


def test_another_course_is_not_found_and_visitors_and_students_refused_its_staff_forms(
    client: TestClient,
) -> None:
    token = _course_with_staff(client, "rl-d", "Grace")
    _sign_in(client, token)
    assert client.get("/ui/courses/default").status_code == 404
    assert client.post("/ui/courses/default/staff", data={"name": "Eve"}).status_code == 404
    assert client.post("/ui/courses", data={"slug": "mine", "title": "Mine"}).status_code == 403
    client.cookies.clear()
    assert client.get("/ui/courses").status_code == 401
    _sign_in(client, add_student(client, "ada"))
    listed = client.get("/ui/courses")  # a student sees their own course, its assignments, not its staff
    assert listed.status_code == 200 and "new-course" not in listed.text
    assert '<a href="/ui/courses/default">' in listed.text and "/ui/courses/rl-d" not in listed.text
    course = client.get("/ui/courses/default")
    assert course.status_code == 200 and 'href="/ui/courses/default/assignments/default"' in course.text
    assert 'id="staff"' not in course.text and "Gradebook keeps" not in course.text
    assert client.get("/ui/courses/rl-d").status_code == 404
    assert client.post("/ui/courses/default/staff", data={"name": "Eve"}).status_code == 403
