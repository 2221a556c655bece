"""What the routes share at run time: settings, the database, the job queue and the worker pool."""

from __future__ import annotations

from dataclasses import dataclass

from sqlalchemy import Engine
from sqlalchemy.orm import Session, sessionmaker

from api.database import make_engine, make_session_factory, migrate
from api.jobs.local import DatabaseQueue
from api.jobs.pool import WorkerPool
from api.jobs.protocol import JobQueue
from api.settings import Settings


@dataclass
class ServiceContext:
    """The service's long-lived objects, made at start-up."""

    settings: Settings
    engine: Engine
    sessions: sessionmaker[Session]
    jobs: JobQueue
    pool: WorkerPool | None = None

    @classmethod
    def open(cls, settings: Settings, *, pool_size: int) -> ServiceContext:
        """Connect, migrate the schema, and start ``pool_size`` grading workers (none when 0)."""
        engine = make_engine(settings)
        migrate(engine)
        sessions = make_session_factory(engine)
        jobs = DatabaseQueue(
            sessions, lease_seconds=settings.lease_seconds, max_attempts=settings.max_attempts
        )
        pool = WorkerPool(jobs, settings, pool_size) if pool_size > 0 else None
        if pool is not None:
            pool.start()
        return cls(settings=settings, engine=engine, sessions=sessions, jobs=jobs, pool=pool)

    def close(self) -> None:
        """Stop the workers (their running jobs return to the queue) and close the database."""
        if self.pool is not None:
            self.pool.stop()
        self.engine.dispose()
