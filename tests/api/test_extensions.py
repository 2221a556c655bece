"""Extensions, overrides and regrades over the API, keyed by enrolment: granted by the course's staff,
followed by the gradebook, refused on another course's enrolment or an assignment without a late policy."""

from __future__ import annotations

import csv
import io

import pytest
from api_testing import SettingsFactory, bearer, instructor_headers
from fastapi.testclient import TestClient

from api.main import create_app
from api.models import Student

pytestmark = pytest.mark.slow  # each starts the service on a fresh database (about a second)

A = "/courses/a/assignments/late"
LATE = {"due": "2020-01-01T00:00:00Z", "penalty_per_day": 0.25}


def _graded(client: TestClient, prefix: str, token: str) -> int:
    upload = client.post(f"{prefix}/submissions", files={"file": ("opengym.py", b"x = 1\n")}, headers=token)
    assert upload.status_code == 202, upload.text
    jobs = client.app.state.context.jobs  # type: ignore[attr-defined]
    submission_id: int = upload.json()["id"]
    assert jobs.claim("w", submission_id) is not None
    report = {
        "score": 2.0,
        "max_score": 2.0,
        "problems": [{"id": p, "score": 1.0, "max_score": 1.0} for p in "xy"],
    }
    assert jobs.complete(submission_id, "w", report)
    return submission_id


def _course(client: TestClient, slug: str) -> tuple[dict[str, str], dict[str, int]]:
    """Course ``slug`` with assignments ``late`` (a late policy, due in 2020) and ``open`` (none), a TA, and
    students ada and bob who uploaded to ``late`` (years late): the tokens, and the enrolments' ids."""
    operator = instructor_headers()
    assert client.post("/courses", json={"slug": slug, "title": slug}, headers=operator).status_code == 201
    ta = client.post(f"/courses/{slug}/staff", json={"name": "Tim", "role": "ta"}, headers=operator).json()
    for assignment in ({"slug": "late", "title": "Late", "late": LATE}, {"slug": "open", "title": "Open"}):
        assert (
            client.post(f"/courses/{slug}/assignments", json=assignment, headers=operator).status_code == 201
        )
    tokens, ids = {"ta": ta["token"]}, {}
    for name in ("ada", "bob"):
        made = client.post(f"/courses/{slug}/students", json={"name": name}, headers=operator).json()
        tokens[name], ids[name] = made["token"], made["id"]
        _graded(client, f"/courses/{slug}/assignments/late", bearer(made["token"]))
    return tokens, ids


def _scores(client: TestClient, prefix: str, headers: dict[str, str]) -> dict[str, tuple[str, str]]:
    text = client.get(f"{prefix}/gradebook.csv", headers=headers).text
    return {row["student"]: (row["late_penalty"], row["score"]) for row in csv.DictReader(io.StringIO(text))}


def test_an_extension_is_granted_to_an_enrolment_and_the_gradebook_follows(
    make_settings: SettingsFactory,
) -> None:
    with TestClient(create_app(make_settings(), run_workers=False)) as client:
        tokens, ids = _course(client, "a")
        ta = bearer(tokens["ta"])
        assert _scores(client, A, ta) == {"ada": ("2", "0"), "bob": ("2", "0")}
        listed = client.get("/courses/a/students", headers=ta).json()
        assert [(row["id"], row["name"], row["lti"]) for row in listed] == [
            (ids["ada"], "ada", False), (ids["bob"], "bob", False)
        ]  # fmt: skip
        granted = client.put(
            f"{A}/enrolments/{ids['bob']}/extension",
            json={"due": "2999-01-01T00:00:00Z", "reason": "ill"},
            headers=ta,
        )
        assert granted.status_code == 200, granted.text
        assert (granted.json()["enrolment"], granted.json()["student"], granted.json()["author"]) == (
            ids["bob"], "bob", "Tim"
        )  # fmt: skip
        with client.app.state.context.sessions() as session:  # type: ignore[attr-defined]
            session.get_one(Student, ids["bob"]).name = "robert"  # renamed: the extension stays his
            session.commit()
        assert _scores(client, A, ta) == {"ada": ("2", "0"), "robert": ("0", "2")}
        again = client.put(
            f"{A}/enrolments/{ids['bob']}/extension",
            json={"due": "2020-01-02T00:00:00Z", "reason": "a day"},
            headers=ta,
        )
        assert again.status_code == 200
        shown = client.get(f"{A}/extensions", headers=ta).json()
        assert [(row["enrolment"], row["due"], row["reason"]) for row in shown] == [
            (ids["bob"], "2020-01-02T00:00:00Z", "a day")
        ]  # one per enrolment: granted again, replaced
        assert client.delete(f"{A}/enrolments/{ids['bob']}/extension", headers=ta).status_code == 204
        assert client.delete(f"{A}/enrolments/{ids['bob']}/extension", headers=ta).status_code == 204
        assert client.get(f"{A}/extensions", headers=ta).json() == []
        assert _scores(client, A, ta) == {"ada": ("2", "0"), "robert": ("2", "0")}


