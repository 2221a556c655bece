"""Uploading and reading submissions over the API: who sees what, and bad input that must never be a 500."""

from __future__ import annotations

import hashlib
from collections.abc import Iterator
from pathlib import Path

import pytest
from api_testing import (
    BOTH_DATABASES,
    SettingsFactory,
    add_student,
    bearer,
    graded_upload,
    instructor_headers,
    recorded_statements,
)
from fastapi.testclient import TestClient

from api.main import create_app
from api.uploads import grading_file_name

SUBMISSIONS = Path(__file__).resolve().parents[2] / "submissions"

SOLUTION = b"def random_blackjack(n):\n    return 0.3\n"


def _upload(
    client: TestClient, token: str, name: str = "opengym.py", content: bytes = SOLUTION
) -> dict[str, object]:
    response = client.post(
        "/submissions", files={"file": (name, content, "text/x-python")}, headers=bearer(token)
    )
    assert response.status_code == 202, response.text
    body: dict[str, object] = response.json()
    return body


def test_upload_is_queued_and_visible_to_its_owner(client: TestClient) -> None:
    token = add_student(client, "ada")
    accepted = _upload(client, token)
    assert accepted["status"] == "queued"
    view = client.get(f"/submissions/{accepted['id']}", headers=bearer(token)).json()
    assert (view["status"], view["student"], view["filename"], view["report"]) == (
        "queued",
        "ada",
        "opengym.py",
        None,
    )
    assert view["sha256"] == hashlib.sha256(SOLUTION).hexdigest()


def test_students_see_only_their_own_and_the_instructor_sees_all(client: TestClient) -> None:
    ada, bob = add_student(client, "ada"), add_student(client, "bob")
    ada_id = _upload(client, ada)["id"]
    bob_id = _upload(client, bob)["id"]
    assert client.get(f"/submissions/{bob_id}", headers=bearer(ada)).status_code == 404
    assert client.get(f"/submissions/{ada_id}", headers=bearer(ada)).status_code == 200
    assert [item["id"] for item in client.get("/submissions", headers=bearer(ada)).json()] == [ada_id]
    everyone = client.get("/submissions", headers=instructor_headers()).json()
    assert [item["id"] for item in everyone] == [bob_id, ada_id]
    only_bob = client.get("/submissions", params={"student": "bob"}, headers=instructor_headers()).json()
    assert [item["id"] for item in only_bob] == [bob_id]
    assert client.get(f"/submissions/{bob_id}", headers=instructor_headers()).status_code == 200


@pytest.mark.parametrize(
    ("method", "path", "who", "expected"),
    [
        ("post", "/students", "nobody", 401),
        ("post", "/students", "student", 403),
        ("get", "/gradebook.csv", "student", 403),
        ("get", "/submissions", "nobody", 401),
        ("get", "/submissions/1", "forged", 401),
        ("get", "/submissions?student=nobody-by-that-name", "instructor", 404),
    ],
    ids=[
        "create-student-anonymous",
        "create-student-as-student",
        "gradebook-as-student",
        "list-anonymous",
        "forged-token",
        "unknown-student-filter",
    ],
)
def test_access_is_refused_with_a_clear_status(
    client: TestClient, method: str, path: str, who: str, expected: int
) -> None:
    headers = {
        "nobody": {},
        "forged": bearer("gg_not-a-real-token"),
        "student": bearer(add_student(client, "eve")),
        "instructor": instructor_headers(),
    }[who]
    response = client.request(method, path, headers=headers, json={"name": "x"} if method == "post" else None)
    assert response.status_code == expected
    assert response.json()["detail"]


def test_the_instructor_cannot_upload(client: TestClient) -> None:
    response = client.post(
        "/submissions", files={"file": ("opengym.py", SOLUTION)}, headers=instructor_headers()
    )
    assert response.status_code == 403
    assert "student's token" in response.json()["detail"]


