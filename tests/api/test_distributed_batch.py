"""`gymgrade grade` on the cluster: a real redis-server and `gymgrade worker`, the fake grader (and once
the real grader, through the real sandbox under full isolation).

The batch core is the local one (tests/grader/grading/test_batch.py); these tests pin that the cluster's
executor hands every report back, that a re-run resumes, and that an interrupted batch keeps what it finished.
"""

from __future__ import annotations

import csv
import re
import time
from collections.abc import Iterator
from pathlib import Path

import pytest
from api_testing import FAKE_GRADER, RedisServer
from live_server import LiveProcess, service_environment

from api.jobs.batch import CeleryExecutor, executor_from_environment
from api.settings import BrokerSettings
from grader import cli
from grader.classroom import command
from grader.errors import BatchInterrupted, ExecutorUnavailable
from grader.grading.batch import grade_many
from grader.report import ProblemResult
from grader.sandbox import IsolationPolicy

pytestmark = pytest.mark.e2e

ONLY = "random_blackjack,blackjack,cartpole"  # the fake grader's problems
READY_SECONDS = 60.0


@pytest.fixture
def broker_url(tmp_path: Path, redis_server: RedisServer) -> Iterator[str]:
    """A Redis database served by one `gymgrade worker` (SQLite for its unused job rows)."""
    url = redis_server.new_url()
    env = service_environment(tmp_path / "data", FAKE_GRADER, broker_url=url, allow_weak_isolation=1, nice=0)
    worker = LiveProcess("worker", env, tmp_path / "worker.log").start(wait_for_http=False)
    deadline = time.monotonic() + READY_SECONDS
    while not re.search(r"gymgrade-\d+@\S+ ready", worker.log()):
        assert time.monotonic() < deadline, worker.log()
        time.sleep(0.1)
    yield url
    worker.stop()


@pytest.fixture
def inputs(tmp_path: Path) -> Path:
    folder = tmp_path / "inputs"
    folder.mkdir()
    (folder / "alice.py").write_text("def random_blackjack(n):\n    return n\n")
    (folder / "bob.py").write_text("def cartpole():\n    return 1\n")
    (folder / "carol.py").write_text("def car(:\n")
    return folder


def _use_cluster(monkeypatch: pytest.MonkeyPatch, broker_url: str) -> None:
    class ClusterEntryPoint:
        name = "cluster"

        def load(self) -> object:
            return executor_from_environment

    monkeypatch.setenv("GYMGRADE_BROKER_URL", broker_url)
    monkeypatch.setattr(
        command,
        "entry_points",
        lambda group: [ClusterEntryPoint()] if group == command.EXECUTOR_GROUP else [],
    )


