"""The distributed job backend: Celery tasks on a Redis broker, the database row staying each job's truth.

A task carries only a submission id. The worker that runs it claims the row with the same conditional
UPDATE as the embedded queue, so a duplicated or re-delivered task finds the row taken or finished and does
nothing. Tasks are acknowledged late (after the grading), so a worker that vanishes leaves its task to be
delivered again after the visibility timeout; the server's reconciler (``api.jobs.reconciler``) re-enqueues
sooner from the rows themselves. Next to each task the dispatcher keeps a marker key in Redis holding the
row's attempt count when it was enqueued, which is how the reconciler sees a task that is gone.
"""

from __future__ import annotations

import logging
import queue
import threading
from collections.abc import Sequence
from datetime import timedelta

import redis
from celery import Celery

from api.settings import BrokerSettings

logger = logging.getLogger(__name__)

QUEUE = "gymgrade"
GRADE_SUBMISSION = "gymgrade.grade_submission"
"""Task: grade the submission row with this id (the service's jobs)."""
GRADE_FILE = "gymgrade.grade_file"
"""Task: grade a file sent whole and push its report to the batch's Redis list (`gymgrade grade`)."""
_MARKER_PREFIX = "gymgrade:task:"
_CONNECT_TIMEOUT_SECONDS = 5.0
RESULT_SECONDS = int(timedelta(days=7).total_seconds())
"""How long a batch file's report waits in Redis for the `gymgrade grade` that asked for it."""


def make_celery(settings: BrokerSettings) -> Celery:
    """The Celery application of the cluster: Redis as broker, no result backend.

    Results go to the database (service jobs) or to a Redis list the batch reads (``api.jobs.batch``):
    Celery's Redis result backend gives up for good after a broker outage ("the Celery application must
    be restarted"), which a long-running server or worker cannot afford.

    Raises:
        ValueError: No broker URL is configured.
    """
    if settings.broker_url is None:
        raise ValueError("GYMGRADE_BROKER_URL is not set; expected redis://HOST:PORT/N")
    app = Celery("gymgrade", broker=settings.broker_url, set_as_current=False)
    transport = {"visibility_timeout": settings.visibility_timeout_seconds}
    app.conf.update(
        task_default_queue=QUEUE,
        task_acks_late=True,  # a task is removed from the broker only once its grading is stored
        task_reject_on_worker_lost=True,
        task_ignore_result=True,
        task_serializer="json",
        accept_content=["json"],
        worker_prefetch_multiplier=1,  # a worker holds no task it cannot start: the others take them
        worker_cancel_long_running_tasks_on_connection_loss=False,  # a grading survives a broker restart
        broker_transport_options=transport,
        broker_connection_retry_on_startup=True,
        broker_connection_timeout=_CONNECT_TIMEOUT_SECONDS,
        task_publish_retry_policy={"max_retries": 2, "interval_start": 0, "interval_step": 0.5},
        worker_hijack_root_logger=False,
    )
    return app


def redis_client(settings: BrokerSettings) -> redis.Redis:
    """A Redis client on the broker with short timeouts (a dead broker is reported, not waited for)."""
    if settings.broker_url is None:
        raise ValueError("GYMGRADE_BROKER_URL is not set; expected redis://HOST:PORT/N")
    client: redis.Redis = redis.Redis.from_url(
        settings.broker_url,
        socket_timeout=_CONNECT_TIMEOUT_SECONDS,
        socket_connect_timeout=_CONNECT_TIMEOUT_SECONDS,
    )
    return client


def broker_problem(settings: BrokerSettings) -> str | None:
    """Why the broker cannot be used right now (a sentence naming the URL), or None when it answers."""
    client = redis_client(settings)
    try:
        client.ping()
    except redis.RedisError as error:
        return (
            f"cannot reach the Redis broker at {settings.broker_url} ({error}); "
            "start it (e.g. `redis-server --port 6379`) or fix GYMGRADE_BROKER_URL"
        )
    finally:
        client.close()
    return None


class CeleryDispatcher:
    """A :class:`~api.jobs.job_queue.Dispatcher` that sends one Celery task per queued submission.

    New submissions are sent from a background thread, so an upload never waits for the broker; one the
    broker could not take is logged and left to the reconciler.

    Args:
        settings: The broker settings.
    """

    def __init__(self, settings: BrokerSettings) -> None:
        self.settings = settings
        self.app = make_celery(settings)
        self._redis = redis_client(settings)
        self._marker_seconds = int(2 * settings.visibility_timeout_seconds)
        self._submitted: queue.SimpleQueue[int | None] = queue.SimpleQueue()
        self._sender: threading.Thread | None = None

    def submitted(self, submission_id: int) -> None:
        """Enqueue a new submission's grading soon, in the background (never raises)."""
        if self._sender is None:
            self._sender = threading.Thread(target=self._send_submitted, name="gymgrade-enqueue", daemon=True)
            self._sender.start()
        self._submitted.put(submission_id)

    def _send_submitted(self) -> None:
        while (submission_id := self._submitted.get()) is not None:
            try:
                self.enqueue(submission_id, attempts=0)
            except Exception as error:  # the row is stored: the reconciler enqueues it once Redis is back
                logger.warning(
                    "could not enqueue submission %s (%s); the reconciler will", submission_id, error
                )

    def enqueue(self, submission_id: int, *, attempts: int) -> None:
        """Send the task of ``submission_id`` and mark it as sent while the row had ``attempts``."""
        self.app.send_task(GRADE_SUBMISSION, args=[submission_id], queue=QUEUE)
        self._redis.set(_MARKER_PREFIX + str(submission_id), attempts, ex=self._marker_seconds)

    def markers(self, submission_ids: Sequence[int]) -> dict[int, int | None]:
        """The attempt count each submission's last task was sent with (None: no task known)."""
        if not submission_ids:
            return {}
        values = self._redis.mget([_MARKER_PREFIX + str(sid) for sid in submission_ids])
        return {
            sid: int(value) if value is not None else None
            for sid, value in zip(submission_ids, values, strict=True)  # type: ignore[arg-type]
        }

    def forget(self, submission_id: int) -> None:
        """Drop the marker of a submission whose grading is final."""
        self._redis.delete(_MARKER_PREFIX + str(submission_id))

    def close(self) -> None:
        """Send what was submitted (briefly), then close the broker connections."""
        if self._sender is not None:
            self._submitted.put(None)
            self._sender.join(_CONNECT_TIMEOUT_SECONDS)
        self._redis.close()
        self.app.close()


def describe(settings: BrokerSettings) -> str:
    """The cluster as a person reads it: the broker's address without credentials."""
    url = settings.broker_url or ""
    _, _, address = url.rpartition("@")
    return f"the Celery cluster at redis://{address.removeprefix('redis://').removeprefix('rediss://')}"
