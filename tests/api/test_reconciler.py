"""The reconciler re-enqueues exactly the unfinished rows whose task is gone (no broker needed)."""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field

import pytest
from api_testing import SettingsFactory
from sqlalchemy.orm import Session, sessionmaker
from test_local_queue import _submit, expire_lease

from api.database import make_engine, make_session_factory, migrate
from api.jobs.local import DatabaseQueue
from api.jobs.reconciler import reconcile


@dataclass
class FakeDispatcher:
    """Keeps the task markers in a dict, as the Celery dispatcher keeps them in Redis."""

    marked: dict[int, int] = field(default_factory=dict)
    sent: list[int] = field(default_factory=list)

    def enqueue(self, submission_id: int, *, attempts: int) -> None:
        self.sent.append(submission_id)
        self.marked[submission_id] = attempts

    def markers(self, submission_ids: list[int]) -> dict[int, int | None]:
        return {sid: self.marked.get(sid) for sid in submission_ids}


@pytest.fixture
def sessions(make_settings: SettingsFactory) -> Iterator[sessionmaker[Session]]:
    engine = make_engine(make_settings())
    migrate(engine)
    yield make_session_factory(engine)
    engine.dispose()


def test_only_rows_without_a_task_for_their_current_attempt_are_enqueued(
    sessions: sessionmaker[Session],
) -> None:
    queued_with_task, queued_lost, live, dead, done = _submit(sessions, 5)
    queue = DatabaseQueue(sessions, lease_seconds=60, max_attempts=3)
    dispatcher = FakeDispatcher(marked={queued_with_task: 0, live: 0, dead: 0, done: 0})
    assert queue.claim("dead-worker", dead) is not None
    expire_lease(sessions, dead)  # the dead worker's lease runs out
    assert queue.claim("live-worker", live) is not None
    assert queue.claim("w", done) is not None and queue.complete(done, "w", {"problems": []})

    assert reconcile(sessions, dispatcher) == [queued_lost, dead]  # type: ignore[arg-type]
    assert dispatcher.marked[dead] == 1, "marked with the attempt the dead worker used up"
    assert reconcile(sessions, dispatcher) == [], "each lost task is sent once"  # type: ignore[arg-type]
