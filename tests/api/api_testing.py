"""Shared helpers of the service's tests: the instructor token, students, ports, PostgreSQL and Redis."""

from __future__ import annotations

import os
import secrets
import shutil
import socket
import subprocess
import tempfile
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import pytest
from fastapi.testclient import TestClient
from sqlalchemy import event

from api.settings import Settings

TESTS_DIR = Path(__file__).resolve().parent
FAKE_GRADER = "fake_grader:grade_submission"
INSTRUCTOR_TOKEN = "instructor-" + "x1y2z3w4v5u6t7s8r9q0"

SettingsFactory = Callable[..., Settings]

BOTH_DATABASES = pytest.mark.parametrize(
    "database_url", ["sqlite", pytest.param("postgresql", marks=pytest.mark.slow)], indirect=True
)
"""Run a test on SQLite and on PostgreSQL. The PostgreSQL run is `slow`: the run's first one starts a cluster
(initdb and pg_ctl, several seconds), so the default run covers the logic on SQLite and `-m ""` both."""


def instructor_headers() -> dict[str, str]:
    """Authorization headers of the instructor."""
    return {"Authorization": f"Bearer {INSTRUCTOR_TOKEN}"}


def bearer(token: str) -> dict[str, str]:
    """Authorization headers for ``token``."""
    return {"Authorization": f"Bearer {token}"}


def add_student(client: TestClient, name: str) -> str:
    """Create a student through the API and return their token."""
    response = client.post("/students", json={"name": name}, headers=instructor_headers())
    if response.status_code != 201:
        raise RuntimeError(f"could not create student {name!r}: {response.status_code} {response.text}")
    token: str = response.json()["token"]
    return token


def free_port() -> int:
    """A TCP port on 127.0.0.1 that nothing listens on right now."""
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        port: int = probe.getsockname()[1]
        return port


class PostgresServer:
    """A throw-away PostgreSQL cluster in a temporary directory, listening on a loopback port."""

    def __init__(self, bin_dir: Path) -> None:
        self.bin_dir = bin_dir
        self.directory = Path(tempfile.mkdtemp(prefix="gymgrade-pg-"))
        self.port = free_port()
        self._databases = 0
        self._as_user = ["runuser", "-u", "postgres", "--"] if os.geteuid() == 0 else []

    def _run(self, *command: str) -> None:
        subprocess.run([*self._as_user, *command], check=True, capture_output=True, timeout=60)

    def start(self) -> None:
        """Initialise and start the cluster (trust authentication, loopback only)."""
        if self._as_user:
            shutil.chown(self.directory, "postgres")
        data = str(self.directory / "data")
        self._run(str(self.bin_dir / "initdb"), "-D", data, "-U", "postgres", "--auth=trust", "-E", "UTF8")
        options = f"-p {self.port} -k {self.directory} -c listen_addresses=127.0.0.1 -c fsync=off"
        self._run(str(self.bin_dir / "pg_ctl"), "-D", data, "-o", options, "-w", "-l", data + "/log", "start")

    def stop(self) -> None:
        """Stop the cluster and delete its files."""
        self._run(str(self.bin_dir / "pg_ctl"), "-D", str(self.directory / "data"), "-m", "immediate", "stop")
        shutil.rmtree(self.directory, ignore_errors=True)

    def new_database(self) -> str:
        """Create an empty database and return its SQLAlchemy URL."""
        import psycopg

        self._databases += 1
        name = f"gymgrade_{self._databases}_{secrets.token_hex(4)}"
        with psycopg.connect(
            f"host=127.0.0.1 port={self.port} user=postgres dbname=postgres", autocommit=True
        ) as c:
            c.execute(f'CREATE DATABASE "{name}"')
        return f"postgresql+psycopg://postgres@127.0.0.1:{self.port}/{name}"


def postgres_bin_dir() -> Path | None:
    initdb = shutil.which("initdb")
    if initdb is not None:
        return Path(initdb).resolve().parent
    candidates = sorted(Path("/usr/lib/postgresql").glob("*/bin/initdb"))
    return candidates[-1].parent if candidates else None


class RedisServer:
    """A throw-away redis-server (no persistence: a restart loses every key) on a loopback port."""

    def __init__(self, executable: Path) -> None:
        self.executable = executable
        self.directory = Path(tempfile.mkdtemp(prefix="gymgrade-redis-"))
        self.port = free_port()
        self.process: subprocess.Popen[bytes] | None = None
        self._databases = 0

    def start(self) -> None:
        """Start the server and wait until it answers PING (at most 20 s)."""
        command = [str(self.executable), "--port", str(self.port), "--bind", "127.0.0.1"]
        command += ["--dir", str(self.directory), "--save", "", "--appendonly", "no", "--databases", "64"]
        with (self.directory / "redis.log").open("ab") as log:
            self.process = subprocess.Popen(command, stdout=log, stderr=subprocess.STDOUT)
        deadline = time.monotonic() + 20
        while not self.answers():
            if self.process.poll() is not None or time.monotonic() > deadline:
                raise RuntimeError(
                    f"redis-server did not start: {(self.directory / 'redis.log').read_text()}"
                )
            time.sleep(0.05)

    def answers(self) -> bool:
        """True when the server accepts a connection and answers PING."""
        try:
            with socket.create_connection(("127.0.0.1", self.port), timeout=1) as connection:
                connection.sendall(b"PING\r\n")
                return connection.recv(16).startswith(b"+PONG")
        except OSError:
            return False

    def stop(self) -> None:
        """Stop the server (its keys are gone: nothing is persisted)."""
        if self.process is not None and self.process.poll() is None:
            self.process.kill()
            self.process.wait()

    def close(self) -> None:
        """Stop the server and delete its directory."""
        self.stop()
        shutil.rmtree(self.directory, ignore_errors=True)

    def new_url(self) -> str:
        """The URL of a database index no earlier caller got."""
        self._databases += 1
        if self._databases >= 64:
            raise RuntimeError("more than 63 Redis databases asked for in one run")
        return f"redis://127.0.0.1:{self.port}/{self._databases}"


def graded_upload(client: TestClient, token: str, scores: dict[str, float]) -> int:
    """Upload a file as the student of ``token`` and complete its grading job with ``scores`` (each problem
    out of 1), as a worker would; return the submission's id."""
    response = client.post("/submissions", files={"file": ("opengym.py", b"x = 1\n")}, headers=bearer(token))
    submission_id: int = response.json()["id"]
    jobs = client.app.state.context.jobs  # type: ignore[attr-defined]
    job = jobs.claim("test-worker")
    if job is None or job.submission_id != submission_id:
        raise RuntimeError(f"expected to claim submission {submission_id}, claimed {job}")
    problems = [{"id": name, "score": score, "max_score": 1.0} for name, score in scores.items()]
    report = {"score": sum(scores.values()), "max_score": float(len(scores)), "problems": problems}
    if not jobs.complete(submission_id, "test-worker", report):
        raise RuntimeError(f"could not complete submission {submission_id}")
    return submission_id


@contextmanager
def recorded_statements(client: TestClient) -> Iterator[list[tuple[str, Any]]]:
    """Every SQL statement (and its parameters) the app of ``client`` runs inside the block."""
    statements: list[tuple[str, Any]] = []

    def record(_connection: Any, _cursor: Any, statement: str, parameters: Any, *_rest: Any) -> None:
        statements.append((statement, parameters))

    engine = client.app.state.context.engine  # type: ignore[attr-defined]
    event.listen(engine, "before_cursor_execute", record)
    try:
        yield statements
    finally:
        event.remove(engine, "before_cursor_execute", record)
