"""The embedded default course and assignment: its row follows the settings, its jobs are graded as it says,
and its late policy's extensions are keyed by enrolment."""

from __future__ import annotations

import csv
import io
import time
from datetime import UTC, datetime, timedelta
from pathlib import Path

import pytest
from api_testing import SettingsFactory, add_student, bearer, graded_upload, instructor_headers
from fastapi.testclient import TestClient
from live_server import GRADING_WAIT_SECONDS

import grader.lab as grader_lab
from api.courses import DEFAULT_ASSIGNMENT_ID, default_assignment, sync_default
from api.main import create_app
from api.models import Assignment, Extension, Staff, Student, Submission
from api.security import token_digest

pytestmark = pytest.mark.slow  # each starts the service on a fresh database (about a second)


def test_the_default_assignment_is_what_the_settings_say_at_every_start(
    make_settings: SettingsFactory,
) -> None:
    due = datetime(2026, 5, 1, 12, tzinfo=UTC)
    first = make_settings(lab="rl2", seed_policy="fixed", seed=77, due_date=due, gradebook_policy="best")
    with TestClient(create_app(first, run_workers=False)) as client:
        with client.app.state.context.sessions() as session:  # type: ignore[attr-defined]
            row = default_assignment(session)
            assert (row.lab, row.edition, row.seed_policy, row.seed, row.gradebook_policy) == (
                "rl2", None, "fixed", 77, "best"
            )  # fmt: skip
            assert row.due_date == due.replace(tzinfo=None)
        token = add_student(client, "ada")
        upload = client.post(
            "/submissions", files={"file": ("opengym.py", b"x = 1\n")}, headers=bearer(token)
        )
        job = client.app.state.context.jobs.claim("w")  # type: ignore[attr-defined]
        assert (job.submission_id, job.seed, job.assignment) == (upload.json()["id"], 77, ("rl2", None))
    again = make_settings(edition="gym026")
    with TestClient(create_app(again, run_workers=False)) as client:
        sessions = client.app.state.context.sessions  # type: ignore[attr-defined]
        with sessions() as session:
            row = session.get_one(Assignment, DEFAULT_ASSIGNMENT_ID)
            assert (row.lab, row.edition, row.seed_policy, row.due_date, row.gradebook_policy) == (
                None, "gym026", "random", None, "latest"
            )  # fmt: skip
            assert sync_default(session, make_settings(edition="gym026")) is row  # unchanged: nothing written


def test_an_extension_is_an_enrolments_not_a_names(make_settings: SettingsFactory, tmp_path: Path) -> None:
    due = datetime(2026, 3, 1, 23, 59, tzinfo=UTC)
    policy = tmp_path / "late.toml"
    policy.write_text(f"[late]\ndue = {due.isoformat()}\npenalty_per_day = 0.25\n", encoding="utf-8")
    with TestClient(create_app(make_settings(late_policy=policy), run_workers=False)) as client:
        tokens = {name: add_student(client, name) for name in ("ada", "bob")}
        uploads = {
            name: graded_upload(client, token, {"car": 1.0, "taxi": 1.0}) for name, token in tokens.items()
        }
        with client.app.state.context.sessions() as session:  # type: ignore[attr-defined]
            for upload in uploads.values():  # both a day and a second late
                session.get_one(Submission, upload).created_at = (due + timedelta(days=1, seconds=1)).replace(
                    tzinfo=None
                )
            bob = session.query(Student).filter_by(name="bob").one()
            session.add(
                Extension(
                    assignment_id=DEFAULT_ASSIGNMENT_ID,
                    student_id=bob.id,
                    due=(due + timedelta(days=3)).replace(tzinfo=None),
                    reason="ill",
                    author="operator",
                )
            )
            bob.name = "robert"  # renamed: the extension stays his
            session.commit()
        response = client.get("/gradebook.csv", headers=instructor_headers())
        rows = {row["student"]: row for row in csv.DictReader(io.StringIO(response.text))}
        assert {name: (row["late_penalty"], row["score"]) for name, row in rows.items()} == {
            "ada": ("1", "1"),
            "robert": ("0", "2"),
        }


