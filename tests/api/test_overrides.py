"""The instructor's overrides in the service: kept with who and when, checked as the CLI checks a file's rows,
applied by every gradebook format with the machine's verdict and the reason, per student or per upload; a
student's token is refused, and so is an override through the page by a student."""

from __future__ import annotations

import csv
import io

import pytest
from api_testing import (
    BOTH_DATABASES,
    SettingsFactory,
    add_student,
    bearer,
    graded_upload,
    instructor_headers,
)
from fastapi.testclient import TestClient

from api.main import create_app
from api.models import Override


def _rows(client: TestClient, gradebook_format: str = "gymgrade") -> dict[str, dict[str, str]]:
    response = client.get(f"/gradebook.csv?format={gradebook_format}", headers=instructor_headers())
    assert response.status_code == 200, response.text
    rows = list(csv.DictReader(io.StringIO(response.text)))
    return {row.get("student") or row.get("SID") or row["github_username"]: row for row in rows}


def _override(client: TestClient, name: str, headers: dict[str, str] | None = None, **body: object):  # type: ignore[no-untyped-def]
    return client.post(f"/students/{name}/overrides", json=body, headers=headers or instructor_headers())


@BOTH_DATABASES
def test_an_override_is_kept_with_who_and_when_and_every_gradebook_shows_it(
    make_settings: SettingsFactory,
) -> None:
    with TestClient(create_app(make_settings(), run_workers=False)) as client:
        ada = add_student(client, "ada")
        graded_upload(client, ada, {"random_blackjack": 1.0, "car": 0.0})
        response = _override(client, "ada", problem="car", points=1, reason='=HYPERLINK("x") checked by hand')
        assert response.status_code == 201, response.text
        kept = response.json()
        assert (kept["author"], kept["problem"], kept["points"], kept["submission_id"]) == (
            "instructor",
            "car",
            1.0,
            None,
        )
        assert kept["created_at"].endswith("Z") or "+00:00" in kept["created_at"]
        gymgrade = _rows(client)["ada"]
        assert (gymgrade["car"], gymgrade["score"]) == ("1", "2")
        assert gymgrade["note"] == 'car overridden to 1 (machine: 0): =HYPERLINK("x") checked by hand'
        assert _rows(client, "gradescope")["ada"]["Total Score"] == "2"
        assert _rows(client, "github-classroom")["ada"]["points_awarded"] == "2"
        listed = client.get("/students/ada/overrides", headers=instructor_headers()).json()
        assert [item["id"] for item in listed] == [kept["id"]]


def test_a_students_token_is_refused_and_nothing_is_kept(make_settings: SettingsFactory) -> None:
    with TestClient(create_app(make_settings(), run_workers=False)) as client:
        ada = add_student(client, "ada")
        graded_upload(client, ada, {"random_blackjack": 0.0})
        response = _override(client, "ada", bearer(ada), problem="random_blackjack", points=1, reason="mine")
        assert response.status_code == 403
        assert client.get("/students/ada/overrides", headers=bearer(ada)).status_code == 403
        client.cookies.set("gymgrade_token", ada)
        form = {"student": "ada", "problem": "random_blackjack", "points": "1", "reason": "x"}
        page = client.post("/ui/overrides", data=form)
        assert page.status_code == 403
        with client.app.state.context.sessions() as session:  # type: ignore[attr-defined]
            assert session.query(Override).count() == 0
        assert _rows(client)["ada"]["score"] == "0"


@pytest.mark.parametrize(
    ("body", "status", "detail"),
    [
        ({"problem": "cartpol", "points": 1, "reason": "x"}, 422, "refused: unknown problem 'cartpol': expected one of random_blackjack, car, total"),  # noqa: E501
        ({"problem": "car", "points": 1.5, "reason": "x"}, 422, "refused: 1.5 points for car of 'ada' is outside 0..1: car is worth 1"),  # noqa: E501
        ({"problem": "total", "points": 3, "reason": "x"}, 422, "refused: 3 points for total of 'ada' is outside 0..2: total is worth 2"),  # noqa: E501
        ({"problem": "car", "points": 1, "reason": "   "}, 422, "an override needs a reason: say why"),
        ({"problem": "car", "points": 1, "reason": "x", "submission_id": 999}, 404, "no graded submission 999 of ada; list theirs with GET /submissions?student=..."),  # noqa: E501
    ],
    ids=["unknown-problem", "over-max", "total-over-max", "blank-reason", "not-their-upload"],
)  # fmt: skip
def test_a_wrong_override_is_refused_saying_what_was_expected(
    make_settings: SettingsFactory, body: dict[str, object], status: int, detail: str
) -> None:
    with TestClient(create_app(make_settings(), run_workers=False)) as client:
        ada = add_student(client, "ada")
        graded_upload(client, ada, {"random_blackjack": 1.0, "car": 0.0})
        response = _override(client, "ada", **body)
        assert (response.status_code, response.json()["detail"]) == (status, detail)
        assert _override(client, "nobody", problem="car", points=1, reason="x").status_code == 404


def test_an_uploads_override_counts_only_while_that_upload_is_shown(make_settings: SettingsFactory) -> None:
    with TestClient(create_app(make_settings(), run_workers=False)) as client:
        ada = add_student(client, "ada")
        first = graded_upload(client, ada, {"random_blackjack": 0.0})
        assert (
            _override(
                client,
                "ada",
                problem="random_blackjack",
                points=1,
                reason="regrade request",
                submission_id=first,
            ).status_code
            == 201
        )
        assert _rows(client)["ada"]["score"] == "1"
        graded_upload(client, ada, {"random_blackjack": 0.0})
        assert _rows(client)["ada"]["score"] == "0", (
            "a later upload is shown: the first one's override no longer counts"
        )
        assert (
            _override(client, "ada", problem="total", points=0.5, reason="late-day waiver").status_code == 201
        )
        assert _rows(client)["ada"]["score"] == "0.5"


