"""`gymgrade worker` on the cluster: a Celery worker whose tasks grade in the same niced child as locally.

Each task runs in a thread of Celery's thread pool (``--workers`` of them at once); the CPU work is in the
grading child process the thread follows (``api.jobs.runner.run_job``), so threads are enough and a
SIGKILL of the worker takes its gradings with it (the children die with their parent).
"""

from __future__ import annotations

import base64
import json
import logging
import os
import socket
import sys
import threading
import time
import uuid
from dataclasses import dataclass, field
from typing import Any

from celery import Celery
from celery.exceptions import Reject
from celery.signals import worker_shutting_down
from sqlalchemy import text

from api.database import make_engine, make_session_factory, migrate
from api.jobs.distributed import (
    GRADE_FILE,
    GRADE_SUBMISSION,
    QUEUE,
    RESULT_SECONDS,
    CeleryDispatcher,
    broker_problem,
    redis_client,
)
from api.jobs.job_queue import ClaimedJob
from api.jobs.local import DatabaseQueue
from api.jobs.runner import run_job
from api.models import JobStatus
from api.settings import Settings
from grader.render.neutral import MAX_FILE_NAME_CHARS, file_name

logger = logging.getLogger(__name__)

RESTARTS_VARIABLE = "GYMGRADE_WORKER_RESTARTS"
"""Where a worker that restarted itself in place keeps the times of its restarts (comma-separated)."""
RESTART_LIMIT = 5
RESTART_WINDOW_SECONDS = 300.0


def restart_history(variable: str | None, now: float) -> tuple[float, ...]:
    """The restart times of ``variable`` still inside the window before ``now`` (garbage ignored)."""
    times = []
    for item in (variable or "").split(","):
        try:
            moment = float(item)
        except ValueError:
            continue
        if now - RESTART_WINDOW_SECONDS <= moment <= now:
            times.append(moment)
    return tuple(times)


def should_restart(exitcode: int | None, stop_requested: bool, history: tuple[float, ...]) -> bool:
    """Whether a worker whose Celery loop returned should start again in place.

    Celery ends its worker on an error it does not know how to recover from, such as kombu failing inside
    its own reconnection after a broker restart (``Unrecoverable error: AttributeError(...)``). The rows
    are safe in the database either way, but a worker that simply exits stops the cluster's grading until
    someone restarts it; so unless a stop was asked for (SIGTERM, Ctrl-C) the worker starts again, at most
    :data:`RESTART_LIMIT` times in :data:`RESTART_WINDOW_SECONDS` (then it exits and says so).
    """
    return not stop_requested and bool(exitcode) and len(history) < RESTART_LIMIT


def cores() -> int:
    """The cores this process may run on."""
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1