A = "/courses/a/assignments/lab1"
B = "/courses/b/assignments/lab1"


def _graded(client: TestClient, prefix: str, token: str, score: float) -> int:
    """Upload to the assignment under ``prefix`` and complete its job as a worker would."""
    response = client.post(
        f"{prefix}/submissions", files={"file": ("opengym.py", b"x = 1\n")}, headers=bearer(token)
    )
    assert response.status_code == 202, response.text
    submission_id: int = response.json()["id"]
    assert response.headers["Location"] == f"{prefix}/submissions/{submission_id}"
    jobs = client.app.state.context.jobs  # type: ignore[attr-defined]
    job = jobs.claim("test-worker", submission_id)
    report = {"score": score, "max_score": 1.0, "problems": [{"id": "car", "score": score, "max_score": 1.0}]}
    assert job is not None and jobs.complete(submission_id, "test-worker", report)
    return submission_id


def _course(client: TestClient, slug: str, edition: str) -> dict[str, str]:
    """A course with assignment lab1, its instructor and TA, and a student ada: their tokens."""
    operator = instructor_headers()
    assert (
        client.post("/courses", json={"slug": slug, "title": f"Course {slug}"}, headers=operator).status_code
        == 201
    )
    tokens = {
        role: client.post(
            f"/courses/{slug}/staff", json={"name": f"{role} of {slug}", "role": role}, headers=operator
        ).json()["token"]
        for role in ("instructor", "ta")
    }
    assignment = {"slug": "lab1", "title": "Lab 1", "edition": edition}
    created = client.post(
        f"/courses/{slug}/assignments", json=assignment, headers=bearer(tokens["instructor"])
    )
    assert created.status_code == 201, created.text
    student = client.post(
        f"/courses/{slug}/students", json={"name": "ada"}, headers=bearer(tokens["instructor"])
    )
    tokens["student"] = student.json()["token"]
    return tokens


def test_staff_and_students_of_one_course_reach_nothing_of_another(make_settings: SettingsFactory) -> None:
    with TestClient(create_app(make_settings(), run_workers=False)) as client:
        a, b = _course(client, "a", "rl1"), _course(client, "b", "v2024")
        mine = _graded(client, A, a["student"], 1.0)
        theirs = _graded(client, B, b["student"], 0.0)
        default = add_student(client, "dee")  # the embedded default course's
        graded_upload(client, default, {"car": 1.0})
        attempts = [
            ("get", f"{A}/submissions", None),
            ("get", f"{A}/submissions/{mine}", None),
            ("get", f"{A}/gradebook.csv", None),
            ("post", f"{A}/students/ada/overrides", {"problem": "car", "points": 0, "reason": "x"}),
            ("get", f"{A}/students/ada/overrides", None),
            ("post", f"{A}/submissions/{mine}/regrade", None),
            ("post", f"{A}/students/ada/regrade", None),
            ("post", "/courses/a/students", {"name": "mallory"}),
            ("post", "/courses/a/staff", {"name": "mallory", "role": "instructor"}),
            ("post", "/courses/a/assignments", {"slug": "lab2", "title": "Lab 2"}),
            ("get", "/courses/a/assignments", None),
            ("get", "/submissions", None),  # the default course's, the routes without a prefix
            ("get", "/gradebook.csv", None),
            ("post", "/students", {"name": "mallory"}),
            ("get", "/students/dee/overrides", None),
            ("get", "/lti/links", None),
            ("get", "/lti/scores", None),
            ("post", "/lti/links/1/roster", None),
        ]
        for role in ("instructor", "ta", "student"):
            for method, path, body in attempts:
                response = client.request(method, path, json=body, headers=bearer(b[role]))
                assert response.status_code == 404, (role, method, path, response.status_code, response.text)
        upload = client.post(
            f"{A}/submissions", files={"file": ("opengym.py", b"x\n")}, headers=bearer(b["student"])
        )
        assert upload.status_code == 404
        # their own assignment does not show another's upload by its id either
        assert client.get(f"{B}/submissions/{mine}", headers=bearer(b["instructor"])).status_code == 404
        # and nothing of A changed
        rows = client.get(f"{A}/gradebook.csv", headers=bearer(a["ta"])).text.splitlines()
        assert [row.split(",")[:2] for row in rows[1:]] == [["ada", str(mine)]]
        assert client.get(f"{A}/students/ada/overrides", headers=bearer(a["instructor"])).json() == []
        assert [item["id"] for item in client.get(f"{B}/submissions", headers=bearer(b["ta"])).json()] == [
            theirs
        ]
        assert [c["slug"] for c in client.get("/courses", headers=bearer(b["ta"])).json()] == ["b"]
        assert [c["slug"] for c in client.get("/courses", headers=instructor_headers()).json()] == [
            "default", "a", "b"
        ]  # fmt: skip