@pytest.mark.parametrize(
    ("name", "content", "status", "message"),
    [
        (
            "opengym.txt",
            SOLUTION,
            422,
            "expected a Python file named like opengym.py or a notebook named like opengym.ipynb, "
            "found the name 'opengym.txt'",
        ),
        ("opengym.py", b"", 422, "opengym.py is empty; upload the file with your functions in it"),
        ("opengym.py", b"  \n\n", 422, "opengym.py is empty; upload the file with your functions in it"),
        (
            "opengym.py",
            b"x = 1\x00\x01",
            422,
            "opengym.py holds binary data (NUL bytes); expected Python source text",
        ),
        (
            "opengym.py",
            "x = 'é'".encode("latin-1"),
            422,
            "opengym.py is not UTF-8 text (byte 5 is 0xe9); save it as UTF-8 and upload it again",
        ),
        (
            "opengym.py",
            b"#" * 2048,
            413,
            "the file is larger than the limit of 1024 bytes; upload only your opengym.py source",
        ),
        (
            "opengym.py",
            b"#" * 200_000,
            413,
            "the request body is larger than the limit of 1024 bytes for a file; "
            "upload only your opengym.py source",
        ),
        ("", SOLUTION, 422, None),
    ],
    ids=["not-py", "empty", "blank", "binary", "latin-1", "over-limit", "far-over-limit", "no-name"],
)
def test_bad_uploads_get_a_clear_json_error(
    make_settings: SettingsFactory, name: str, content: bytes, status: int, message: str | None
) -> None:
    with TestClient(create_app(make_settings(max_upload_bytes=1024), run_workers=False)) as client:
        token = add_student(client, "mallory")
        response = client.post("/submissions", files={"file": (name, content)}, headers=bearer(token))
        assert response.status_code == status
        if message is not None:
            assert response.json() == {"detail": message}
        assert client.get("/submissions", headers=bearer(token)).json() == []


@pytest.mark.parametrize(
    ("client_name", "stored_name"),
    [
        ("../../etc/passwd.py", "passwd.py"),
        ("C:\\Users\\ada\\opengym.py", "opengym.py"),
        ("<b onclick=alert(1)>x</b>.py", "b_.py"),
        ("<script>alert(1).py", "_script_alert_1_.py"),
        ("...opengym.py", "opengym.py"),
        ("opengym (2).py", "opengym _2_.py"),
        ("a" * 300 + ".py", "a" * 97 + ".py"),
    ],
    ids=["traversal", "windows-path", "markup-with-slash", "markup", "leading-dots", "brackets", "very-long"],
)
def test_hostile_file_names_are_stored_sanitised(
    client: TestClient, client_name: str, stored_name: str
) -> None:
    token = add_student(client, "ada")
    submission_id = _upload(client, token, name=client_name)["id"]
    assert (
        client.get(f"/submissions/{submission_id}", headers=bearer(token)).json()["filename"] == stored_name
    )


def test_syntax_errors_are_accepted_for_the_grader_to_judge(client: TestClient) -> None:
    token = add_student(client, "ada")
    assert _upload(client, token, content=b"def broken(:\n")["status"] == "queued"


def test_uploads_over_the_rate_limit_are_refused_with_retry_after(make_settings: SettingsFactory) -> None:
    with TestClient(create_app(make_settings(rate_limit_per_minute=2), run_workers=False)) as client:
        token = add_student(client, "ada")
        _upload(client, token)
        _upload(client, token)
        response = client.post(
            "/submissions", files={"file": ("opengym.py", SOLUTION)}, headers=bearer(token)
        )
        assert response.status_code == 429
        assert 1 <= int(response.headers["Retry-After"]) <= 60
        assert response.json()["detail"].startswith("at most 2 uploads per minute; try again in ")
        other = add_student(client, "bob")
        assert _upload(client, other)["status"] == "queued"


def test_upload_without_content_length_is_refused(client: TestClient) -> None:
    token = add_student(client, "ada")

    def chunks() -> Iterator[bytes]:
        yield b'--b\r\nContent-Disposition: form-data; name="file"; filename="a.py"\r\n\r\nx=1\r\n--b--\r\n'

    response = client.post(
        "/submissions",
        content=chunks(),
        headers={**bearer(token), "Content-Type": "multipart/form-data; boundary=b"},
    )
    assert response.status_code == 411


