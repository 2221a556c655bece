"""The server's reconciler: every accepted job keeps a task on the broker, whatever the broker lost.

The rows are the truth, the broker's tasks only wake workers. At start-up and every
GYMGRADE_RECONCILE_SECONDS the reconciler re-enqueues a queued row whose task marker is gone (the broker
was restarted without persistence, flushed, or the upload's enqueue failed) and a running row whose
worker stopped renewing its lease (killed mid-grading), once per attempt. Duplicated tasks are harmless:
the claim lets only one of them grade.
"""

from __future__ import annotations

import logging
import threading
from typing import TYPE_CHECKING

from sqlalchemy import and_, or_, select
from sqlalchemy.orm import Session, sessionmaker

from api.models import JobStatus, Submission, utcnow

if TYPE_CHECKING:
    from api.jobs.distributed import CeleryDispatcher

logger = logging.getLogger(__name__)


def reconcile(sessions: sessionmaker[Session], dispatcher: CeleryDispatcher) -> list[int]:
    """Re-enqueue every unfinished job whose task is gone; the ids re-enqueued.

    A row needs a task when no marker holds its current attempt count: queued rows whose marker vanished,
    rows put back by a crashed grading (attempts grew) and running rows whose lease expired (attempts grew
    when the dead worker claimed them).
    """
    now = utcnow()
    with sessions() as session:
        rows = session.execute(
            select(Submission.id, Submission.attempts)
            .where(
                or_(
                    Submission.status == JobStatus.QUEUED.value,
                    and_(Submission.status == JobStatus.RUNNING.value, Submission.lease_expires_at < now),
                )
            )
            .order_by(Submission.id)
        ).all()
    markers = dispatcher.markers([row.id for row in rows])
    enqueued = []
    for row in rows:
        if markers.get(row.id) != row.attempts:
            dispatcher.enqueue(row.id, attempts=row.attempts)
            enqueued.append(row.id)
    return enqueued


class Reconciler:
    """Runs :func:`reconcile` at start and then periodically in a daemon thread of the server.

    Args:
        sessions: Sessions on the service's database.
        dispatcher: The Celery dispatcher.
        every_seconds: The period.
    """

    def __init__(
        self, sessions: sessionmaker[Session], dispatcher: CeleryDispatcher, every_seconds: float
    ) -> None:
        self._sessions = sessions
        self._dispatcher = dispatcher
        self._every = every_seconds
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name="gymgrade-reconciler", daemon=True)

    def start(self) -> None:
        """Start reconciling."""
        self._thread.start()

    def stop(self) -> None:
        """Stop and wait for the thread."""
        self._stop.set()
        self._thread.join(10)

    def _run(self) -> None:
        while not self._stop.is_set():
            try:
                enqueued = reconcile(self._sessions, self._dispatcher)
                if enqueued:
                    logger.warning("re-enqueued %d job(s) whose task was gone: %s", len(enqueued), enqueued)
            except Exception as error:  # broker or database down: try again next period
                logger.warning("could not reconcile the jobs with the broker (%s); retrying", error)
            self._stop.wait(self._every)
