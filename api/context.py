"""What the routes share at run time: settings, the database, the job queue, its dispatcher and workers."""

from __future__ import annotations

from dataclasses import dataclass, field

from sqlalchemy import Engine
from sqlalchemy.orm import Session, sessionmaker

from api.courses import sync_default
from api.database import make_engine, make_session_factory, migrate
from api.jobs.job_queue import Dispatcher, JobQueue
from api.jobs.local import DatabaseQueue, PollingDispatcher
from api.jobs.pool import WorkerPool
from api.jobs.reconciler import Reconciler
from api.lti.keys import protect_keys
from api.lti.outbound import Outbound, OutboundPolicy
from api.lti.platforms import PlatformKeys
from api.lti.publisher import ScorePublisher
from api.lti.services import AccessTokens
from api.settings import Settings


@dataclass
class ServiceContext:
    """The service's long-lived objects, made at start-up."""

    settings: Settings
    engine: Engine
    sessions: sessionmaker[Session]
    jobs: JobQueue
    dispatcher: Dispatcher
    pool: WorkerPool | None = None
    reconciler: Reconciler | None = None
    publisher: ScorePublisher | None = None
    outbound: Outbound = field(init=False)
    platform_keys: PlatformKeys = field(init=False)
    access_tokens: AccessTokens = field(init=False)

    def __post_init__(self) -> None:
        self.outbound = Outbound(OutboundPolicy.of(self.settings))
        self.platform_keys = PlatformKeys(self.outbound)
        self.access_tokens = AccessTokens(self.outbound, self.settings.lti_hosts)

    @classmethod
    def open(cls, settings: Settings, *, pool_size: int, publish: bool = True) -> ServiceContext:
        """Connect, migrate the schema, bring the default assignment to the settings, and start grading:
        ``pool_size`` in-process workers (none when 0), or, with GYMGRADE_BROKER_URL, no grading here but
        Celery tasks and their reconciler; and, when
        ``publish`` (the server; not `gymgrade worker`), publish scores to the LMSs (LTI AGS)."""
        engine = make_engine(settings)
        migrate(engine)
        sessions = make_session_factory(engine)
        protect_keys(sessions, settings)
        with sessions() as session:
            sync_default(session, settings)
        publisher = ScorePublisher(sessions, settings) if publish else None
        if publisher is not None:
            publisher.start()
        jobs = DatabaseQueue(
            sessions, lease_seconds=settings.lease_seconds, max_attempts=settings.max_attempts
        )
        if settings.broker_url is not None:
            from api.jobs.distributed import CeleryDispatcher  # Celery is imported only where it is used

            celery = CeleryDispatcher(settings)
            reconciler = Reconciler(sessions, celery, settings.reconcile_seconds)
            reconciler.start()
            return cls(settings, engine, sessions, jobs, celery, reconciler=reconciler, publisher=publisher)
        pool = WorkerPool(jobs, settings, pool_size) if pool_size > 0 else None
        if pool is not None:
            pool.start()
        return cls(
            settings, engine, sessions, jobs, dispatcher=PollingDispatcher(), pool=pool, publisher=publisher
        )

    def close(self) -> None:
        """Stop the workers (their running jobs return to the queue) and close the database."""
        if self.pool is not None:
            self.pool.stop()
        if self.reconciler is not None:
            self.reconciler.stop()
        if self.publisher is not None:
            self.publisher.stop()
        self.dispatcher.close()
        self.outbound.close()
        self.engine.dispose()