def test_a_teaching_assistant_grades_but_does_not_manage_the_course(make_settings: SettingsFactory) -> None:
    with TestClient(create_app(make_settings(), run_workers=False)) as client:
        a = _course(client, "a", "rl1")
        mine = _graded(client, A, a["student"], 0.0)
        ta = bearer(a["ta"])
        kept = client.post(
            f"{A}/students/ada/overrides",
            json={"problem": "car", "points": 1, "reason": "by hand"},
            headers=ta,
        )
        assert (kept.status_code, kept.json()["author"]) == (201, "ta of a")
        rows = client.get(f"{A}/gradebook.csv", headers=ta).text.splitlines()
        assert rows[1].split(",")[:2] == ["ada", str(mine)] and "car overridden to 1" in rows[1]
        assert client.post(f"{A}/submissions/{mine}/regrade", headers=ta).status_code == 202
        refused = [
            client.post("/courses/a/staff", json={"name": "x", "role": "ta"}, headers=ta),
            client.post("/courses/a/assignments", json={"slug": "lab2", "title": "Lab 2"}, headers=ta),
            client.post("/courses/a/students", json={"name": "bob"}, headers=ta),
            client.post("/courses", json={"slug": "c", "title": "C"}, headers=bearer(a["instructor"])),
            client.post("/lti/keys/rotate", headers=bearer(a["instructor"])),
        ]
        assert [response.status_code for response in refused] == [403] * 5


def test_an_assignment_grades_as_its_own_lab_and_a_name_is_unique_in_its_course_only(
    make_settings: SettingsFactory,
) -> None:
    with TestClient(create_app(make_settings(lab="opengym"), run_workers=False)) as client:
        _course(client, "a", "v2024")  # its ada is not the default course's
        assert client.post("/students", json={"name": "ada"}, headers=instructor_headers()).status_code == 201
        again = client.post("/courses/a/students", json={"name": "ada"}, headers=instructor_headers())
        assert again.status_code == 409
        token = client.post("/courses/a/students", json={"name": "bea"}, headers=instructor_headers()).json()[
            "token"
        ]
        client.post(f"{A}/submissions", files={"file": ("opengym.py", b"x = 1\n")}, headers=bearer(token))
        job = client.app.state.context.jobs.claim("w")  # type: ignore[attr-defined]
        assert job.assignment == (None, "v2024")
        listed = client.get("/courses/a/assignments", headers=bearer(token)).json()
        assert [(item["slug"], item["lab"], item["edition"]) for item in listed] == [("lab1", "rl2", "v2024")]
        wrong = client.post(
            "/courses/a/assignments",
            json={"slug": "x", "title": "X", "edition": "v1999"},
            headers=instructor_headers(),
        )
        assert wrong.status_code == 422 and "edition" in wrong.json()["detail"]
        fixed = client.post(
            "/courses/a/assignments",
            json={"slug": "y", "title": "Y", "seed_policy": "fixed"},
            headers=instructor_headers(),
        )
        assert fixed.status_code == 201  # a secret seed drawn: never the practice seed
        with client.app.state.context.sessions() as session:  # type: ignore[attr-defined]
            assert session.query(Assignment).filter_by(slug="y").one().seed > 0
        taken = client.post(
            "/courses/a/assignments", json={"slug": "lab1", "title": "X"}, headers=instructor_headers()
        )
        assert taken.status_code == 409


