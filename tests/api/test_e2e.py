"""End to end: `gymgrade serve` on loopback, uploads graded by the real grader, reports over HTTP."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import httpx
import pytest
from api_testing import BOTH_DATABASES, instructor_headers
from live_server import (
    E2E_GRADER,
    PARTIAL_SOLUTION,
    PARTIAL_STATUSES,
    SYNTAX_ERROR,
    LiveProcess,
    create_student,
    service_environment,
    upload,
    wait_for,
)

# The real grader, with the full isolation the service requires.
pytestmark = [pytest.mark.e2e, pytest.mark.sandbox]


@pytest.fixture
def server(tmp_path: Path) -> Iterator[LiveProcess]:
    process = LiveProcess(
        "serve", service_environment(tmp_path / "data", E2E_GRADER, workers=1), tmp_path / "log"
    )
    process.start()
    yield process
    process.stop()


def test_upload_is_graded_and_reported(server: LiveProcess) -> None:
    assert httpx.get(server.url + "/healthz").json()["workers"] == 1
    token = create_student(server.url, "ada")
    submission_id = upload(server.url, token, PARTIAL_SOLUTION)
    view = wait_for(server.url, token, submission_id, {"done", "failed"})
    assert view["status"] == "done", view.get("error") or server.log()
    report = view["report"]
    assert (report["submission"], report["sha256"]) == ("opengym.py", view["sha256"])
    assert {problem["id"]: problem["status"] for problem in report["problems"]} == PARTIAL_STATUSES
    assert (view["score"], view["max_score"]) == (report["score"], report["max_score"]) == (3.0, 5.0)
    gradebook = httpx.get(server.url + "/gradebook.csv", headers=instructor_headers()).text
    assert gradebook.splitlines()[1].startswith(f"ada,{submission_id},")


@BOTH_DATABASES
def test_a_separate_worker_process_grades_what_the_server_queues(
    tmp_path: Path, database_url: str | None
) -> None:
    database = {"database_url": database_url} if database_url else {}
    env = service_environment(tmp_path / "data", E2E_GRADER, workers=0, **database)
    server = LiveProcess("serve", env, tmp_path / "server.log").start()
    worker = LiveProcess("worker", env, tmp_path / "worker.log")
    try:
        # No clock stands in for "the server grades nothing": the server counts no grading worker of its own
        # (GET /healthz), and the job is queued when looked at once (timeout 0: one look, no wait).
        assert httpx.get(server.url + "/healthz").json()["workers"] == 0
        token = create_student(server.url, "ada")
        submission_id = upload(server.url, token, SYNTAX_ERROR)
        assert wait_for(server.url, token, submission_id, set(), timeout=0)["status"] == "queued"
        worker.start(wait_for_http=False)
        view = wait_for(server.url, token, submission_id, {"done", "failed"})
        assert view["status"] == "done", view.get("error") or worker.log()
        assert view["report"]["submission_error"], "a syntax error is a stored verdict of the grader"
        assert view["report"]["score"] == 0.0
        assert view["attempts"] == 1
    finally:
        worker.stop()
        server.stop()
