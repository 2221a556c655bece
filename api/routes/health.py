"""GET /healthz: the service is up and its database answers."""

from __future__ import annotations

from fastapi import APIRouter

from api.deps import ContextDep, SessionDep
from api.models import JobStatus
from api.schemas import Health
from api.submissions import count_by_status

router = APIRouter(tags=["health"])


@router.get("/healthz", response_model=Health)
def get_health(session: SessionDep, context: ContextDep) -> Health:
    """Liveness, queue depth, and the grading workers this process runs."""
    counts = count_by_status(session)
    return Health(
        database=session.get_bind().dialect.name,
        queued=counts.get(JobStatus.QUEUED.value, 0),
        running=counts.get(JobStatus.RUNNING.value, 0),
        workers=context.pool.running() if context.pool is not None else 0,
    )
