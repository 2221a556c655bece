"""Migrations build exactly the tables the models describe, on SQLite (WAL) and PostgreSQL."""

from __future__ import annotations

from alembic.autogenerate import compare_metadata
from alembic.migration import MigrationContext
from api_testing import BOTH_DATABASES, SettingsFactory
from sqlalchemy import text

from api.database import make_engine, migrate
from api.models import Base


@BOTH_DATABASES
def test_migrations_match_the_models_and_can_run_twice(make_settings: SettingsFactory) -> None:
    engine = make_engine(make_settings())
    try:
        migrate(engine)
        migrate(engine)
        with engine.connect() as connection:
            differences = compare_metadata(MigrationContext.configure(connection), Base.metadata)
        assert differences == []
    finally:
        engine.dispose()


def test_sqlite_runs_in_wal_mode_in_the_data_dir(make_settings: SettingsFactory) -> None:
    settings = make_settings()
    engine = make_engine(settings)
    try:
        with engine.connect() as connection:
            assert connection.execute(text("PRAGMA journal_mode")).scalar() == "wal"
        assert (settings.data_dir / "gymgrade.sqlite3").exists()
    finally:
        engine.dispose()