def test_a_staff_token_reaches_one_course_with_its_role_and_is_revoked(
    make_settings: SettingsFactory,
) -> None:
    with TestClient(create_app(make_settings(), run_workers=False)) as client:
        a, b = _course(client, "a", "rl1"), _course(client, "b", "rl1")
        operator = instructor_headers()
        made = client.post("/courses/a/staff", json={"name": "Bot", "role": "ta"}, headers=operator).json()
        token = bearer(made["token"])
        assert client.get(f"{A}/submissions", headers=token).status_code == 200
        assert client.get(f"{B}/submissions", headers=token).status_code == 404  # another course's
        assert (
            client.post("/courses/a/students", json={"name": "x"}, headers=token).status_code == 403
        )  # a TA's
        listed = client.get("/courses/a/staff", headers=bearer(a["instructor"])).json()
        assert [(row["name"], row["role"], row["token"]) for row in listed] == [
            ("instructor of a", "instructor", True), ("ta of a", "ta", True), ("Bot", "ta", True)
        ]  # fmt: skip
        assert "token_sha256" not in listed[0] and all(made["token"] not in str(row) for row in listed)
        with client.app.state.context.sessions() as session:  # type: ignore[attr-defined]
            stored = session.get_one(Staff, made["id"]).token_sha256
            assert stored == token_digest(made["token"])  # only the digest is kept
        # another course's instructor, and a TA, may neither list nor revoke
        assert (
            client.delete(f"/courses/a/staff/{made['id']}/token", headers=bearer(b["instructor"])).status_code
            == 404
        )
        assert (
            client.delete(f"/courses/a/staff/{made['id']}/token", headers=bearer(a["ta"])).status_code == 403
        )
        assert client.delete(f"/courses/b/staff/{made['id']}/token", headers=operator).status_code == 404
        assert (
            client.delete(f"/courses/a/staff/{made['id']}/token", headers=bearer(a["instructor"])).status_code
            == 204
        )
        assert client.get(f"{A}/submissions", headers=token).status_code == 401
        assert [row["token"] for row in client.get("/courses/a/staff", headers=operator).json()] == [
            True,
            True,
            False,
        ]
        renewed = client.post(f"/courses/a/staff/{made['id']}/token", headers=operator)
        assert renewed.status_code == 201 and renewed.json()["role"] == "ta"
        assert client.get(f"{A}/submissions", headers=bearer(renewed.json()["token"])).status_code == 200
        assert client.get(f"{A}/submissions", headers=token).status_code == 401


RL1_CONFIG = Path(grader_lab.__file__).parent / "editions" / "rl1.toml"


def _config(edition_file: Path, points: dict[str, float], hidden: str) -> str:
    """An edition's bundled configuration with some problems' points changed and one problem hidden."""
    text = edition_file.read_text(encoding="utf-8")
    for problem, value in points.items():
        table = f"[problems.{problem}]\n"
        start = text.index(table)
        at = text.index("points = 1.0", start)
        text = text[:at] + f"points = {value}" + text[at + len("points = 1.0") :]
    table = f"[problems.{hidden}]\n"
    return text.replace(table, table + 'visibility = "hidden"\n')


def _done(client: TestClient, path: str, headers: dict[str, str]) -> dict[str, object]:
    deadline = time.monotonic() + GRADING_WAIT_SECONDS  # bounds a hang only: the event is the status
    while True:
        view: dict[str, object] = client.get(path, headers=headers).json()
        if view["status"] in ("done", "failed") or time.monotonic() > deadline:
            return view
        time.sleep(0.05)


