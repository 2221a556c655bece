"""The embedded default course and assignment: its row follows the settings, its jobs are graded as it says,
and its late policy's extensions are keyed by enrolment."""

from __future__ import annotations

import csv
import io
from datetime import UTC, datetime, timedelta
from pathlib import Path

import pytest
from api_testing import SettingsFactory, add_student, bearer, graded_upload, instructor_headers
from fastapi.testclient import TestClient

from api.courses import DEFAULT_ASSIGNMENT_ID, default_assignment, sync_default
from api.main import create_app
from api.models import Assignment, Extension, Student, Submission

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
