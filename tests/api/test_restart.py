"""A server killed with SIGKILL while grading loses nothing: after a restart every accepted job completes."""

from __future__ import annotations

from pathlib import Path

import httpx
import pytest
from api_testing import instructor_headers
from live_server import (
    E2E_GRADER,
    PARTIAL_SOLUTION,
    SYNTAX_ERROR,
    LiveProcess,
    create_student,
    service_environment,
    upload,
    wait_for,
)

# The real grader, with the full isolation the service requires.
pytestmark = [pytest.mark.e2e, pytest.mark.sandbox]

LEASE_SECONDS = 2


def test_jobs_survive_a_kill_and_restart(tmp_path: Path) -> None:
    env = service_environment(tmp_path / "data", E2E_GRADER, workers=1, lease_seconds=LEASE_SECONDS)
    first = LiveProcess("serve", env, tmp_path / "first.log").start()
    try:
        token = create_student(first.url, "ada")
        interrupted = upload(first.url, token, PARTIAL_SOLUTION)
        waiting = upload(first.url, token, SYNTAX_ERROR, name="second.py")
        assert wait_for(first.url, token, interrupted, {"running", "done", "failed"})["status"] == "running"
    finally:
        first.kill()

    second = LiveProcess("serve", env, tmp_path / "second.log", port=first.port).start()
    try:
        finished = [
            wait_for(second.url, token, submission_id, {"done", "failed"})
            for submission_id in (interrupted, waiting)
        ]
        assert [view["status"] for view in finished] == ["done", "done"], second.log()
        assert finished[0]["attempts"] == 2, "the interrupted job was graded again after the restart"
        assert finished[1]["attempts"] == 1
        assert [view["report"]["score"] for view in finished] == [3.0, 0.0]
        assert finished[1]["report"]["submission_error"]
        listed = httpx.get(second.url + "/submissions", headers=instructor_headers()).json()
        assert sorted(item["id"] for item in listed) == [interrupted, waiting]
    finally:
        second.stop()
