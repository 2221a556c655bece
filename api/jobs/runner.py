"""Grades one claimed job in a niced child process, renewing its lease until the report is stored."""

from __future__ import annotations

import json
import logging
import queue
import shutil
import subprocess
import sys
import tempfile
import threading
import time
from dataclasses import dataclass
from pathlib import Path
from typing import IO, Any

from api.jobs.job_queue import ClaimedJob, JobQueue
from api.settings import Settings
from api.uploads import grading_file_name
from grader.sandbox import signalling

logger = logging.getLogger(__name__)

_STDERR_TAIL_CHARS = 4000
_WAIT_SECONDS = 0.25


@dataclass(frozen=True)
class _ChildExited:
    """End of the child's protocol stream."""


def run_job(
    job: ClaimedJob, jobs: JobQueue, worker_id: str, settings: Settings, stop: threading.Event
) -> None:
    """Grade ``job`` and store the outcome through ``jobs``; never raises for a grading failure.

    The grading runs in ``python -P -m api.jobs.child`` (niced, in its own session so that the whole
    process group is killed afterwards). While waiting, the lease is renewed every third of its length.
    When ``stop`` is set (shutdown) the job is put back in the queue.

    Args:
        job: The claimed job.
        jobs: The queue the job came from.
        worker_id: The lease owner.
        settings: Service settings (grader, niceness, lease, timeout).
        stop: Set when the worker must stop.
    """
    workdir = Path(tempfile.mkdtemp(prefix="gymgrade-job-"))
    # The file sits in a subdirectory and the child runs with -P, so nothing the student named
    # (json.py, grader.py...) can shadow a module of the trusted process that drives the sandbox.
    submission = workdir / "submission" / grading_file_name(job.filename)
    submission.parent.mkdir()
    with submission.open("xb") as created:  # a new file in a new folder: nothing to follow
        created.write(job.content)
    config = None
    if job.config_toml is not None:
        config = workdir / "assignment.toml"
        config.write_text(job.config_toml, encoding="utf-8")
    stderr_path = workdir / "grader-stderr.log"
    with stderr_path.open("wb") as stderr:
        child = subprocess.Popen(
            [sys.executable, "-P", "-m", "api.jobs.child"],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            stderr=stderr,
            cwd=workdir,
            start_new_session=True,
            text=True,
            encoding="utf-8",
        )
    try:
        _send_request(child, submission, config, job, settings)
        _follow(child, job, jobs, worker_id, settings, stop, stderr_path)
    finally:
        _kill_group(child)
        shutil.rmtree(workdir, ignore_errors=True)


def _send_request(
    child: subprocess.Popen[str], submission: Path, config: Path | None, job: ClaimedJob, settings: Settings
) -> None:
    shown = job.shown_name or job.filename
    request = {
        "grader": settings.grader,
        "path": str(submission),
        # The name messages and the report show, when the file here has another (safe) name: "my lab.py"
        # graded as submission.py, a class's download name. Only ever shown, never a path.
        "name": shown if shown != submission.name else None,
        "seed": job.seed,
        "only": list(job.only) if job.only is not None else None,
        "config": str(config) if config is not None else None,
        "edition": job.assignment[1] if job.assignment is not None else settings.edition,
        "lab": job.assignment[0] if job.assignment is not None else settings.lab,
        "workers": settings.grading_workers,
        "allow_weak_isolation": settings.allow_weak_isolation,
        "nice": settings.nice,
    }
    if child.stdin is None:
        raise RuntimeError("the grading child was started without a stdin pipe")
    try:
        child.stdin.write(json.dumps(request))
        child.stdin.close()
    except BrokenPipeError:
        logger.warning("grading child of submission %s died before reading its request", job.submission_id)


def _follow(
    child: subprocess.Popen[str],
    job: ClaimedJob,
    jobs: JobQueue,
    worker_id: str,
    settings: Settings,
    stop: threading.Event,
    stderr_path: Path,
) -> None:
    messages: queue.Queue[dict[str, Any] | _ChildExited] = queue.Queue()
    if child.stdout is None:
        raise RuntimeError("the grading child was started without a stdout pipe")
    threading.Thread(target=_read_messages, args=(child.stdout, messages), daemon=True).start()
    renew_every = settings.lease_seconds / 3
    last_renewal = time.monotonic()
    deadline = last_renewal + settings.grading_timeout_seconds
    sid = job.submission_id
    while True:
        try:
            message: dict[str, Any] | _ChildExited | None = messages.get(timeout=_WAIT_SECONDS)
        except queue.Empty:
            message = None
        if isinstance(message, _ChildExited):
            _kill_group(child)  # its leftovers, before its pid (the group's id) is free for reuse
            code = child.wait()
            logger.warning("grading child of submission %s exited with %s: %s", sid, code, _tail(stderr_path))
            jobs.retry(sid, worker_id, f"the grading process ended unexpectedly (exit status {code})")
            return
        if message is not None:
            kind = message.get("kind")
            if kind == "report":
                jobs.complete(sid, worker_id, message["report"])
                return
            if kind != "progress":
                jobs.fail(sid, worker_id, str(message.get("message", "the grader failed without saying why")))
                return
            jobs.add_progress(sid, worker_id, message["problem"])
        if stop.is_set():
            jobs.release(sid, worker_id)
            return
        now = time.monotonic()
        if now > deadline:
            jobs.fail(sid, worker_id, f"grading took longer than {settings.grading_timeout_seconds:.0f} s")
            return
        if now - last_renewal >= renew_every:
            if not jobs.renew(sid, worker_id):
                logger.warning("lost the lease of submission %s; another worker took it over", sid)
                return
            last_renewal = now


def _read_messages(stream: IO[str], messages: queue.Queue[dict[str, Any] | _ChildExited]) -> None:
    for line in stream:
        try:
            decoded = json.loads(line)
        except json.JSONDecodeError:
            logger.warning("ignored a malformed line from a grading child: %.200s", line)
            continue
        if isinstance(decoded, dict):
            messages.put(decoded)
    messages.put(_ChildExited())


def _kill_group(child: subprocess.Popen[str]) -> None:
    """SIGKILLs the grading child's process group (it leads its own session), then reaps it.

    Once the child is reaped its pid, the group's id, may name another process's group: then nothing is
    signalled (`grader.sandbox.signalling` also refuses the worker's own group)."""
    if child.returncode is None:
        signalling.kill_group(child.pid)
    child.wait()


def _tail(path: Path) -> str:
    return path.read_text(encoding="utf-8", errors="replace")[-_STDERR_TAIL_CHARS:]
