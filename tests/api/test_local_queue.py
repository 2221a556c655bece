"""The database job queue: atomic claims, leases, retries and attempts, on SQLite and PostgreSQL."""

from __future__ import annotations

import threading
import time
from collections.abc import Iterator
from datetime import timedelta

import pytest
from api_testing import BOTH_DATABASES, SettingsFactory
from sqlalchemy.orm import Session, sessionmaker

from api.courses import DEFAULT_ASSIGNMENT_ID, DEFAULT_COURSE_ID
from api.database import make_engine, make_session_factory, migrate
from api.jobs.local import DatabaseQueue
from api.models import JobStatus, Student, Submission, utcnow
from api.settings import Settings


@pytest.fixture
def sessions(make_settings: SettingsFactory) -> Iterator[sessionmaker[Session]]:
    settings: Settings = make_settings()
    engine = make_engine(settings)
    migrate(engine)
    yield make_session_factory(engine)
    engine.dispose()


def _queue(
    sessions: sessionmaker[Session], *, lease_seconds: float = 30.0, max_attempts: int = 3
) -> DatabaseQueue:
    return DatabaseQueue(sessions, lease_seconds=lease_seconds, max_attempts=max_attempts)


def _submit(sessions: sessionmaker[Session], count: int = 1) -> list[int]:
    with sessions() as session:
        student = Student(
            course_id=DEFAULT_COURSE_ID,
            name=f"student-{time.monotonic_ns()}",
            token_sha256=f"{time.monotonic_ns():064d}",
        )
        session.add(student)
        session.flush()
        rows = [
            Submission(
                assignment_id=DEFAULT_ASSIGNMENT_ID,
                student_id=student.id,
                filename="opengym.py",
                sha256="0" * 64,
                content=b"x = 1\n",
                size=6,
                seed=7,
                status="queued",
                created_at=utcnow(),
                attempts=0,
                progress=[],
            )
            for _ in range(count)
        ]
        session.add_all(rows)
        session.commit()
        return [row.id for row in rows]


def expire_lease(sessions: sessionmaker[Session], submission_id: int) -> None:
    """The row's lease runs out: its expiry set a second in the past, as the clock would leave it (no sleep,
    so a lease long enough for a loaded machine is never taken over by accident)."""
    with sessions() as session:
        row = session.get_one(Submission, submission_id)
        assert row.lease_expires_at is not None, "expire_lease needs a claimed row"
        row.lease_expires_at = utcnow() - timedelta(seconds=1)
        session.commit()


def _row(sessions: sessionmaker[Session], submission_id: int) -> Submission:
    with sessions() as session:
        return session.get_one(Submission, submission_id)


@BOTH_DATABASES
def test_claims_oldest_first_and_each_job_once(sessions: sessionmaker[Session]) -> None:
    ids = _submit(sessions, 3)
    queue = _queue(sessions)
    claimed = [queue.claim("w1"), queue.claim("w2"), queue.claim("w3"), queue.claim("w4")]
    assert [job.submission_id if job else None for job in claimed] == [*ids, None]
    first = claimed[0]
    assert first is not None and (first.content, first.seed, first.attempt) == (b"x = 1\n", 7, 1)
    assert _row(sessions, ids[0]).lease_owner == "w1"


