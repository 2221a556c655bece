"""Writes ``before_courses.sqlite3`` and ``before_courses.json``: a service database as gymgrade wrote it
before courses (schema 0003), made by that version's own code, and what that version answered on it.

``tests/api/test_migrations.py`` migrates a copy (on SQLite, and its rows copied into PostgreSQL) and checks
that nothing is lost. To write them again, run this file with the old version's code first on the path::

    git archive <commit of before courses> | tar -x -C /tmp/before
    PYTHONPATH=/tmp/before:/tmp/before/tests/api python3 tests/api/data/write_before_courses.py tests/api/data

Students are made over the API, uploads graded through the job queue as a worker does (the test
helpers' ``graded_upload``), overrides recorded over the API, a platform registered over the API; the LTI
learner, link, membership and score outbox are made by that version's ``api.lti`` functions.
"""

from __future__ import annotations

import json
import sqlite3
import sys
import tempfile
from pathlib import Path

from api_testing import FAKE_GRADER, INSTRUCTOR_TOKEN, add_student, bearer, graded_upload, instructor_headers
from fastapi.testclient import TestClient

from api.lti import claims as names
from api.lti.claims import Role
from api.lti.people import ensure_link, ensure_member, ensure_user
from api.lti.publisher import sync_outbox
from api.main import create_app
from api.models import Submission, utcnow
from api.settings import GradebookPolicy, Settings


def main(out: Path) -> None:
    """Write the database and what the service answered on it into ``out``."""
    with tempfile.TemporaryDirectory() as scratch:
        settings = Settings(
            data_dir=Path(scratch), instructor_token=INSTRUCTOR_TOKEN, grader=FAKE_GRADER, workers=0
        )
        answers: dict[str, object] = {}
        with TestClient(create_app(settings, run_workers=False)) as client:
            tokens = {name: add_student(client, name) for name in ("ada", "bob", "Zoë Ünicode")}
            graded_upload(client, tokens["ada"], {"random_blackjack": 1.0, "car": 0.0})
            second = graded_upload(client, tokens["ada"], {"random_blackjack": 1.0, "car": 1.0})
            graded_upload(client, tokens["bob"], {"random_blackjack": 0.0, "car": 1.0})
            client.post(
                "/submissions", files={"file": ("opengym.py", b"y = 2\n")}, headers=bearer(tokens["bob"])
            )
            for name, body in (
                ("ada", {"problem": "car", "points": 0.5, "reason": "half by hand"}),
                (
                    "ada",
                    {"problem": "total", "points": 1.5, "reason": "for this upload", "submission_id": second},
                ),
                ("bob", {"problem": "random_blackjack", "points": 1, "reason": "checked"}),
            ):
                response = client.post(f"/students/{name}/overrides", json=body, headers=instructor_headers())
                assert response.status_code == 201, response.text
            platform = client.post(
                "/lti/platforms",
                json={
                    "issuer": "https://lms.example",
                    "client_id": "tool",
                    "deployment_ids": ["d1"],
                    "jwks_url": "https://lms.example/jwks",
                    "auth_url": "https://lms.example/auth",
                    "token_url": "https://lms.example/token",
                },
                headers=instructor_headers(),
            ).json()
            client.post("/lti/keys/rotate", headers=instructor_headers())
            context = client.app.state.context  # type: ignore[attr-defined]
            with context.sessions() as session:
                from api.models import LtiPlatform

                row = session.get_one(LtiPlatform, platform["id"])
                claims = {
                    names.RESOURCE_LINK: {"id": "link-1", "title": "Lab 1"},
                    names.CONTEXT: {"id": "course-1", "title": "RL"},
                    names.AGS_ENDPOINT: {"lineitem": "https://lms.example/lineitems/1", "scope": []},
                }
                link = ensure_link(session, row, "d1", claims)
                carol = ensure_user(session, row, "sub-carol", "Carol", Role.LEARNER)
                ensure_member(session, link, carol)
                ensure_user(session, row, "sub-teacher", "Teacher", Role.STAFF)
                upload = Submission(
                    student_id=carol.student_id, filename="opengym.py", sha256="0" * 64, content=b"x = 1\n",
                    size=6, seed=5, status="queued", created_at=utcnow(), attempts=0, progress=[],
                )  # fmt: skip
                session.add(upload)
                session.commit()
                uploaded = upload.id
            job = context.jobs.claim("writer", uploaded)
            report = {
                "score": 2.0,
                "max_score": 2.0,
                "problems": [{"id": "car", "score": 2.0, "max_score": 2.0}],
            }
            context.jobs.complete(job.submission_id, "writer", report)
            with context.sessions() as session:
                sync_outbox(session, GradebookPolicy.LATEST)
            answers["tokens"] = tokens
            answers["gradebook"] = client.get("/gradebook.csv", headers=instructor_headers()).text
            answers["ada_submissions"] = client.get("/submissions", headers=bearer(tokens["ada"])).json()
            answers["ada_overrides"] = client.get(
                "/students/ada/overrides", headers=instructor_headers()
            ).json()
            answers["scores"] = client.get("/lti/scores", headers=instructor_headers()).json()
        database = Path(scratch) / "gymgrade.sqlite3"
        with sqlite3.connect(database) as connection:
            connection.execute("PRAGMA wal_checkpoint(TRUNCATE)")
            connection.execute("PRAGMA journal_mode=DELETE")
        (out / "before_courses.sqlite3").write_bytes(database.read_bytes())
    (out / "before_courses.json").write_text(
        json.dumps(answers, indent=1, ensure_ascii=False) + "\n", "utf-8"
    )


if __name__ == "__main__":
    main(Path(sys.argv[1]))
