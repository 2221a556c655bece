"""The grader on the machines it is deployed on: every report arrives, with the plain Linux run's statuses,
whatever the namespaces, beside a live grading on the host (issue 46)."""

from __future__ import annotations

import json
import subprocess
from collections.abc import Iterator

import pytest

from grader.sandbox import probe_isolation
from grader.sandbox.isolation.cgroup import JobCgroup, create_job_cgroup, join_argv
from tests.grader.sandbox.deployment_shapes import GYMGRADE, HONEST, PID_NAMESPACE, can_build_shapes, run_in

FULL = probe_isolation()
CANNOT = can_build_shapes()
pytestmark = [
    pytest.mark.sandbox,
    pytest.mark.slow,
    pytest.mark.skipif(CANNOT is not None, reason=CANNOT or ""),
    pytest.mark.skipif(not FULL.is_active("cgroup"), reason="the cgroup tree is not writable here"),
]
RUNS = 3
"""Runs per shape in the suite; bench/deployment_shapes.py runs 20."""


@pytest.fixture
def host_job() -> Iterator[tuple[JobCgroup, subprocess.Popen[bytes]]]:
    """A live job of a grader on the host (this test process): a process in a job cgroup it owns."""
    job = create_job_cgroup(memory_bytes=256 << 20, max_pids=8)
    process = subprocess.Popen([*join_argv(job), "sleep", "600"], start_new_session=True)
    try:
        yield job, process
    finally:
        job.remove()
        process.wait(timeout=30)


def honest_check(shape: tuple[str, ...]) -> dict[str, object]:
    """Checks the bundled honest solution's first problem in `shape`; its report (exit 0 asserted)."""
    argv = [*GYMGRADE, "check", str(HONEST), "--only", "random_blackjack", "--seed", "1", "--format", "json"]
    run = run_in(shape, argv)
    assert run.returncode == 0, f"exit {run.returncode}: {run.stderr[-2000:]}"
    report: dict[str, object] = json.loads(run.stdout)
    return report


def test_check_in_a_pid_namespace_beside_a_live_host_job_reports_every_time(
    host_job: tuple[JobCgroup, subprocess.Popen[bytes]],
) -> None:
    """Inside the namespace the host job's process reads as 0 in `cgroup.procs`: the grader never takes
    it for a pid (kill(0) was the grader's own process group)."""
    for _ in range(RUNS):
        report = honest_check(PID_NAMESPACE)
        assert [(p["id"], p["status"]) for p in report["problems"]] == [("random_blackjack", "passed")]  # type: ignore[attr-defined,index]
        assert report["score"] == report["max_score"] == 1