def test_healthz_reports_the_queue(client: TestClient) -> None:
    token = add_student(client, "ada")
    _upload(client, token)
    assert client.get("/healthz").json() == {
        "status": "ok",
        "database": "sqlite",
        "queued": 1,
        "running": 0,
        "workers": 0,
    }


def test_healthz_counts_the_workers_this_process_grades_with(make_settings: SettingsFactory) -> None:
    with TestClient(create_app(make_settings(workers=2))) as running:
        assert running.get("/healthz").json()["workers"] == 2
    with TestClient(create_app(make_settings(workers=2), run_workers=False)) as not_grading:
        assert not_grading.get("/healthz").json()["workers"] == 0


@BOTH_DATABASES
@pytest.mark.parametrize(
    ("path", "status"),
    [
        ("/submissions/0", 404),
        ("/submissions/-5", 404),
        ("/submissions/99999999999999999999999", 404),
        ("/submissions?student=a%00b", 404),
        ("/submissions?student=" + "x" * 500, 404),
        ("/submissions/abc", 422),
    ],
    ids=["zero", "negative", "beyond-64-bits", "nul-in-name", "long-name", "not-a-number"],
)
def test_odd_identifiers_are_client_errors_on_every_database(
    client: TestClient, path: str, status: int
) -> None:
    assert client.get(path, headers=instructor_headers()).status_code == status


@pytest.mark.parametrize(
    ("settings", "fixed"),
    [({}, None), ({"seed_policy": "fixed", "seed": 77}, 77)],
    ids=["random-by-default", "fixed"],
)
def test_each_submission_stores_its_grading_seed(
    make_settings: SettingsFactory, settings: dict[str, object], fixed: int | None
) -> None:
    with TestClient(create_app(make_settings(**settings), run_workers=False)) as client:
        token = add_student(client, "ada")
        ids = [_upload(client, token)["id"] for _ in range(3)]
        seeds = [client.get(f"/submissions/{i}", headers=instructor_headers()).json()["seed"] for i in ids]
        own = client.get(f"/submissions/{ids[0]}", headers=bearer(token)).json()
    assert own["seed"] is None, "a student never sees the grading seed unless it is released"
    if fixed is not None:
        assert seeds == [fixed] * 3
    else:
        assert len(set(seeds)) == 3 and all(1 <= seed < 2**31 for seed in seeds)


@pytest.mark.slow  # a grading through the sandbox
def test_notebooks_are_accepted_and_graded_under_their_own_name(client: TestClient) -> None:
    token = add_student(client, "ada")
    notebook = (SUBMISSIONS / "notebooks" / "classic_complete.ipynb").read_bytes()
    accepted = _upload(client, token, name="opengym.ipynb", content=notebook)
    view = client.get(f"/submissions/{accepted['id']}", headers=bearer(token)).json()
    assert (view["status"], view["filename"]) == ("queued", "opengym.ipynb")
    assert grading_file_name("opengym.ipynb") == "opengym.ipynb"
    assert grading_file_name("my lab.ipynb") == "submission.ipynb"


def test_the_staff_listing_reads_no_file_progress_or_report_and_one_query_for_any_number(
    client: TestClient,
) -> None:
    token = add_student(client, "ada")
    graded_upload(client, token, {"car": 1.0})
    with recorded_statements(client) as one:
        assert len(client.get("/submissions", headers=instructor_headers()).json()) == 1
    for _ in range(3):
        graded_upload(client, token, {"car": 0.5})
    with recorded_statements(client) as four:
        listed = client.get("/submissions", headers=instructor_headers()).json()
    assert [item["score"] for item in listed] == [0.5, 0.5, 0.5, 1.0], "totals are the staff's to see"
    assert len(four) == len(one), "no query per submission"
    read = " ".join(sql for sql, _ in four)
    for column in ("submissions.content", "submissions.progress", "submissions.report"):
        assert column not in read