def test_an_extension_or_override_reaches_only_an_enrolment_of_the_course(
    make_settings: SettingsFactory,
) -> None:
    with TestClient(create_app(make_settings(), run_workers=False)) as client:
        tokens, ids = _course(client, "a")
        other, theirs = _course(client, "b")
        ta = bearer(tokens["ta"])
        body = {"due": "2999-01-01T00:00:00Z", "reason": "ill"}
        for enrolment in (theirs["ada"], 0, 2**40):  # another course's, and ids nobody has
            refused = client.put(f"{A}/enrolments/{enrolment}/extension", json=body, headers=ta)
            assert refused.status_code == 404 and "no enrolment" in refused.json()["detail"], refused.text
            override = {"problem": "x", "points": 0, "reason": "copied"}
            assert (
                client.post(f"{A}/enrolments/{enrolment}/overrides", json=override, headers=ta).status_code
                == 404
            )
        # the other course's staff do not find this course at all; a student may not grant
        assert (
            client.put(
                f"{A}/enrolments/{ids['ada']}/extension", json=body, headers=bearer(other["ta"])
            ).status_code
            == 404
        )
        assert (
            client.put(
                f"{A}/enrolments/{ids['ada']}/extension", json=body, headers=bearer(tokens["ada"])
            ).status_code
            == 403
        )
        no_policy = client.put(
            f"/courses/a/assignments/open/enrolments/{ids['ada']}/extension", json=body, headers=ta
        )
        assert no_policy.status_code == 409
        assert no_policy.json()["detail"].startswith("assignment 'open' has no late policy")
        assert _scores(client, "/courses/b/assignments/late", bearer(other["ta"])) == {
            "ada": ("2", "0"), "bob": ("2", "0")
        }  # fmt: skip


def test_an_override_is_made_and_listed_by_enrolment(make_settings: SettingsFactory) -> None:
    with TestClient(create_app(make_settings(), run_workers=False)) as client:
        tokens, ids = _course(client, "a")
        ta = bearer(tokens["ta"])
        made = client.post(
            f"{A}/enrolments/{ids['ada']}/overrides",
            json={"problem": "total", "points": 1.5, "reason": "oral exam"},
            headers=ta,
        )
        assert made.status_code == 201, made.text
        assert (made.json()["enrolment"], made.json()["student"]) == (ids["ada"], "ada")
        by_name = client.get(f"{A}/students/ada/overrides", headers=ta).json()
        by_id = client.get(f"{A}/enrolments/{ids['ada']}/overrides", headers=ta).json()
        assert by_name == by_id and [row["points"] for row in by_id] == [1.5]
        assert client.get(f"{A}/enrolments/{ids['bob']}/overrides", headers=ta).json() == []
        ada_uploads = [row["id"] for row in client.get(f"{A}/submissions?student=ada", headers=ta).json()]
        regraded = client.post(f"{A}/enrolments/{ids['ada']}/regrade", headers=ta)
        assert (regraded.status_code, [row["id"] for row in regraded.json()]) == (202, ada_uploads)
        assert client.post(f"{A}/enrolments/{ids['ada']}/regrade", headers=ta).status_code == 409  # queued
        assert client.post(f"{A}/enrolments/{2**40}/regrade", headers=ta).status_code == 404
