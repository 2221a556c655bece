"""The grader on the machines it is deployed on: every report arrives, with the plain Linux run's statuses,
whatever the namespaces, beside a live grading on the host (issue 46)."""

from __future__ import annotations

import json
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from grader.sandbox import probe_isolation
from grader.sandbox.isolation.cgroup import JobCgroup, create_job_cgroup, join_argv
from tests.grader.sandbox.deployment_shapes import (
    DOCKER_DEFAULT,
    GRADESCOPE,
    GYMGRADE,
    HONEST,
    PID_NAMESPACE,
    ROOT,
    SHAPE_HOSTILE,
    THIS_FILE,
    can_build_shapes,
    gradescope_root,
    hostile_sample,
    hostile_upload,
    run_autograder_argv,
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


SHAPES = {"pid namespace": PID_NAMESPACE, "docker default": DOCKER_DEFAULT}
NOT_APPLIED = {"pid namespace": set(), "docker default": {"cgroup", "bubblewrap"}}
"""Layers each shape cannot apply (the Docker shape's `privileges` too where the interpreter is not
readable by an unprivileged uid, as on this machine's /root/.pyenv; Gradescope's /usr/bin Python is)."""
DEGRADED = {
    ("docker default", "fork_bomb.py"): {"timeout", "ok"},
}
"""Where a shape's status may differ from the plain Linux run's, and why: without a pids cgroup, nothing
bounds the fork bomb's 500 forks (root ignores RLIMIT_NPROC; a dropped uid shares it with every child) but
the call's wall clock: a loaded machine stops it (`timeout`), an idle one may finish all 500 (`ok`, with
500 where the plain run's pids limit stopped it below 32) (docs/operations.md, "Deployment shapes")."""


@pytest.mark.parametrize("file", SHAPE_HOSTILE)
@pytest.mark.parametrize("shape", list(SHAPES))
def test_hostile_samples_get_the_plain_runs_outcome_in_each_shape(shape: str, file: str) -> None:
    """Killing (kill -1, the parent, init), forking, filling memory and the disk: the grader's report
    arrives with the child's verdict, the following call is served, nothing is left behind."""
    run = run_in(SHAPES[shape], [sys.executable, str(THIS_FILE), "hostile", file])
    assert run.returncode == 0, f"the grader did not report (exit {run.returncode}): {run.stderr[-2000:]}"
    outcome: dict[str, Any] = json.loads(run.stdout)
    sample = hostile_sample(file)
    assert outcome["status"] in DEGRADED.get((shape, file), {sample["status"]}), outcome["message"]
    if "value" in sample:  # kill_parent: the parent and init refused it, as in the plain run
        assert outcome["value"] == sample["value"]
    assert outcome["following"] == ["ok", 42]
    assert outcome["leftovers"] == 0
    missing = set(outcome["missing"])
    assert NOT_APPLIED[shape] <= missing <= NOT_APPLIED[shape] | {"privileges"}


def test_check_in_the_docker_shape_grades_and_names_the_layers_it_could_not_apply() -> None:
    report = honest_check(DOCKER_DEFAULT)
    assert statuses(report) == [("random_blackjack", "passed")]
    isolation = report["isolation"]
    assert isinstance(isolation, dict)
    inactive = {layer["name"]: layer["detail"] for layer in isolation["layers"] if not layer["active"]}
    assert isolation["full"] is False
    assert "read-only" in inactive["cgroup"]
    assert "Operation not permitted" in inactive["bubblewrap"]


def test_grade_in_the_docker_shape_refuses_and_says_why(tmp_path: Path) -> None:
    (tmp_path / "class" / "ada").mkdir(parents=True)
    (tmp_path / "class" / "ada" / "opengym.py").write_bytes(HONEST.read_bytes())
    argv = [*GYMGRADE, "grade", str(tmp_path / "class"), "--out", str(tmp_path / "book"), "--seed", "1"]
    run = run_in(DOCKER_DEFAULT, argv)
    assert run.returncode == 2, run.stderr[-2000:]
    assert "full isolation is required" in run.stderr
    assert "- cgroup: the cgroup tree is read-only here" in run.stderr
    assert "root may not make namespaces here" in run.stderr
    assert not (tmp_path / "book" / "grades.csv").exists()


DOCTOR = {
    "pid namespace": (0, ["[x] cgroup:", "by cgroup.kill; in a nested PID namespace", "ready to grade"]),
    "docker default": (2, ["[ ] cgroup: the cgroup tree is read-only", "[ ] bubblewrap:", "NOT ready"]),
}


@pytest.mark.parametrize("shape", list(DOCTOR))
def test_doctor_tells_the_truth_in_each_shape(shape: str) -> None:
    code, lines = DOCTOR[shape]
    run = run_in(SHAPES[shape], [*GYMGRADE, "doctor"])
    assert run.returncode == code, run.stdout[-3000:] + run.stderr[-2000:]
    for line in lines:
        assert line in run.stdout


UPLOADS = ["honest", *SHAPE_HOSTILE]


@pytest.mark.parametrize("upload", UPLOADS)
def test_gradescope_shape_writes_the_results_of_every_upload(tmp_path: Path, upload: str) -> None:
    """The bundle's run_autograder as root in the Docker-default container: results.json arrives for the
    honest solution (full marks) and for uploads whose random_blackjack kills, forks, floods memory and
    fills the disk (that problem failed), and says which layers the container did not allow."""
    source = HONEST.read_text(encoding="utf-8") if upload == "honest" else hostile_upload(upload)
    root = gradescope_root(tmp_path, source)
    run = run_in(GRADESCOPE, run_autograder_argv(root))
    assert run.returncode == 0, run.stderr[-2000:]
    results = json.loads((root / "results" / "results.json").read_text(encoding="utf-8"))
    (problem,) = [test for test in results["tests"] if test["name"] == "Problem 1: random Blackjack"]
    assert problem["status"] == ("passed" if upload == "honest" else "failed"), problem["output"]
    assert "weaker isolation" in results["output"]
    assert "- cgroup: the cgroup tree is read-only" in results["output"]
