"""The cluster: real redis-server, PostgreSQL, uvicorn and `gymgrade worker` processes (fake grader).

Workers are killed with SIGKILL mid-grading and Redis is restarted (losing every key); every accepted
submission must still end `done`, graded into its row once.
"""

from __future__ import annotations

import re
import time
from collections.abc import Iterator
from datetime import timedelta
from pathlib import Path
from typing import Any

import httpx
import pytest
import redis
from api_testing import FAKE_GRADER, PostgresServer, RedisServer, free_port, instructor_headers
from fake_grader import held, release
from live_server import LiveProcess, create_student, service_environment, upload, wait_for
from sqlalchemy import create_engine, select, update

from api.jobs.distributed import QUEUE, CeleryDispatcher
from api.models import Submission, utcnow
from api.settings import BrokerSettings

pytestmark = pytest.mark.e2e

WAIT_SECONDS = 60.0
"""Bounds a hang only: every wait polls for its event and ends as soon as it happens."""
DUPLICATE_SKIPPED = "skipped: already graded, failed, or being graded by a live worker"
LEASE_SECONDS = 300.0
"""Long: a live worker's lease never runs out by accident on a loaded machine (its renewals late); the test
that needs a lease run out, its worker killed, sets the expiry in the past itself (:func:`expire_lease`)."""
RECONCILE_SECONDS = 1.0


def fake_submission(index: int, sleep: float) -> bytes:
    """A file the fake grader takes about 3 x ``sleep`` seconds on (3 problems), unique by ``index`` (the
    sleep is a cost, no test's verdict depends on it)."""
    return f"# fake-grader: sleep={sleep}\n# {index}\ndef random_blackjack(n):\n    return n\n".encode()


class Cluster:
    """A server and workers sharing one PostgreSQL database and one Redis database."""

    def __init__(self, tmp_path: Path, database_url: str, broker_url: str) -> None:
        self.tmp_path = tmp_path
        self.database_url = database_url
        self.env = service_environment(
            tmp_path / "data",
            FAKE_GRADER,
            database_url=database_url,
            broker_url=broker_url,
            lease_seconds=LEASE_SECONDS,
            reconcile_seconds=RECONCILE_SECONDS,
            allow_weak_isolation=1,  # the fake grader runs nothing; isolation is the real tests' business
            nice=0,
        )
        self.server = LiveProcess("serve", self.env, tmp_path / "serve.log")
        self.workers: list[LiveProcess] = []

    def start_worker(self) -> LiveProcess:
        """Start a `gymgrade worker` and wait until Celery says it is ready."""
        log = self.tmp_path / f"worker-{len(self.workers)}.log"
        worker = LiveProcess("worker", self.env, log).start(wait_for_http=False)
        self.workers.append(worker)
        deadline = time.monotonic() + WAIT_SECONDS
        while not re.search(r"gymgrade-\d+@\S+ ready", worker.log()):
            if worker.process is not None and worker.process.poll() is not None:
                raise RuntimeError(f"the worker exited with {worker.process.returncode}:\n{worker.log()}")
            if time.monotonic() > deadline:
                raise RuntimeError(f"the worker was not ready within {WAIT_SECONDS} s:\n{worker.log()}")
            time.sleep(0.1)
        return worker

    def rows(self) -> dict[int, Submission]:
        """Every submission row, read directly from the database."""
        engine = create_engine(self.database_url)
        try:
            with engine.connect() as connection:
                return {row.id: row for row in connection.execute(select(Submission))}  # type: ignore[misc]
        finally:
            engine.dispose()

    def stop(self) -> None:
        """Stop every process (all asked at once, then each waited for)."""
        processes = [self.server, *self.workers]
        for live in processes:
            if live.process is not None and live.process.poll() is None:
                live.process.terminate()
        for live in processes:
            live.stop()


@pytest.fixture
def cluster(tmp_path: Path, postgres_server: PostgresServer, redis_server: RedisServer) -> Iterator[Cluster]:
    """A server on PostgreSQL + Redis (no worker yet)."""
    running = Cluster(tmp_path, postgres_server.new_database(), redis_server.new_url())
    running.server.start()
    try:
        yield running
    finally:
        running.stop()


def _wait_all(cluster: Cluster, token: str, ids: list[int]) -> list[dict[str, Any]]:
    views = [
        wait_for(cluster.server.url, token, sid, {"done", "failed"}, timeout=WAIT_SECONDS) for sid in ids
    ]
    logs = "\n".join(worker.log() for worker in cluster.workers)
    assert [view["status"] for view in views] == ["done"] * len(ids), logs
    return views


def expire_lease(cluster: Cluster, submission_id: int) -> None:
    """The row's lease runs out, as the clock would leave it once its worker stopped renewing it."""
    engine = create_engine(cluster.database_url)
    try:
        with engine.begin() as connection:
            connection.execute(
                update(Submission)
                .where(Submission.id == submission_id)
                .values(lease_expires_at=utcnow() - timedelta(seconds=1))
            )
    finally:
        engine.dispose()


def _owner_pid(cluster: Cluster, submission_id: int) -> int | None:
    owner = cluster.rows()[submission_id].lease_owner
    return int(owner.split(":")[1]) if owner else None