def split_cores(concurrency: int | None, settings: Settings) -> tuple[int, int]:
    """Gradings at once and xdist workers per grading on this machine (measured in bench/RESULTS.md).

    By default one grading per core, each without xdist (its checks run one after another in the pytest
    process): under a burst of uploads that gave the most gradings per minute, since every xdist worker
    costs a start-up that a grading's short checks do not repay. GYMGRADE_GRADING_WORKERS (or fewer
    ``--workers``) trades throughput for the latency of one grading when the queue is short.
    """
    gradings = concurrency or cores()
    per_grading = settings.grading_workers or max(cores() // gradings, 1)
    return gradings, per_grading


def startup_problem(settings: Settings) -> str | None:
    """Why this machine cannot run a worker (broker, database or isolation), or None when it can."""
    problem = broker_problem(settings)
    if problem is not None:
        return problem
    engine = make_engine(settings)
    try:
        with engine.connect() as connection:
            connection.execute(text("SELECT 1"))
    except Exception as error:
        return (
            f"cannot reach the database at {engine.url.render_as_string(hide_password=True)} ({type(error).__name__}); "  # noqa: E501
            "check GYMGRADE_DATABASE_URL and that the database accepts connections from this machine"
        )
    finally:
        engine.dispose()
    if settings.allow_weak_isolation:
        return None
    from grader.sandbox import probe_isolation

    isolation = probe_isolation()
    if not isolation.full:
        missing = "; ".join(f"{layer.name}: {layer.detail} ({layer.remedy})" for layer in isolation.missing)
        return (
            f"this machine cannot isolate submissions as grading requires: {missing}. "
            "Install the missing layers (see scripts/setup.sh), or set GYMGRADE_ALLOW_WEAK_ISOLATION=1 for a trial only"  # noqa: E501
        )
    return None


MAX_REQUEST_NAME_CHARS = 4 * MAX_FILE_NAME_CHARS
"""Characters of a request's ``filename`` or ``name`` read: more than any name shown keeps."""


def shown_name(name: object, filename: str) -> str:
    """The name a batch file's messages and report show: the request's ``name`` (the batch computed it from
    the download, ``grader.render.neutral.file_name``), else its ``filename`` (a request from a batch of
    before the field), neutralised again here: a request is untrusted input, and the name is only ever
    shown (the file is written under ``api.uploads.grading_file_name``)."""
    given = name if isinstance(name, str) and name else filename
    return file_name(given[:MAX_REQUEST_NAME_CHARS])


@dataclass
class BatchFileJob:
    """A :class:`~api.jobs.job_queue.JobQueue` for one batch file: no row, the outcome is returned."""

    report: dict[str, Any] | None = None
    error: str | None = None
    released: bool = False
    progress: list[dict[str, Any]] = field(default_factory=list)

    def claim(self, worker_id: str, submission_id: int | None = None) -> ClaimedJob | None:
        """Never used: the task hands its job to the runner directly."""
        return None

    def renew(self, submission_id: int, worker_id: str) -> bool:
        """Nothing to renew: the broker holds the task until it is acknowledged."""
        return True

    def add_progress(self, submission_id: int, worker_id: str, problem: dict[str, Any]) -> bool:
        """Keep a finished problem."""
        self.progress.append(problem)
        return True

    def complete(self, submission_id: int, worker_id: str, report: dict[str, Any]) -> bool:
        """Keep the report."""
        self.report = report
        return True

    def fail(self, submission_id: int, worker_id: str, message: str) -> bool:
        """Keep the reason."""
        self.error = message
        return True

    def retry(self, submission_id: int, worker_id: str, message: str) -> bool:
        """Keep the reason (the batch's next run grades the file again)."""
        self.error = message
        return True

    def release(self, submission_id: int, worker_id: str) -> bool:
        """Note that the worker is shutting down."""
        self.released = True
        return True


class WorkerRuntime:
    """What the tasks of one worker process share: settings, the rows' queue, the dispatcher, a stop flag.

    Args:
        settings: Service settings (``grading_workers`` already decided).
    """

    def __init__(self, settings: Settings) -> None:
        self.settings = settings
        self.engine = make_engine(settings)
        migrate(self.engine)
        self.jobs = DatabaseQueue(
            make_session_factory(self.engine),
            lease_seconds=settings.lease_seconds,
            max_attempts=settings.max_attempts,
        )
        self.dispatcher = CeleryDispatcher(settings)
        self.redis = redis_client(settings)
        self.stop = threading.Event()
        self.prefix = f"{socket.gethostname()}:{os.getpid()}"

    def grade_row(self, submission_id: int) -> str:
        """Claim and grade the row ``submission_id``; what happened, for the worker's log.

        A row that is finished, or held by a live worker, is left alone (a duplicated delivery). A row
        that goes back to the queue (shutdown, crashed grading) gets a new task before this one is
        acknowledged.
        """
        worker_id = f"{self.prefix}:{uuid.uuid4().hex[:8]}"
        job = self.jobs.claim(worker_id, submission_id)
        if job is None:
            return "skipped: already graded, failed, or being graded by a live worker"
        try:
            run_job(job, self.jobs, worker_id, self.settings, self.stop)
        except Exception:
            logger.exception("worker %s failed while grading submission %s", worker_id, submission_id)
            self.jobs.retry(submission_id, worker_id, "the worker failed while grading")
        state = self.jobs.state(submission_id)
        if state is None:
            return "row deleted"
        status, attempts = state
        if status is JobStatus.QUEUED:
            self.dispatcher.enqueue(submission_id, attempts=attempts)
        elif status in (JobStatus.DONE, JobStatus.FAILED):
            self.dispatcher.forget(submission_id)
        return status.value

    def grade_file(self, request: dict[str, Any]) -> str:
        """Grade a batch file sent whole and push ``{"key", "report"}`` or ``{"key", "error"}`` to the
        batch's reply list in Redis; what happened, for the worker's log.

        Raises:
            celery.exceptions.Reject: The worker is shutting down; the task goes back to the queue.
        """
        filename = str(request["filename"])[:MAX_REQUEST_NAME_CHARS]
        job = ClaimedJob(
            submission_id=0,
            filename=filename,
            shown_name=shown_name(request.get("name"), filename),
            content=base64.b64decode(request["content"]),
            seed=int(request["seed"]),
            attempt=1,
            only=tuple(request["only"]) if request.get("only") is not None else None,
            config_toml=request.get("config_toml"),
        )
        settings = self.settings
        if not request.get("allow_weak_isolation", False):
            settings = settings.model_copy(update={"allow_weak_isolation": False})
        outcome = BatchFileJob()
        run_job(job, outcome, f"{self.prefix}:{uuid.uuid4().hex[:8]}", settings, self.stop)
        if outcome.released:
            raise Reject("the worker is shutting down", requeue=True)
        reply: dict[str, Any] = {"key": request["key"]}
        if outcome.report is not None:
            reply["report"] = outcome.report
        else:
            reply["error"] = outcome.error or "the grading ended without a report"
        reply_to = str(request["reply_to"])
        self.redis.rpush(reply_to, json.dumps(reply))
        self.redis.expire(reply_to, RESULT_SECONDS)
        return "report sent" if outcome.report is not None else "error sent"

    def close(self) -> None:
        """Close the database and broker connections."""
        self.dispatcher.close()
        self.redis.close()
        self.engine.dispose()


def register_tasks(app: Celery, runtime: WorkerRuntime) -> None:
    """Declare the cluster's two tasks on ``app``, run by ``runtime``."""

    @app.task(name=GRADE_SUBMISSION, ignore_result=True)  # type: ignore[untyped-decorator]
    def grade_submission(submission_id: int) -> str:
        return runtime.grade_row(int(submission_id))

    @app.task(name=GRADE_FILE, ignore_result=True)  # type: ignore[untyped-decorator]
    def grade_file(request: dict[str, Any]) -> str:
        return runtime.grade_file(request)


def run_worker(settings: Settings, concurrency: int | None) -> int:
    """Run a Celery worker until it is stopped (SIGTERM or Ctrl-C: running gradings go back to the queue).

    Args:
        settings: Service settings with a broker URL.
        concurrency: Gradings at once (None: one per core, see :func:`split_cores`).

    Returns:
        The worker's exit code.
    """
    gradings, per_grading = split_cores(concurrency, settings)
    settings = settings.model_copy(update={"grading_workers": per_grading})
    runtime = WorkerRuntime(settings)
    app = runtime.dispatcher.app
    register_tasks(app, runtime)

    def shutting_down(**_: Any) -> None:
        runtime.stop.set()

    worker_shutting_down.connect(shutting_down, weak=False)
    logger.info("grading %d submission(s) at once, %d xdist worker(s) each", gradings, per_grading)
    worker = app.Worker(
        pool="threads",
        concurrency=gradings,
        queues=[QUEUE],
        hostname=f"gymgrade-{os.getpid()}@{socket.gethostname()}",
        loglevel="INFO",
        without_gossip=True,
        without_mingle=True,
        optimization="fair",
    )
    try:
        worker.start()
    finally:
        runtime.close()
    exitcode = int(worker.exitcode or 0)
    now = time.time()
    history = restart_history(os.environ.get(RESTARTS_VARIABLE), now)
    if should_restart(exitcode, runtime.stop.is_set(), history):
        logger.critical(
            "the Celery worker stopped on an error it could not recover from (exit code %d); "
            "starting it again in place (restart %d of at most %d in %.0f s)",
            exitcode,
            len(history) + 1,
            RESTART_LIMIT,
            RESTART_WINDOW_SECONDS,
        )
        _restart_in_place([*history, now])
    if exitcode and not runtime.stop.is_set():
        logger.critical(
            "the Celery worker stopped on errors %d times in %.0f s; exiting. "
            "Check the broker (`gymgrade doctor`), then start `gymgrade worker` again: queued submissions are kept",  # noqa: E501
            len(history) + 1,  # this stop too
            RESTART_WINDOW_SECONDS,
        )
    return exitcode


def _restart_in_place(history: list[float]) -> None:
    """Replace this process with a fresh run of the same command (same pid, so leases stay readable)."""
    for handler in logging.getLogger().handlers:
        handler.flush()
    sys.stdout.flush()
    sys.stderr.flush()
    time.sleep(min(2.0 ** (len(history) - 1), 30.0))  # 1, 2, 4, 8, 16 s: a broken broker is not hammered
    environment = {**os.environ, RESTARTS_VARIABLE: ",".join(f"{moment:.3f}" for moment in history)}
    os.execve(sys.executable, list(sys.orig_argv), environment)
