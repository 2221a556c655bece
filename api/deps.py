"""Dependency aliases of the routes: the service context, a database session, and the caller.

Dependencies that do no I/O are ``async`` so that FastAPI does not hop to its thread pool for each of them
(each hop costs about as much as the request's own queries); those that query the database stay synchronous
and run in the pool. The session is opened lazily in the pool; only its closing (a ROLLBACK of the read
transaction at most) runs on the event loop.
"""

from __future__ import annotations

from collections.abc import AsyncIterator
from typing import Annotated

from fastapi import Depends, Request
from fastapi.security import HTTPAuthorizationCredentials, HTTPBearer
from sqlalchemy.orm import Session

from api.auth import Principal, authenticate
from api.context import ServiceContext
from api.courses import default_assignment
from api.disclosure import Disclosure, disclosure_for
from api.errors import NotAuthenticated
from api.jobs.job_queue import Dispatcher
from api.lti.sessions import SESSION_PARAMETER, SESSION_PREFIX, session_caller
from api.models import Assignment, Student
from api.settings import Settings

SESSION_COOKIE = "gymgrade_token"

bearer_scheme = HTTPBearer(
    auto_error=False,
    description="The instructor's token (GYMGRADE_INSTRUCTOR_TOKEN) or a student's from POST /students.",
)


async def get_context(request: Request) -> ServiceContext:
    """The service context made at start-up."""
    context: ServiceContext = request.app.state.context
    return context


ContextDep = Annotated[ServiceContext, Depends(get_context)]


async def get_settings(context: ContextDep) -> Settings:
    """The service settings."""
    return context.settings


SettingsDep = Annotated[Settings, Depends(get_settings)]


async def get_dispatcher(context: ContextDep) -> Dispatcher:
    """Who tells the workers about a new job (Celery tasks, or nothing for the polling workers)."""
    return context.dispatcher


DispatcherDep = Annotated[Dispatcher, Depends(get_dispatcher)]


async def get_session(context: ContextDep) -> AsyncIterator[Session]:
    """A database session for one request (made lazily: it connects on first use, in the route's thread)."""
    with context.sessions() as session:
        yield session


SessionDep = Annotated[Session, Depends(get_session)]


def get_caller(
    session: SessionDep,
    settings: SettingsDep,
    credentials: Annotated[HTTPAuthorizationCredentials | None, Depends(bearer_scheme)],
) -> Principal:
    """The caller identified by the bearer token (raises NotAuthenticated)."""
    return authenticate(session, settings, credentials.credentials if credentials else None)


CallerDep = Annotated[Principal, Depends(get_caller)]


def get_assignment(session: SessionDep) -> Assignment:
    """The assignment the request is about: the embedded default's."""
    return default_assignment(session)


AssignmentDep = Annotated[Assignment, Depends(get_assignment)]


async def get_disclosure(caller: CallerDep, assignment: AssignmentDep) -> Disclosure:
    """What the caller may see of the assignment's reports: everything (staff) or the student's view."""
    return disclosure_for(caller, assignment)


DisclosureDep = Annotated[Disclosure, Depends(get_disclosure)]


async def get_instructor(caller: CallerDep) -> Principal:
    """The caller, who must be the instructor."""
    caller.require_instructor()
    return caller


InstructorDep = Annotated[Principal, Depends(get_instructor)]


async def get_student(caller: CallerDep) -> Student:
    """The calling student (the instructor is refused)."""
    return caller.require_student()


StudentDep = Annotated[Student, Depends(get_student)]


def get_page_caller(request: Request, session: SessionDep, settings: SettingsDep) -> Principal | None:
    """The web page's signed-in caller (from the session cookie, or an LTI launch's session carried in the
    page's links), or None when signed out."""
    launched = request.query_params.get(SESSION_PARAMETER, "")
    if launched.startswith(SESSION_PREFIX):
        caller = session_caller(session, launched)
        request.state.lti_caller = caller
        return caller
    token = request.cookies.get(SESSION_COOKIE)
    if not token:
        return None
    try:
        return authenticate(session, settings, token)
    except NotAuthenticated:
        return None


PageCallerDep = Annotated[Principal | None, Depends(get_page_caller)]
