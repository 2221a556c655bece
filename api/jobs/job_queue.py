"""The job queue protocol: how workers claim gradings and report on them, whatever the backend."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Protocol


@dataclass(frozen=True)
class ClaimedJob:
    """A submission a worker holds the lease on and must grade."""

    submission_id: int
    filename: str
    content: bytes
    seed: int
    attempt: int
    only: tuple[str, ...] | None = None
    """Problems to grade (a batch's --only); all enabled ones when None."""
    config_toml: str | None = None
    """The assignment configuration's TOML text (a batch's --config); the bundled one when None."""
    shown_name: str | None = None
    """The file's own name as its messages and report show it (a class's download name, sent by the batch
    that read it, neutralised again on receipt); ``filename`` when None. Only ever shown, never a path."""
    assignment: tuple[str | None, str | None] | None = None
    """The (lab, edition) of the submission's assignment, as ``service_edition`` reads them; None (a
    batch's file): the worker's own GYMGRADE_LAB and GYMGRADE_EDITION."""


class JobQueue(Protocol):
    """A queue of grading jobs with leases: a job whose worker stops renewing its lease is handed out again.

    Every method that changes a job takes the worker's id and does nothing (returning False) when that
    worker no longer holds the job's lease, so a worker presumed dead can never overwrite a newer result.
    """

    def claim(self, worker_id: str, submission_id: int | None = None) -> ClaimedJob | None:
        """Take the oldest queued job, or a running one whose lease expired; None when there is none.

        With ``submission_id`` (a Celery task names its row), take that job only if it is claimable: a
        job that is done, failed, or held under a live lease is not taken again.
        """
        ...

    def renew(self, submission_id: int, worker_id: str) -> bool:
        """Extend the lease; False when the lease was lost (the worker must stop grading)."""
        ...

    def add_progress(self, submission_id: int, worker_id: str, problem: dict[str, Any]) -> bool:
        """Record one finished problem of a running job (shown live)."""
        ...

    def complete(self, submission_id: int, worker_id: str, report: dict[str, Any]) -> bool:
        """Store the report and mark the job done."""
        ...

    def fail(self, submission_id: int, worker_id: str, message: str) -> bool:
        """Mark the job failed for a reason that retrying cannot fix."""
        ...

    def retry(self, submission_id: int, worker_id: str, message: str) -> bool:
        """Put the job back in the queue after an interruption, or fail it once its attempts are used up."""
        ...

    def release(self, submission_id: int, worker_id: str) -> bool:
        """Put the job back in the queue without counting the attempt (the worker is shutting down)."""
        ...


class Dispatcher(Protocol):
    """Tells the workers that a queued job exists (the embedded queue's workers poll, so it does nothing)."""

    def submitted(self, submission_id: int) -> None:
        """Make sure a worker will pick up the queued submission ``submission_id`` (never raises)."""
        ...

    def close(self) -> None:
        """Release connections and stop background work."""
        ...