@BOTH_DATABASES
def test_concurrent_claims_never_hand_out_a_job_twice(sessions: sessionmaker[Session]) -> None:
    ids = _submit(sessions, 12)
    queue = _queue(sessions)
    claimed: list[int] = []
    lock = threading.Lock()

    def drain(worker: str) -> None:
        while (job := queue.claim(worker)) is not None:
            with lock:
                claimed.append(job.submission_id)

    threads = [threading.Thread(target=drain, args=(f"w{index}",)) for index in range(6)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    assert sorted(claimed) == ids


@BOTH_DATABASES
def test_an_expired_lease_is_claimed_again_and_the_old_worker_is_locked_out(
    sessions: sessionmaker[Session],
) -> None:
    (submission_id,) = _submit(sessions)
    queue = _queue(sessions)
    assert queue.claim("dead-worker") is not None
    assert queue.claim("other") is None, "a live lease must not be taken over"
    expire_lease(sessions, submission_id)
    job = queue.claim("new-worker")
    assert job is not None and job.attempt == 2
    assert not queue.renew(submission_id, "dead-worker")
    assert not queue.complete(submission_id, "dead-worker", {"score": 1.0, "max_score": 1.0, "problems": []})
    assert queue.complete(submission_id, "new-worker", {"score": 2.0, "max_score": 5.0, "problems": []})
    row = _row(sessions, submission_id)
    assert (row.status, row.score, row.max_score, row.lease_owner) == ("done", 2.0, 5.0, None)


@BOTH_DATABASES
def test_progress_is_recorded_then_replaced_by_the_report(sessions: sessionmaker[Session]) -> None:
    (submission_id,) = _submit(sessions)
    queue = _queue(sessions)
    assert queue.claim("w") is not None
    assert queue.add_progress(submission_id, "w", {"id": "cartpole", "score": 1.0})
    assert queue.add_progress(submission_id, "w", {"id": "car", "score": 0.0})
    assert [item["id"] for item in _row(sessions, submission_id).progress] == ["cartpole", "car"]
    assert not queue.add_progress(submission_id, "intruder", {"id": "taxi"})
    report = {"score": 1.0, "max_score": 2.0, "problems": [{"id": "cartpole"}, {"id": "car"}]}
    assert queue.complete(submission_id, "w", report)
    assert _row(sessions, submission_id).report == report


@pytest.mark.parametrize(
    ("max_attempts", "expected_status"),
    [(3, JobStatus.QUEUED.value), (1, JobStatus.FAILED.value)],
    ids=["retried-while-attempts-remain", "failed-when-attempts-are-used-up"],
)
def test_retry_requeues_until_the_attempts_are_used_up(
    sessions: sessionmaker[Session], max_attempts: int, expected_status: str
) -> None:
    (submission_id,) = _submit(sessions)
    queue = _queue(sessions, max_attempts=max_attempts)
    assert queue.claim("w") is not None
    assert queue.retry(submission_id, "w", "the grading process ended unexpectedly")
    row = _row(sessions, submission_id)
    assert row.status == expected_status
    assert row.error is not None and row.error.startswith("the grading process ended unexpectedly")


def test_a_job_interrupted_too_often_is_failed_with_a_reason(sessions: sessionmaker[Session]) -> None:
    (submission_id,) = _submit(sessions)
    queue = _queue(sessions, max_attempts=2)
    for worker in ("crash-1", "crash-2"):
        assert queue.claim(worker) is not None
        expire_lease(sessions, submission_id)
    assert queue.claim("w3") is None
    row = _row(sessions, submission_id)
    assert row.status == "failed"
    assert row.error == "grading was interrupted 2 times (worker crash or restart); upload again"


def test_release_requeues_without_spending_an_attempt(sessions: sessionmaker[Session]) -> None:
    (submission_id,) = _submit(sessions)
    queue = _queue(sessions, max_attempts=1)
    assert queue.claim("w") is not None
    assert queue.release(submission_id, "w")
    job = queue.claim("w2")
    assert job is not None and job.attempt == 1


@BOTH_DATABASES
def test_a_task_claims_only_the_row_it_names_and_only_while_claimable(
    sessions: sessionmaker[Session],
) -> None:
    first, second = _submit(sessions, 2)
    queue = _queue(sessions)  # a lease long enough for a loaded machine: the test is about a live one
    job = queue.claim("w1", second)
    assert job is not None and job.submission_id == second, "the named row, not the oldest"
    assert queue.claim("w2", second) is None, "a duplicated task leaves a row under a live lease alone"
    assert queue.complete(second, "w1", {"score": 1.0, "max_score": 1.0, "problems": []})
    assert queue.claim("w3", second) is None, "a finished row is never graded again"
    assert queue.state(second) == (JobStatus.DONE, 1)
    assert queue.state(first) == (JobStatus.QUEUED, 0)