def test_each_assignment_grades_with_its_own_lab_edition_and_configuration(
    make_settings: SettingsFactory,
) -> None:
    settings = make_settings(grader="fake_grader:grade_as_configured", workers=1, edition="classic")
    lab = Path(grader_lab.__file__).parent
    configs = {
        "one": ("rl1", _config(lab / "editions" / "rl1.toml", {"car": 4.0}, hidden="taxi")),
        "two": ("v2024", _config(lab / "rl2" / "v2024.toml", {"value_iteration": 3.0}, hidden="frozen_lake")),
    }
    with TestClient(create_app(settings)) as client:
        operator = instructor_headers()
        client.post("/courses", json={"slug": "c", "title": "C"}, headers=operator)
        for slug, (edition, text) in configs.items():
            body = {"slug": slug, "title": slug, "edition": edition, "config": text}
            made = client.post("/courses/c/assignments", json=body, headers=operator)
            assert made.status_code == 201, made.text
            assert (made.json()["lab"], made.json()["edition"], made.json()["config"]) == (
                "opengym" if slug == "one" else "rl2", edition, text
            )  # fmt: skip
        token = bearer(
            client.post("/courses/c/students", json={"name": "ada"}, headers=operator).json()["token"]
        )
        seen = {}
        for slug in configs:
            upload = client.post(
                f"/courses/c/assignments/{slug}/submissions",
                files={"file": ("opengym.py", b"x = 1\n")},
                headers=token,
            )
            location = upload.headers["Location"]
            staff = _done(client, location, operator)
            assert staff["status"] == "done", staff
            student = client.get(location, headers=token).json()
            seen[slug] = (staff, student)
        one, two = seen["one"], seen["two"]
        problems = {
            slug: {p["id"]: p for p in staff["report"]["problems"]} for slug, (staff, _) in seen.items()
        }
        # each grading had its assignment's configuration: its edition's problems, points and visibility
        assert {p["measurements"]["edition"] for p in problems["one"].values()} == {"rl1"}
        assert {p["measurements"]["edition"] for p in problems["two"].values()} == {"v2024"}
        assert "car" in problems["one"] and "value_iteration" not in problems["one"]
        assert (problems["one"]["car"]["max_score"], problems["two"]["value_iteration"]["max_score"]) == (
            4.0,
            3.0,
        )
        assert (problems["one"]["taxi"]["visibility"], problems["two"]["frozen_lake"]["visibility"]) == (
            "hidden", "hidden"
        )  # fmt: skip
        # and the student's view withholds each assignment's own hidden problem
        for (_, student), hidden in ((one, "taxi"), (two, "frozen_lake")):
            shown = {p["id"]: p["status"] for p in student["report"]["problems"]}
            assert shown[hidden] == "withheld" and {s for p, s in shown.items() if p != hidden} == {"passed"}


@pytest.mark.parametrize(
    ("body", "expected"),
    [
        ({"edition": "rl1", "config": "not = [toml"}, "config is not TOML"),
        ({"edition": "rl1", "config": "[problems]\n"}, "config is not an assignment configuration"),
        ({"edition": "rl1", "config": "a = " + "[" * 30000}, "config nests arrays or tables too deeply"),
        (
            {"edition": "v2024", "config": RL1_CONFIG.read_text(encoding="utf-8")},
            "config grades edition 'rl1', the assignment edition 'v2024'",
        ),
    ],
    ids=["not-toml", "not-a-configuration", "too-deep", "another-edition"],
)
def test_an_assignment_configuration_is_checked_when_it_is_given(
    make_settings: SettingsFactory, body: dict[str, str], expected: str
) -> None:
    with TestClient(create_app(make_settings(), run_workers=False)) as client:
        client.post("/courses", json={"slug": "c", "title": "C"}, headers=instructor_headers())
        refused = client.post(
            "/courses/c/assignments", json={"slug": "x", "title": "X", **body}, headers=instructor_headers()
        )
        assert refused.status_code == 422 and refused.json()["detail"].startswith(expected), refused.text
        assert refused.json()["problems"][0]["location"] == ["body", "config"]
