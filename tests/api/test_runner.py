"""Grading one claimed job in a child process: progress, report, grader failures, crashes, shutdown."""

from __future__ import annotations

import threading
from collections.abc import Iterator
from pathlib import Path

import pytest
from api_testing import SettingsFactory
from fake_grader import held
from sqlalchemy import select
from sqlalchemy.orm import Session, sessionmaker

from api.courses import DEFAULT_ASSIGNMENT_ID, DEFAULT_COURSE_ID, sync_default
from api.database import make_engine, make_session_factory, migrate
from api.jobs.local import DatabaseQueue
from api.jobs.runner import run_job
from api.models import Student, Submission, utcnow
from api.settings import Settings

pytestmark = pytest.mark.slow  # grades claimed jobs in child processes

SOLUTION = b"def random_blackjack(n):\n    return 0.3\n\ndef blackjack(n=11):\n    return 0.4\n"


@pytest.fixture
def settings(make_settings: SettingsFactory) -> Settings:
    return make_settings(max_attempts=2)


@pytest.fixture
def sessions(settings: Settings) -> Iterator[sessionmaker[Session]]:
    engine = make_engine(settings)
    migrate(engine)
    yield make_session_factory(engine)
    engine.dispose()


def _grade(
    sessions: sessionmaker[Session],
    settings: Settings,
    content: bytes,
    *,
    filename: str = "opengym.py",
    stop: bool = False,
) -> Submission:
    with sessions() as session:
        sync_default(session, settings)  # as a service start does: the default follows the settings
        student = session.scalars(select(Student)).first()
        if student is None:
            student = Student(course_id=DEFAULT_COURSE_ID, name="ada", token_sha256="a" * 64)
            session.add(student)
            session.flush()
        row = Submission(
            assignment_id=DEFAULT_ASSIGNMENT_ID,
            student_id=student.id,
            filename=filename,
            sha256="0" * 64,
            content=content,
            size=len(content),
            seed=11,
            status="queued",
            created_at=utcnow(),
            attempts=0,
            progress=[],
        )
        session.add(row)
        session.commit()
        submission_id = row.id
    queue = DatabaseQueue(sessions, lease_seconds=settings.lease_seconds, max_attempts=settings.max_attempts)
    job = queue.claim("worker")
    assert job is not None
    stop_event = threading.Event()
    if stop:
        stop_event.set()
    run_job(job, queue, "worker", settings, stop_event)
    with sessions() as session:
        return session.get_one(Submission, submission_id)


def test_a_graded_job_stores_the_report_with_its_seed(
    sessions: sessionmaker[Session], settings: Settings
) -> None:
    row = _grade(sessions, settings, SOLUTION)
    assert row.status == "done", row.error
    assert row.report is not None
    assert (row.score, row.max_score, row.report["seed"]) == (2.0, 3.0, 11)
    assert [problem["status"] for problem in row.progress] == ["passed", "passed", "missing"]


@pytest.mark.parametrize(
    ("overrides", "policy", "workers"),
    [({}, "require_full", None), ({"allow_weak_isolation": True, "grading_workers": 2}, "allow_fallback", 2)],
    ids=["strict-by-default", "weak-isolation-allowed"],
)
def test_the_grader_gets_the_isolation_policy_and_workers_of_the_settings(
    sessions: sessionmaker[Session],
    make_settings: SettingsFactory,
    overrides: dict[str, object],
    policy: str,
    workers: int | None,
) -> None:
    row = _grade(sessions, make_settings(**overrides), SOLUTION)
    assert row.report is not None
    assert row.report["problems"][0]["measurements"] == {"policy": policy, "workers": workers}


@pytest.mark.parametrize(
    "filename",
    ["opengym.py", "my lab (2).py", "policy_iteration-1.py"],
    ids=["module-name", "space", "hyphen"],
)
def test_a_syntax_error_is_a_stored_verdict_naming_the_upload(
    sessions: sessionmaker[Session], settings: Settings, filename: str
) -> None:
    """An upload whose name is no module name is graded as submission.py, and still named as uploaded."""
    row = _grade(sessions, settings, b"def broken(:\n", filename=filename)
    assert row.status == "done"
    assert row.report is not None and row.report["submission"] == filename
    assert row.report["submission_error"].startswith(f"{filename} is not valid Python")


@pytest.mark.parametrize(
    ("content", "status", "error"),
    [
        (
            b"# fake-grader: fail\n",
            "failed",
            "the grader failed: RuntimeError: the fake grader was told to fail",
        ),
        (b"# fake-grader: crash\n", "queued", "the grading process ended unexpectedly (exit status 3)"),
        (
            b"# fake-grader: internal-error\n",
            "failed",
            "the grader failed on this submission (not the student's fault): "
            "cartpole: the fake grader crashed",
        ),
    ],
    ids=["grader-raises", "grading-process-crashes", "grader-reports-its-own-failure"],
)
def test_grader_failures_are_stored_not_raised(
    sessions: sessionmaker[Session], settings: Settings, content: bytes, status: str, error: str
) -> None:
    row = _grade(sessions, settings, content)
    assert (row.status, row.error) == (status, error)


def test_an_unknown_grader_fails_the_job_with_the_setting_named(
    sessions: sessionmaker[Session], make_settings: SettingsFactory
) -> None:
    settings = make_settings(grader="no_such_module:grade")
    row = _grade(sessions, settings, SOLUTION)
    assert row.status == "failed"
    assert row.error is not None and row.error.startswith("GYMGRADE_GRADER names module 'no_such_module'")