def test_the_instructors_page_overrides_and_says_why_it_refuses(make_settings: SettingsFactory) -> None:
    with TestClient(create_app(make_settings(), run_workers=False)) as client:
        ada = add_student(client, "ada")
        graded_upload(client, ada, {"random_blackjack": 0.0})
        client.cookies.set("gymgrade_token", instructor_headers()["Authorization"].removeprefix("Bearer "))
        form = {"student": "ada", "problem": "random_blackjack", "points": "1", "reason": "<b>by hand</b>"}
        page = client.post("/ui/overrides", data=form)
        assert (
            page.status_code == 200
            and "random_blackjack of ada set to 1: &lt;b&gt;by hand&lt;/b&gt;" in page.text
        )
        refused = client.post("/ui/overrides", data={**form, "points": "7"})
        assert refused.status_code == 422 and "is outside 0..1" in refused.text
        assert _rows(client)["ada"]["score"] == "1"


def test_the_late_policy_takes_penalties_by_upload_time(make_settings: SettingsFactory, tmp_path) -> None:  # type: ignore[no-untyped-def]
    from datetime import UTC, datetime, timedelta

    from api.models import Submission

    policy = tmp_path / "late.toml"
    due = datetime(2026, 3, 1, 23, 59, tzinfo=UTC)
    policy.write_text(
        f'[late]\ndue = {due.isoformat()}\npenalty_per_day = 0.25\n[late.extensions]\nbob = "{(due + timedelta(days=3)).isoformat()}"\n',  # noqa: E501
        encoding="utf-8",
    )
    with TestClient(create_app(make_settings(late_policy=policy), run_workers=False)) as client:
        ada, bob = add_student(client, "ada"), add_student(client, "bob")
        uploads = {
            name: graded_upload(client, token, {"random_blackjack": 1.0, "car": 1.0})
            for name, token in (("ada", ada), ("bob", bob))
        }
        with client.app.state.context.sessions() as session:  # type: ignore[attr-defined]
            for upload in uploads.values():  # both uploaded 1 day and 1 second after the class's due time
                session.get(Submission, upload).created_at = (due + timedelta(days=1, seconds=1)).replace(
                    tzinfo=None
                )
            session.commit()
        rows = _rows(client)
        assert {name: (row["late_penalty"], row["score"]) for name, row in rows.items()} == {
            "ada": ("1", "1"),
            "bob": ("0", "2"),
        }
        assert rows["ada"]["note"] == (
            "2 days late (submitted 2026-03-02T23:59:01+00:00, due 2026-03-01T23:59:00+00:00): 1 points taken"
        )
        assert _rows(client, "gradescope")["ada"]["Total Score"] == "1"


def test_a_late_policy_without_a_late_table_stops_the_service(
    make_settings: SettingsFactory, tmp_path
) -> None:  # type: ignore[no-untyped-def]
    from pydantic import ValidationError

    empty = tmp_path / "empty.toml"
    empty.write_text("edition = 'classic'\n", encoding="utf-8")
    with pytest.raises(ValidationError, match=r"has no \[late\] table: add one"):
        make_settings(late_policy=empty)


def test_the_student_sees_the_reason_on_their_submission_but_nothing_withheld(
    make_settings: SettingsFactory,
) -> None:
    with TestClient(create_app(make_settings(), run_workers=False)) as client:
        ada = add_student(client, "ada")
        upload = graded_upload(client, ada, {"random_blackjack": 0.0, "car": 0.0})
        with client.app.state.context.sessions() as session:  # type: ignore[attr-defined]
            from api.models import Submission

            row = session.get(Submission, upload)
            report = dict(row.report)
            report["problems"] = [
                {**p, "visibility": "hidden" if p["id"] == "car" else "visible"} for p in report["problems"]
            ]
            row.report = report
            session.commit()
        for problem, reason in (("random_blackjack", "<i>checked by hand</i>"), ("car", "secret")):
            assert _override(client, "ada", problem=problem, points=1, reason=reason).status_code == 201
        assert _override(client, "ada", problem="total", points=2, reason="whole").status_code == 201
        mine = client.get(f"/submissions/{upload}", headers=bearer(ada)).json()["overrides"]
        assert [(item["problem"], item["reason"]) for item in mine] == [
            ("random_blackjack", "<i>checked by hand</i>")
        ]
        everything = client.get(f"/submissions/{upload}", headers=instructor_headers()).json()["overrides"]
        assert [item["problem"] for item in everything] == ["random_blackjack", "car", "total"]
        client.cookies.set("gymgrade_token", ada)
        page = client.get(f"/ui/submissions/{upload}").text
        assert "&lt;i&gt;checked by hand&lt;/i&gt;" in page and "secret" not in page


def test_an_override_of_a_student_with_nothing_graded_waits(make_settings: SettingsFactory) -> None:
    # A schema-valid request the state refuses: 409, not 422 (schemathesis holds the difference).
    with TestClient(create_app(make_settings(), run_workers=False)) as client:
        add_student(client, "ada")
        response = _override(client, "ada", problem="car", points=0, reason="checked by hand")
        assert response.status_code == 409, response.text
        assert response.json()["detail"] == (
            "ada has no graded submission yet: an override needs one to know what each problem is worth; "
            "override once one is graded"
        )
        with client.app.state.context.sessions() as session:  # type: ignore[attr-defined]
            assert session.query(Override).count() == 0
