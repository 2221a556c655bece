"""The database engine (SQLite in WAL mode by default, PostgreSQL by URL) and migrations at start-up."""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any

from alembic import command
from alembic.config import Config
from sqlalchemy import Connection, Engine, create_engine, event, text
from sqlalchemy.exc import OperationalError
from sqlalchemy.orm import Session, sessionmaker

from api.settings import Settings

MIGRATIONS_DIR = Path(__file__).with_name("migrations")
_MIGRATION_LOCK_ID = 0x67796D67  # "gymg": serialises start-up migrations of several processes on PostgreSQL
SQLITE_BUSY_TIMEOUT_MS = 30_000
_MIGRATION_ATTEMPTS = 3


def make_engine(settings: Settings) -> Engine:
    """Create the engine for the configured database, making DATA_DIR for the default SQLite file.

    Args:
        settings: The service settings.

    Returns:
        An engine; SQLite connections use WAL journaling, a busy timeout and foreign keys.
    """
    url = settings.sqlalchemy_url
    if not url.startswith("sqlite"):
        return create_engine(url, pool_pre_ping=True, pool_size=10, max_overflow=20)
    settings.data_dir.mkdir(parents=True, exist_ok=True)
    engine = create_engine(
        url, connect_args={"check_same_thread": False, "timeout": SQLITE_BUSY_TIMEOUT_MS / 1000}
    )
    event.listen(engine, "connect", _configure_sqlite_connection)
    return engine


def _configure_sqlite_connection(dbapi_connection: Any, _record: Any) -> None:
    cursor = dbapi_connection.cursor()
    cursor.execute("PRAGMA journal_mode=WAL")
    cursor.execute(f"PRAGMA busy_timeout={SQLITE_BUSY_TIMEOUT_MS}")
    cursor.execute("PRAGMA foreign_keys=ON")
    cursor.execute("PRAGMA synchronous=NORMAL")
    cursor.close()


def migrate(engine: Engine) -> None:
    """Bring the database schema to the newest migration (safe to run from several processes at once).

    Args:
        engine: The engine of the database to migrate.
    """
    for attempt in range(_MIGRATION_ATTEMPTS):
        try:
            _upgrade_to_head(engine)
            return
        except OperationalError:
            # Two processes migrating one SQLite file race on the first DDL statement; the loser
            # finds the schema done on its next try.
            if attempt == _MIGRATION_ATTEMPTS - 1 or engine.dialect.name != "sqlite":
                raise
            time.sleep(0.2 * (attempt + 1))


def _upgrade_to_head(engine: Engine) -> None:
    config = Config()
    config.set_main_option("script_location", str(MIGRATIONS_DIR))
    with engine.connect() as connection:
        sqlite = connection.dialect.name == "sqlite"
        if sqlite:
            # Batch migrations copy, drop and rename tables others reference (SQLite cannot alter a
            # constraint); with foreign keys enforced, dropping a referenced table fails. The pragma only
            # takes effect outside a transaction; the keys are checked before the commit instead.
            connection.exec_driver_sql("PRAGMA foreign_keys=OFF")
            connection.commit()
        try:
            with connection.begin():
                if connection.dialect.name == "postgresql":
                    connection.execute(
                        text("SELECT pg_advisory_xact_lock(:lock)"), {"lock": _MIGRATION_LOCK_ID}
                    )
                config.attributes["connection"] = connection
                command.upgrade(config, "head")
                if sqlite:
                    _check_foreign_keys(connection)
        finally:
            if sqlite:
                connection.exec_driver_sql("PRAGMA foreign_keys=ON")
                connection.commit()


def _check_foreign_keys(connection: Connection) -> None:
    broken = connection.exec_driver_sql("PRAGMA foreign_key_check").all()
    if broken:
        raise RuntimeError(
            f"the migration left rows whose foreign keys point nowhere (table, row, parent): {broken[:5]}; "
            "nothing was changed: report this with the database's schema version"
        )


def make_session_factory(engine: Engine) -> sessionmaker[Session]:
    """A session factory whose objects stay readable after commit."""
    return sessionmaker(engine, expire_on_commit=False)