def test_a_stopping_worker_puts_its_job_back(
    sessions: sessionmaker[Session], settings: Settings, tmp_path: Path
) -> None:
    # Held on a file never made: the grading cannot end by itself, only the stop ends it (no clock races it).
    row = _grade(sessions, settings, held(tmp_path / "never") + SOLUTION, stop=True)
    assert (row.status, row.attempts, row.lease_owner) == ("queued", 0, None)


def test_a_submission_named_like_a_module_cannot_shadow_the_grading_process(
    sessions: sessionmaker[Session], settings: Settings
) -> None:
    hostile = b"raise SystemExit('imported outside the sandbox')\n"
    for name in ("json.py", "fake_grader.py", "api.py"):
        row = _grade(sessions, settings, hostile, filename=name)
        assert row.status == "done", (name, row.error)
        assert row.report is not None and row.report["submission"] == name


RL1_EPSILON_ONLY = b'''"""An rl1 (Reinforcement Learning 1) submission with only epsilon_decay written."""


def epsilon_decay(episode, N, epsilon_start=1.0, epsilon_end=1e-6):
    delta = (epsilon_start - epsilon_end) / N
    return epsilon_start - (episode - 1) * delta


def taxi(q_table, q_table_decay):
    raise NotImplementedError
'''


CLASSIC_TAXI_ONLY = b'''"""Last year\'s classic solution, handed in to a course of today\'s edition."""
import gym


def taxi(q_table):
    raise NotImplementedError
'''


@pytest.mark.parametrize(
    ("edition", "upload", "graded", "expected", "told"),
    [
        (None, RL1_EPSILON_ONLY, "classic", {"taxi": "missing", "cartpole": "missing"}, "edition 4 (rl1"),
        (
            "rl1",
            CLASSIC_TAXI_ONLY,
            "rl1",
            {"epsilon_decay": "missing", "cartpole": "missing"},
            "edition 1 (classic",
        ),
        ("rl1", RL1_EPSILON_ONLY, "rl1", {"epsilon_decay": "passed", "taxi": "missing"}, None),
        (
            "classic",
            RL1_EPSILON_ONLY,
            "classic",
            {"taxi": "missing", "cartpole": "missing"},
            "edition 4 (rl1",
        ),
    ],
    ids=[
        "unset-is-the-first-edition",
        "a-classic-file-in-an-rl1-course",
        "rl1-in-rl1",
        "named-by-the-service",
    ],
)
def test_the_real_grader_grades_the_services_edition_never_the_uploads(
    sessions: sessionmaker[Session],
    make_settings: SettingsFactory,
    edition: str | None,
    upload: bytes,
    graded: str,
    expected: dict[str, str],
    told: str | None,
) -> None:
    # Hostile: a file written for another edition does not choose what it is graded on; it is told so.
    real = {
        "grader": "grader.grading.grade:grade_submission",
        "allow_weak_isolation": True,
        "grading_workers": 1,
    }
    settings = make_settings(**real, edition=edition)
    row = _grade(sessions, settings, upload, filename="gymnasium.py")
    assert row.status == "done", row.error
    assert row.report is not None and row.report["edition"] == graded
    statuses = {problem["id"]: problem["status"] for problem in row.report["problems"]}
    assert {problem: statuses.get(problem) for problem in expected} == expected
    assert ("epsilon_decay" in statuses) == (graded == "rl1")
    note = row.report["edition_note"]
    assert (note is None) if told is None else (f"This file looks written for {told}" in note), note


RL2_HONEST = (Path(__file__).resolve().parents[2] / "submissions" / "rl2" / "honest_v2024.py").read_bytes()


@pytest.mark.parametrize(
    ("lab", "upload", "filename", "graded", "missing", "told"),
    [
        (None, RL2_HONEST, "policy_iteration.py", ("opengym", "classic"), "random_blackjack", "the lab rl2"),
        ("rl2", CLASSIC_TAXI_ONLY, "opengym.py", ("rl2", "v2026"), "value_iteration", "the lab opengym"),
    ],
    ids=["a-second-lab-upload-while-GYMGRADE_LAB-is-unset", "a-first-lab-upload-to-a-second-lab-service"],
)
def test_the_real_grader_grades_the_services_lab_never_the_uploads(
    sessions: sessionmaker[Session],
    make_settings: SettingsFactory,
    lab: str | None,
    upload: bytes,
    filename: str,
    graded: tuple[str, str],
    missing: str,
    told: str,
) -> None:
    # Hostile: an upload that looks written for another lab does not choose its lab; it is told so.
    real = {
        "grader": "grader.grading.grade:grade_submission",
        "allow_weak_isolation": True,
        "grading_workers": 1,
    }
    settings = make_settings(**real, lab=lab)
    row = _grade(sessions, settings, upload, filename=filename)
    assert row.status == "done", row.error
    assert row.report is not None and (row.report["lab"], row.report["edition"]) == graded
    statuses = {problem["id"]: problem["status"] for problem in row.report["problems"]}
    assert statuses[missing] == "missing"
    note = row.report["edition_note"]
    assert note is not None and f"This file looks written for {told}" in note, note


def test_the_grading_childs_group_is_killed_only_while_its_pid_is_its_own(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Once reaped, the child's pid (its group's id) may be another process's group: never signalled."""
    import subprocess

    from api.jobs import runner
    from grader.sandbox import signalling

    sent: list[int] = []
    monkeypatch.setattr(signalling.os, "killpg", lambda pgid, _sig: sent.append(pgid))
    reaped = subprocess.Popen(["true"], start_new_session=True, text=True)
    reaped.wait()
    runner._kill_group(reaped)
    live = subprocess.Popen(["sleep", "60"], start_new_session=True, text=True)
    monkeypatch.undo()
    runner._kill_group(live)
    assert sent == []
    assert live.returncode == -9
