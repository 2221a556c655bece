"""Fixtures of the service's tests: settings on a temporary database, a client, PostgreSQL."""

from __future__ import annotations

import os
import shutil
import subprocess
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from api_testing import (
    FAKE_GRADER,
    INSTRUCTOR_TOKEN,
    TESTS_DIR,
    PostgresServer,
    RedisServer,
    SettingsFactory,
    postgres_bin_dir,
)
from fastapi.testclient import TestClient

from api.main import create_app
from api.settings import Settings


@pytest.fixture(autouse=True)
def _fake_grader_importable(monkeypatch: pytest.MonkeyPatch) -> None:
    """Grading children (``python -m api.jobs.child``) must be able to import the fake grader."""
    paths = [str(TESTS_DIR), *filter(None, os.environ.get("PYTHONPATH", "").split(os.pathsep))]
    monkeypatch.setenv("PYTHONPATH", os.pathsep.join(paths))


@pytest.fixture(params=["sqlite"])
def database_url(request: pytest.FixtureRequest, tmp_path: Path) -> str | None:
    """The database under test; tests that also run on PostgreSQL parametrize this indirectly."""
    if request.param == "sqlite":
        return None
    server: PostgresServer = request.getfixturevalue("postgres_server")
    return server.new_database()


@pytest.fixture
def make_settings(tmp_path: Path, database_url: str | None) -> SettingsFactory:
    """Build settings on a fresh database with the fake grader and fast leases; keywords override."""

    def build(**overrides: Any) -> Settings:
        values: dict[str, Any] = {
            "data_dir": tmp_path / "data",
            "database_url": database_url,
            "instructor_token": INSTRUCTOR_TOKEN,
            "grader": FAKE_GRADER,
            "workers": 0,
            "poll_seconds": 0.05,
            "lease_seconds": 30.0,
            "nice": 0,
            "rate_limit_per_minute": 1000,
        }
        values.update(overrides)
        return Settings(**values)

    return build


@pytest.fixture
def client(make_settings: SettingsFactory) -> Iterator[TestClient]:
    """A client of the app with no grading workers (tests grade through the queue themselves)."""
    with TestClient(create_app(make_settings(), run_workers=False)) as test_client:
        yield test_client


@pytest.fixture(scope="session")
def postgres_server() -> Iterator[PostgresServer]:
    """A PostgreSQL server for the whole run; the tests needing it are skipped when it cannot start."""
    bin_dir = postgres_bin_dir()
    if bin_dir is None:
        pytest.skip("PostgreSQL is not installed (apt-get install -y postgresql); its tests are skipped")
    try:
        import psycopg  # noqa: F401
    except ImportError:
        pytest.skip("psycopg is not installed (pip install -e .[postgres]); PostgreSQL tests are skipped")
    server = PostgresServer(bin_dir)
    try:
        server.start()
    except (subprocess.CalledProcessError, subprocess.TimeoutExpired, OSError) as error:
        shutil.rmtree(server.directory, ignore_errors=True)
        pytest.skip(f"could not start a PostgreSQL cluster: {error}")
    yield server
    server.stop()


@pytest.fixture(scope="session")
def redis_server() -> Iterator[RedisServer]:
    """A redis-server for the whole run (Debian's redis-server package); its tests skip without it."""
    executable = shutil.which("redis-server")
    if executable is None:
        pytest.skip(
            "redis-server is not installed (apt-get install -y redis-server); Celery tests are skipped"
        )
    server = RedisServer(Path(executable))
    try:
        server.start()
    except (RuntimeError, OSError) as error:
        server.close()
        pytest.skip(f"could not start redis-server: {error}")
    yield server
    server.close()
