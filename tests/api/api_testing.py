"""Shared helpers of the service's tests: the instructor token, students, ports, a PostgreSQL cluster."""

from __future__ import annotations

import os
import secrets
import shutil
import socket
import subprocess
import tempfile
from collections.abc import Callable
from pathlib import Path

from fastapi.testclient import TestClient

from api.settings import Settings

TESTS_DIR = Path(__file__).resolve().parent
FAKE_GRADER = "fake_grader:grade_submission"
INSTRUCTOR_TOKEN = "instructor-" + "x1y2z3w4v5u6t7s8r9q0"

SettingsFactory = Callable[..., Settings]


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
