"""The grader on the machines it is deployed on: every report arrives, with the plain Linux run's statuses,
whatever the namespaces, beside a live grading on the host (issue 46)."""

from __future__ import annotations

import json
import subprocess
from collections.abc import Iterator

import pytest

from grader.sandbox import probe_isolation
from grader.sandbox.isolation.cgroup import JobCgroup, create_job_cgroup, join_argv
from tests.grader.sandbox.deployment_shapes import (
    GYMGRADE,
    HONEST,
    PID_NAMESPACE,
    ROOT,
    can_build_shapes,
    run_in,
)

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


def statuses(report: dict[str, object]) -> list[tuple[str, str]]:
    """(problem, status) of each problem of a report."""
    problems = report["problems"]
    assert isinstance(problems, list)
    return [(problem["id"], problem["status"]) for problem in problems]


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
    job, process = host_job
    for _ in range(RUNS):
        report = honest_check(PID_NAMESPACE)
        assert statuses(report) == [("random_blackjack", "passed")]
        assert report["score"] == report["max_score"] == 1
    # ... and the namespace's graders took the host's live job for nobody's: its process runs, in its job.
    assert process.poll() is None
    assert process.pid in job.pids()


def test_two_graders_in_different_pid_namespaces_grading_at_once_lose_no_verdict(
    host_job: tuple[JobCgroup, subprocess.Popen[bytes]],
) -> None:
    """A grading on the host and gradings in a PID namespace at the same time: each sweeps the job
    cgroups of the other, whose owners it cannot see, on every child it starts. Before the lock, the
    namespace's sweep SIGKILLed the host's children (`random_blackjack() was killed by SIGKILL`)."""
    argv = [*GYMGRADE, "check", str(HONEST), "--only", "random_blackjack,blackjack", "--seed", "1", "--json"]
    host = subprocess.Popen(argv, cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    namespaced = [honest_check(PID_NAMESPACE) for _ in range(RUNS)]
    out, err = host.communicate(timeout=600)
    assert host.returncode == 0, err[-2000:]
    assert statuses(json.loads(out)) == [("random_blackjack", "passed"), ("blackjack", "passed")]
    for report in namespaced:
        assert statuses(report) == [("random_blackjack", "passed")]
    job, process = host_job
    assert process.poll() is None
    assert process.pid in job.pids()
