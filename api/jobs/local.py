"""The local job queue: workers poll the database, whose rows are the jobs (SQLite or PostgreSQL)."""

from __future__ import annotations

from datetime import datetime, timedelta
from typing import Any

from sqlalchemy import ColumnElement, and_, or_, select, update
from sqlalchemy.orm import Session, sessionmaker

from api.jobs.job_queue import ClaimedJob
from api.models import Assignment, JobStatus, Submission, utcnow

_CLAIM_TRIES = 10


class DatabaseQueue:
    """A :class:`~api.jobs.job_queue.JobQueue` whose claims are conditional UPDATEs on the submission rows.

    Args:
        session_factory: Makes sessions on the service's database.
        lease_seconds: How long a claim or renewal holds a job.
        max_attempts: Claims of one job before it is failed instead of retried.
    """

    def __init__(
        self, session_factory: sessionmaker[Session], *, lease_seconds: float, max_attempts: int
    ) -> None:
        self._sessions = session_factory
        self._lease = timedelta(seconds=lease_seconds)
        self._max_attempts = max_attempts

    def claim(self, worker_id: str, submission_id: int | None = None) -> ClaimedJob | None:
        """Take the oldest claimable job, or job ``submission_id``; see :meth:`JobQueue.claim`."""
        with self._sessions() as session:
            for _ in range(_CLAIM_TRIES):
                now = utcnow()
                query = select(Submission.id, Submission.attempts).where(_claimable(now))
                if submission_id is not None:
                    query = query.where(Submission.id == submission_id)
                candidate = session.execute(query.order_by(Submission.id).limit(1)).first()
                if candidate is None:
                    return None
                candidate_id, attempts = candidate
                if attempts >= self._max_attempts:
                    self._give_up(session, candidate_id, attempts, now)
                    continue
                claimed = session.execute(
                    update(Submission)
                    .where(Submission.id == candidate_id, Submission.attempts == attempts, _claimable(now))
                    .values(
                        status=JobStatus.RUNNING.value,
                        lease_owner=worker_id,
                        lease_expires_at=now + self._lease,
                        attempts=attempts + 1,
                        started_at=now,
                        progress=[],
                    )
                )
                session.commit()
                if claimed.rowcount == 1:  # type: ignore[attr-defined]
                    row = session.get_one(Submission, candidate_id)
                    assignment = session.get_one(Assignment, row.assignment_id)
                    return ClaimedJob(
                        candidate_id,
                        row.filename,
                        row.content,
                        row.seed,
                        attempts + 1,
                        config_toml=assignment.config_toml,
                        assignment=(assignment.lab, assignment.edition),
                    )
        return None

    def state(self, submission_id: int) -> tuple[JobStatus, int] | None:
        """The job's status and attempts so far, None when there is no such row."""
        with self._sessions() as session:
            row = session.execute(
                select(Submission.status, Submission.attempts).where(Submission.id == submission_id)
            ).first()
        return (JobStatus(row.status), row.attempts) if row is not None else None

    def renew(self, submission_id: int, worker_id: str) -> bool:
        """Extend the lease; see :meth:`JobQueue.renew`."""
        return self._update_owned(submission_id, worker_id, lease_expires_at=utcnow() + self._lease)

    def add_progress(self, submission_id: int, worker_id: str, problem: dict[str, Any]) -> bool:
        """Append one finished problem; see :meth:`JobQueue.add_progress`."""
        with self._sessions() as session:
            row = session.get(Submission, submission_id)
            if row is None or row.lease_owner != worker_id or row.status != JobStatus.RUNNING.value:
                return False
            progress = [*row.progress, problem]
        return self._update_owned(submission_id, worker_id, progress=progress)

    def complete(self, submission_id: int, worker_id: str, report: dict[str, Any]) -> bool:
        """Store the report; see :meth:`JobQueue.complete`."""
        return self._update_owned(
            submission_id,
            worker_id,
            status=JobStatus.DONE.value,
            report=report,
            error=None,
            score=float(report.get("score", 0.0)),
            max_score=float(report.get("max_score", 0.0)),
            progress=list(report.get("problems", [])),
            **_finished(),
        )

    def fail(self, submission_id: int, worker_id: str, message: str) -> bool:
        """Mark the job failed; see :meth:`JobQueue.fail`."""
        return self._update_owned(
            submission_id, worker_id, status=JobStatus.FAILED.value, error=message, **_finished()
        )

    def retry(self, submission_id: int, worker_id: str, message: str) -> bool:
        """Requeue or fail; see :meth:`JobQueue.retry`."""
        with self._sessions() as session:
            row = session.get(Submission, submission_id)
            attempts = row.attempts if row is not None else self._max_attempts
        if attempts >= self._max_attempts:
            return self.fail(submission_id, worker_id, f"{message}; gave up after {attempts} attempts")
        return self._update_owned(
            submission_id,
            worker_id,
            status=JobStatus.QUEUED.value,
            error=message,
            lease_owner=None,
            lease_expires_at=None,
            progress=[],
        )

    def release(self, submission_id: int, worker_id: str) -> bool:
        """Requeue without counting the attempt; see :meth:`JobQueue.release`."""
        return self._update_owned(
            submission_id,
            worker_id,
            status=JobStatus.QUEUED.value,
            attempts=Submission.attempts - 1,
            lease_owner=None,
            lease_expires_at=None,
            progress=[],
        )

    def _update_owned(self, submission_id: int, worker_id: str, **values: Any) -> bool:
        with self._sessions() as session:
            result = session.execute(
                update(Submission)
                .where(
                    Submission.id == submission_id,
                    Submission.lease_owner == worker_id,
                    Submission.status == JobStatus.RUNNING.value,
                )
                .values(**values)
            )
            session.commit()
            return bool(result.rowcount == 1)  # type: ignore[attr-defined]

    def _give_up(self, session: Session, submission_id: int, attempts: int, now: datetime) -> None:
        session.execute(
            update(Submission)
            .where(Submission.id == submission_id, Submission.attempts == attempts, _claimable(now))
            .values(
                status=JobStatus.FAILED.value,
                error=f"grading was interrupted {attempts} times (worker crash or restart); upload again",
                lease_owner=None,
                lease_expires_at=None,
                finished_at=now,
            )
        )
        session.commit()


def _claimable(now: datetime) -> ColumnElement[bool]:
    return or_(
        Submission.status == JobStatus.QUEUED.value,
        and_(Submission.status == JobStatus.RUNNING.value, Submission.lease_expires_at < now),
    )


def _finished() -> dict[str, Any]:
    return {"finished_at": utcnow(), "lease_owner": None, "lease_expires_at": None}


class PollingDispatcher:
    """The embedded queue's :class:`~api.jobs.job_queue.Dispatcher`: its workers poll the rows themselves."""

    def submitted(self, submission_id: int) -> None:
        """Nothing to do: a polling worker finds the queued row."""

    def close(self) -> None:
        """Nothing to release."""
