"""A pool of worker threads, each claiming one job at a time and grading it in a child process."""

from __future__ import annotations

import logging
import os
import socket
import threading
import uuid

from api.jobs.job_queue import JobQueue
from api.jobs.runner import run_job
from api.settings import Settings

logger = logging.getLogger(__name__)


class WorkerPool:
    """Runs ``size`` gradings at once, in the server process or in ``gymgrade worker``.

    Args:
        jobs: The queue to claim from.
        settings: Service settings.
        size: Gradings run at once.
    """

    def __init__(self, jobs: JobQueue, settings: Settings, size: int) -> None:
        self._jobs = jobs
        self._settings = settings
        self._stop = threading.Event()
        prefix = f"{socket.gethostname()}:{os.getpid()}:{uuid.uuid4().hex[:8]}"
        self._threads = [
            threading.Thread(
                target=self._work, args=(f"{prefix}:{index}",), name=f"gymgrade-worker-{index}", daemon=True
            )
            for index in range(size)
        ]

    def running(self) -> int:
        """How many of the worker threads run now."""
        return sum(thread.is_alive() for thread in self._threads)

    def start(self) -> None:
        """Start the worker threads."""
        for thread in self._threads:
            thread.start()

    def stop(self, timeout: float = 10.0) -> None:
        """Ask the workers to stop (running jobs go back to the queue) and wait for them."""
        self._stop.set()
        for thread in self._threads:
            thread.join(timeout)

    def wait(self) -> None:
        """Block until :meth:`stop` is called (used by ``gymgrade worker``)."""
        self._stop.wait()

    def _work(self, worker_id: str) -> None:
        while not self._stop.is_set():
            try:
                job = self._jobs.claim(worker_id)
            except Exception:  # a database hiccup must not kill the worker; it tries again
                logger.exception("could not claim a job; retrying in %s s", self._settings.poll_seconds)
                job = None
            if job is None:
                self._stop.wait(self._settings.poll_seconds)
                continue
            try:
                run_job(job, self._jobs, worker_id, self._settings, self._stop)
            except Exception:
                logger.exception("worker %s failed while grading submission %s", worker_id, job.submission_id)
                self._jobs.retry(job.submission_id, worker_id, "the worker failed while grading")
