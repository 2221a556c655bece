"""A database written before courses (schema 0003, by that version's own code: ``data/before_courses.*``)
migrates into the embedded default course and assignment with nothing lost, on SQLite and PostgreSQL: every
row and value is kept, and the service answers on it as that version did."""

from __future__ import annotations

import json
import shutil
from pathlib import Path
from typing import Any

from alembic import command
from alembic.config import Config
from api_testing import (
    BOTH_DATABASES,
    SettingsFactory,
    add_student,
    bearer,
    graded_upload,
    instructor_headers,
)
from fastapi.testclient import TestClient
from sqlalchemy import Engine, MetaData, create_engine, select, text

from api.courses import DEFAULT_ASSIGNMENT_ID, DEFAULT_COURSE_ID
from api.database import MIGRATIONS_DIR
from api.main import create_app
from api.settings import Settings

DATA = Path(__file__).with_name("data")
BEFORE = DATA / "before_courses.sqlite3"
ANSWERS: dict[str, Any] = json.loads((DATA / "before_courses.json").read_text(encoding="utf-8"))
MOVED = {("lti_users", "student_id")}
"""Columns of before courses that moved: an LTI user's student row is now its enrolment's ``lti_user_id``."""


def _rows(engine: Engine) -> dict[str, dict[Any, dict[str, Any]]]:
    """Every row of every table but alembic's, by table and primary key."""
    metadata = MetaData()
    metadata.reflect(engine)
    found: dict[str, dict[Any, dict[str, Any]]] = {}
    with engine.connect() as connection:
        for table in metadata.sorted_tables:
            if table.name == "alembic_version":
                continue
            key = [column.name for column in table.primary_key.columns]
            found[table.name] = {
                tuple(row[name] for name in key): dict(row)
                for row in connection.execute(select(table)).mappings()
            }
    return found


def _copy_to_postgres(url: str) -> None:
    """Make ``url`` what the SQLite fixture is: schema 0003 by its migrations, then every row."""
    target = create_engine(url)
    config = Config()
    config.set_main_option("script_location", str(MIGRATIONS_DIR))
    with target.begin() as connection:
        config.attributes["connection"] = connection
        command.upgrade(config, "0003")
    source = create_engine(f"sqlite:///{BEFORE}")
    rows = _rows(source)
    source.dispose()
    metadata = MetaData()
    metadata.reflect(target)
    with target.begin() as connection:
        for table in metadata.sorted_tables:
            if rows.get(table.name):
                connection.execute(table.insert(), list(rows[table.name].values()))
                if "id" in table.columns:
                    sequence = f"pg_get_serial_sequence('{table.name}', 'id')"
                    connection.execute(text(f"SELECT setval({sequence}, (SELECT max(id) FROM {table.name}))"))
    target.dispose()


def _database_of_before(settings: Settings) -> None:
    if settings.database_url:
        _copy_to_postgres(settings.database_url)
        return
    settings.data_dir.mkdir(parents=True, exist_ok=True)
    shutil.copyfile(BEFORE, settings.data_dir / "gymgrade.sqlite3")


@BOTH_DATABASES
def test_a_database_of_before_courses_keeps_every_row_in_the_default_course(
    make_settings: SettingsFactory,
) -> None:
    settings = make_settings()
    _database_of_before(settings)
    source = create_engine(f"sqlite:///{BEFORE}")
    before = _rows(source)
    source.dispose()
    with TestClient(create_app(settings, run_workers=False)):
        pass  # started: migrated, and the default assignment brought to the settings
    engine = create_engine(settings.sqlalchemy_url)
    after = _rows(engine)
    engine.dispose()
    for table, rows in before.items():
        assert set(after[table]) == set(rows), f"{table}: rows lost or added"
        for key, row in rows.items():
            kept = {name: value for name, value in row.items() if (table, name) not in MOVED}
            assert {name: after[table][key][name] for name in kept} == kept, f"{table} {key}"
    assert {row["course_id"] for row in after["students"].values()} == {DEFAULT_COURSE_ID}
    for table in ("submissions", "overrides", "lti_links"):
        assert {row["assignment_id"] for row in after[table].values()} == {DEFAULT_ASSIGNMENT_ID}, table
    learners = {row["student_id"]: id_ for (id_,), row in before["lti_users"].items() if row["student_id"]}
    assert learners, "the fixture has an LTI learner"
    assert {
        key[0]: row["lti_user_id"] for key, row in after["students"].items() if row["lti_user_id"]
    } == learners
    assert [(row["slug"], row["course_id"]) for row in after["assignments"].values()] == [
        ("default", DEFAULT_COURSE_ID)
    ]


def _sent(score: dict[str, object]) -> dict[str, object]:
    """A score row as migrated: whose, for which link and submission, and what it says."""
    return {key: score[key] for key in ("student", "link_id", "submission_id", "score", "max_score")}


@BOTH_DATABASES
def test_the_service_answers_on_a_migrated_database_as_before(make_settings: SettingsFactory) -> None:
    # no publishing round meanwhile: a round would try to send the fixture's pending score (to a platform
    # that does not exist) and change the outbox the test compares (it did, under load, past 2 s)
    settings = make_settings(lti_publish_seconds=3600.0)
    _database_of_before(settings)
    tokens = ANSWERS["tokens"]
    with TestClient(create_app(settings, run_workers=False)) as client:
        assert client.get("/gradebook.csv", headers=instructor_headers()).text == ANSWERS["gradebook"]
        assert client.get("/submissions", headers=bearer(tokens["ada"])).json() == ANSWERS["ada_submissions"]
        overrides = client.get("/students/ada/overrides", headers=instructor_headers()).json()
        # the same, with one field added since (the enrolment's id, what overrides are keyed by)
        assert [{k: v for k, v in row.items() if k != "enrolment"} for row in overrides] == ANSWERS[
            "ada_overrides"
        ]
        enrolments = client.get("/students", headers=instructor_headers()).json()
        assert {row["enrolment"] for row in overrides} == {
            row["id"] for row in enrolments if row["name"] == "ada"
        }
        # the service's publisher may already be trying the fixture's unreachable LMS: what it sends is kept,
        # how far it got (status, attempts, error) is its own
        assert [_sent(score) for score in client.get("/lti/scores", headers=instructor_headers()).json()] == [
            _sent(score) for score in ANSWERS["scores"]
        ]
        # and it goes on: a job queued before is graded as the default assignment's, an old token uploads,
        # a taken name is still taken, a new student is made
        jobs = client.app.state.context.jobs  # type: ignore[attr-defined]
        queued = jobs.claim("after")
        assert (queued.submission_id, queued.content, queued.assignment) == (4, b"y = 2\n", (None, None))
        assert jobs.complete(4, "after", {"score": 0.0, "max_score": 2.0, "problems": []})
        later = graded_upload(client, tokens["Zoë Ünicode"], {"random_blackjack": 1.0, "car": 1.0})
        assert later > max(item["id"] for item in ANSWERS["ada_submissions"])
        assert client.post("/students", json={"name": "ada"}, headers=instructor_headers()).status_code == 409
        add_student(client, "dan")
        rows = client.get("/gradebook.csv", headers=instructor_headers()).text.splitlines()
        assert [row.split(",")[0] for row in rows[1:]] == ["Carol", "Zoë Ünicode", "ada", "bob", "dan"]