def test_a_worker_killed_mid_grading_loses_nothing(cluster: Cluster) -> None:
    first, second = cluster.start_worker(), cluster.start_worker()
    token = create_student(cluster.server.url, "ada")
    hold = cluster.tmp_path / "release"
    slow = upload(cluster.server.url, token, held(hold) + fake_submission(0, sleep=0.0))
    # The job is held until its worker is killed: the kill lands mid-grading whatever the machine's speed.
    deadline = time.monotonic() + WAIT_SECONDS
    while _owner_pid(cluster, slow) is None:
        assert time.monotonic() < deadline, "no worker took the job"
        time.sleep(0.05)
    victim = next(
        w for w in (first, second) if w.process is not None and w.process.pid == _owner_pid(cluster, slow)
    )
    victim.kill()
    expire_lease(cluster, slow)  # the reconciler hands the job to the other worker
    release(hold)  # whose attempt may go on
    quick = [upload(cluster.server.url, token, fake_submission(i, sleep=0.05)) for i in range(1, 5)]
    views = _wait_all(cluster, token, [slow, *quick])  # bounded by WAIT_SECONDS (bench/ times recovery)
    assert views[0]["attempts"] == 2, "the killed worker's job was graded again by the other"
    assert [view["attempts"] for view in views[1:]] == [1, 1, 1, 1]
    assert all(view["report"]["score"] == 1.0 for view in views)


def test_a_broker_restart_and_duplicated_tasks_lose_and_repeat_nothing(
    cluster: Cluster, redis_server: RedisServer
) -> None:
    cluster.start_worker()
    token = create_student(cluster.server.url, "grace")
    before = [upload(cluster.server.url, token, fake_submission(i, sleep=0.02)) for i in range(2)]
    _wait_all(cluster, token, before)
    redis_server.stop()
    during = [upload(cluster.server.url, token, fake_submission(i, sleep=0.02)) for i in range(2, 4)]
    redis_server.start()
    views = _wait_all(cluster, token, [*before, *during])
    finished = {sid: row.finished_at for sid, row in cluster.rows().items()}

    def skipped() -> int:  # Celery logs each task's return value: a duplicate's is grade_row's "skipped: ..."
        return sum(worker.log().count(DUPLICATE_SKIPPED) for worker in cluster.workers)

    already = skipped()
    dispatcher = CeleryDispatcher(BrokerSettings(broker_url=cluster.env["GYMGRADE_BROKER_URL"]))
    try:
        for submission_id in before:
            dispatcher.enqueue(submission_id, attempts=1)
    finally:
        dispatcher.close()
    deadline = time.monotonic() + WAIT_SECONDS  # bounds a hang only: the loop ends when both were handled
    while skipped() < already + len(before):
        assert time.monotonic() < deadline, (
            "the duplicate tasks were not handled:\n" + cluster.workers[0].log()
        )
        time.sleep(0.1)
    rows = cluster.rows()
    assert {sid: row.finished_at for sid, row in rows.items()} == finished, "a duplicate task re-graded a row"
    assert [view["attempts"] for view in views] == [1] * 4
    listed = httpx.get(cluster.server.url + "/submissions", headers=instructor_headers()).json()
    assert sorted(item["id"] for item in listed) == sorted([*before, *during])


def test_a_worker_whose_celery_loop_dies_starts_again_in_place_and_grades(cluster: Cluster) -> None:
    worker = cluster.start_worker()
    broker = redis.Redis.from_url(cluster.env["GYMGRADE_BROKER_URL"])
    try:
        broker.set(QUEUE, "not a list")  # the consumer's BRPOP gets WRONGTYPE: Celery cannot recover
        deadline = time.monotonic() + WAIT_SECONDS
        while "starting it again in place" not in worker.log():
            assert time.monotonic() < deadline, f"the worker did not restart itself:\n{worker.log()}"
            time.sleep(0.1)
        broker.delete(QUEUE)
    finally:
        broker.close()
    token = create_student(cluster.server.url, "hedy")
    graded = upload(cluster.server.url, token, fake_submission(0, sleep=0.02))
    _wait_all(cluster, token, [graded])
    assert worker.process is not None and worker.process.poll() is None, "the same process still runs"
    assert len(re.findall(rf"gymgrade-{worker.process.pid}@\S+ ready", worker.log())) >= 2


@pytest.mark.parametrize(
    ("setting", "message"),
    [
        ({"broker_url": "redis://127.0.0.1:{port}/0"}, "cannot reach the Redis broker at redis://127.0.0.1:"),
        (
            {"database_url": "postgresql+psycopg://postgres@127.0.0.1:{port}/none"},
            "cannot reach the database",
        ),
    ],
    ids=["no-broker", "no-database"],
)
def test_a_worker_refuses_to_start_without_its_broker_or_database(
    tmp_path: Path, redis_server: RedisServer, setting: dict[str, str], message: str
) -> None:
    values = {"broker_url": redis_server.new_url(), "allow_weak_isolation": "1"}
    values.update({name: value.format(port=free_port()) for name, value in setting.items()})
    worker = LiveProcess(
        "worker", service_environment(tmp_path / "data", FAKE_GRADER, **values), tmp_path / "w.log"
    )
    worker.start(wait_for_http=False)
    assert worker.process is not None
    assert worker.process.wait(timeout=WAIT_SECONDS) == 2
    assert f"gymgrade worker: {message}" in worker.log()