def test_a_batch_on_the_cluster_keeps_every_report_and_resumes(
    tmp_path: Path,
    broker_url: str,
    inputs: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    _use_cluster(monkeypatch, broker_url)
    out = tmp_path / "out"
    argv = ["grade", str(inputs), "--out", str(out), "--only", ONLY, "--allow-weak-isolation"]
    assert cli.main(argv) == 0
    err = capsys.readouterr().err
    assert f"Grading on the Celery cluster at {broker_url}." in err
    rows = list(csv.DictReader((out / "grades.csv").open()))
    assert [(row["student"], row["total"]) for row in rows] == [
        ("alice", "1"),
        ("bob", "1"),
        ("carol", "0"),
    ]
    assert rows[2]["note"].startswith("carol.py is not valid Python")

    (inputs / "bob.py").write_text("def cartpole():\n    return 2\n\ndef blackjack(n):\n    return n\n")
    assert cli.main(argv) == 0
    err = capsys.readouterr().err
    assert f"Resuming in {out}: 2 of 3 submissions are already graded there" in err
    assert "bob: blackjack passed" in err and "alice:" not in err.split("grading 1.")[1]
    rows = list(csv.DictReader((out / "grades.csv").open()))
    assert [(row["student"], row["total"]) for row in rows] == [
        ("alice", "1"),
        ("bob", "2"),
        ("carol", "0"),
    ]


def test_an_interrupted_cluster_batch_keeps_what_it_finished(
    tmp_path: Path, broker_url: str, inputs: Path
) -> None:
    paths = sorted(inputs.glob("*.py"))
    executor = CeleryExecutor(BrokerSettings(broker_url=broker_url), IsolationPolicy.ALLOW_FALLBACK)
    seen: list[str] = []

    def stop_at_the_second_file(path: Path, result: ProblemResult) -> None:
        seen.append(path.name)
        if len(set(seen)) == 2:
            raise KeyboardInterrupt

    out = tmp_path / "out"
    with pytest.raises(BatchInterrupted) as interrupted:
        grade_many(paths, out, only=ONLY.split(","), executor=executor, on_result=stop_at_the_second_file)
    assert (interrupted.value.finished, interrupted.value.total) == (1, 3)
    outcome = grade_many(paths, out, only=ONLY.split(","), executor=executor)
    assert len(outcome.reused) == 1 and len(outcome.graded) == 2
    assert [report.score for report in outcome.reports] == [1.0, 1.0, 0.0]


def test_an_unreachable_broker_is_refused_with_a_remedy(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("GYMGRADE_BROKER_URL", "redis://127.0.0.1:1/0")
    with pytest.raises(
        ExecutorUnavailable,
        match=r"cannot reach the Redis broker at redis://127.0.0.1:1/0 .*unset GYMGRADE_BROKER_URL",
    ):
        executor_from_environment(IsolationPolicy.REQUIRE_FULL)
    monkeypatch.delenv("GYMGRADE_BROKER_URL")
    assert executor_from_environment(IsolationPolicy.REQUIRE_FULL) is None


def test_a_file_the_cluster_could_not_grade_is_a_grader_error_in_every_problem(tmp_path: Path) -> None:
    from api.jobs.batch import _report
    from grader.grading.plan import GradingPlan

    path = tmp_path / "alice.py"
    path.write_bytes(b"def car():\n    return 1\n")
    plan = GradingPlan.load(None, ["cartpole", "car"])
    report = _report(path, path.read_bytes(), {"error": "the worker was killed"}, plan, 7)
    assert (report.submission, report.seed, report.score) == ("alice.py", 7, 0.0)
    assert [(result.id, result.status) for result in report.problems] == [
        ("cartpole", "error"),
        ("car", "error"),
    ]
    assert report.grader_errors == [
        "cartpole: the cluster could not grade it: the worker was killed",
        "car: the cluster could not grade it: the worker was killed",
    ]
    assert "not your code's fault" in report.problems[0].feedback


def test_the_workers_are_sent_the_configuration_the_batch_checked(tmp_path: Path) -> None:
    from api.jobs.batch import configuration_text
    from grader.errors import ConfigError
    from grader.grading.plan import GradingPlan
    from grader.lab.assignment import DEFAULT_CONFIG_PATH

    bundled = DEFAULT_CONFIG_PATH.read_text(encoding="utf-8")
    config = tmp_path / "assignment.toml"
    config.write_text(bundled, encoding="utf-8")
    plan = GradingPlan.load(config, None)
    assert configuration_text(plan) == bundled
    assert configuration_text(GradingPlan.load(None, None)) is None
    config.write_text("# the same configuration, with a comment\n" + bundled, encoding="utf-8")
    assert configuration_text(plan) is not None  # the same configuration: sent as the file now reads
    edited = bundled.replace("[problems.car]\npoints = 1.0", "[problems.car]\npoints = 4.0")
    assert edited != bundled
    config.write_text(edited, encoding="utf-8")
    with pytest.raises(ConfigError, match="changed after the batch read it"):
        configuration_text(plan)
    config.write_text("[problems.car\n", encoding="utf-8")
    with pytest.raises(ConfigError, match="cannot read the assignment configuration"):
        configuration_text(plan)


ROOT = Path(__file__).resolve().parents[2]


@pytest.mark.slow
@pytest.mark.sandbox
def test_a_real_worker_grades_through_the_real_sandbox(tmp_path: Path, redis_server: RedisServer) -> None:
    """The cluster with the real grader: a `gymgrade worker` on the service's default grader, full isolation
    required, one cheap problem; the honest file passes and the mistaken one fails with its diagnosis."""
    from grader.sandbox import probe_isolation

    isolation = probe_isolation()
    if not isolation.full:
        pytest.skip("needs full isolation:\n" + isolation.summary())
    url = redis_server.new_url()
    real_grader = "grader.grading.grade:grade_submission"
    env = service_environment(tmp_path / "data", real_grader, broker_url=url, allow_weak_isolation=0, nice=0)
    worker = LiveProcess("worker", env, tmp_path / "worker.log").start(wait_for_http=False)
    try:
        deadline = time.monotonic() + READY_SECONDS  # bounds a hang only: the loop ends at the log's "ready"
        while not re.search(r"gymgrade-\d+@\S+ ready", worker.log()):
            assert time.monotonic() < deadline, worker.log()
            time.sleep(0.1)
        inputs = tmp_path / "inputs"
        inputs.mkdir()
        honest = (ROOT / "submissions" / "classic_complete.py").read_bytes()
        mistaken = (ROOT / "submissions" / "mistakes" / "random_blackjack_average_reward.py").read_bytes()
        (inputs / "ada.py").write_bytes(honest)
        (inputs / "bob.py").write_bytes(mistaken)
        executor = CeleryExecutor(BrokerSettings(broker_url=url), IsolationPolicy.REQUIRE_FULL)

        outcome = grade_many(
            sorted(inputs.glob("*.py")), tmp_path / "out", only=["random_blackjack"], executor=executor
        )
    finally:
        worker.stop()

    ada, bob = outcome.reports
    assert (ada.grader_errors, bob.grader_errors) == ([], []), worker.log()
    assert ada.isolation is not None and ada.isolation.full, worker.log()
    assert [(result.id, result.status) for result in ada.problems] == [("random_blackjack", "passed")]
    assert [(result.id, result.status) for result in bob.problems] == [("random_blackjack", "failed")]
    assert "it equals the average reward" in bob.problems[0].feedback
