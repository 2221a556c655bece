"""Dependency aliases of the routes: the service context, a database session, and the caller.

Dependencies that do no I/O are ``async`` so that FastAPI does not hop to its thread pool for each of them
(each hop costs about as much as the request's own queries); those that query the database stay synchronous
and run in the pool. The session is opened lazily in the pool; only its closing (a ROLLBACK of the read
transaction at most) runs on the event loop.
"""

from __future__ import annotations

from collections.abc import AsyncIterator
from typing import Annotated

from fastapi import Depends, Path, Request
from fastapi.security import HTTPAuthorizationCredentials, HTTPBearer
from sqlalchemy.orm import Session

from api.auth import Principal, authenticate
from api.context import ServiceContext
from api.courses import Scope, launch_scope, scope_of
from api.disclosure import Disclosure, disclosure_for
from api.errors import NotAuthenticated
from api.jobs.job_queue import Dispatcher
from api.lti.binding import SESSION_COOKIE as BROWSER_COOKIE
from api.lti.sessions import SESSION_PARAMETER, SESSION_PREFIX, session_caller
from api.models import Assignment, Course, Student
from api.schemas import SLUG_PATTERN
from api.settings import Settings

SESSION_COOKIE = "gymgrade_token"

bearer_scheme = HTTPBearer(
    auto_error=False,
    description="The operator's token (GYMGRADE_OPERATOR_TOKEN or GYMGRADE_INSTRUCTOR_TOKEN), a course staff member's from POST /courses/{course}/staff, or a student's from POST /students.",  # noqa: E501
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


COURSE_PREFIX = "/courses/{course}"
ASSIGNMENT_PREFIX = COURSE_PREFIX + "/assignments/{assignment}"
"""Where a course's routes, and one of its assignments' routes, are mounted; the same routes without the
prefix are the embedded default course's and assignment's."""
ASSIGNMENT_PAGES = "/ui" + ASSIGNMENT_PREFIX
"""Where an assignment's web pages are (its home page, upload, reports, overrides and gradebook); the same
pages at ``/`` and ``/ui/...`` are the default assignment's (or an LTI launch's)."""

CoursePath = Annotated[str, Path(pattern=SLUG_PATTERN, description="The course's slug.")]
AssignmentPath = Annotated[
    str, Path(pattern=SLUG_PATTERN, description="The assignment's slug in the course.")
]


async def in_course(course: CoursePath) -> None:
    """Declares (and checks the form of) the ``course`` of a course's routes; :func:`get_scope` reads it."""


async def in_assignment(course: CoursePath, assignment: AssignmentPath) -> None:
    """Declares (and checks the form of) the ``course`` and ``assignment`` of an assignment's routes."""


def get_scope(request: Request, session: SessionDep) -> Scope:
    """The course and assignment the request's path names (the default's without a prefix), looked up once
    per request (raises CourseNotFound)."""
    found: Scope | None = getattr(request.state, "scope", None)
    if found is None:
        found = scope_of(session, request.path_params.get("course"), request.path_params.get("assignment"))
        request.state.scope = found
    return found


def get_any_caller(
    session: SessionDep,
    settings: SettingsDep,
    credentials: Annotated[HTTPAuthorizationCredentials | None, Depends(bearer_scheme)],
) -> Principal:
    """The caller identified by the bearer token, of whatever course (raises NotAuthenticated): for the
    routes of no course (the list of courses, the operator's)."""
    return authenticate(session, settings, credentials.credentials if credentials else None)


AnyCallerDep = Annotated[Principal, Depends(get_any_caller)]


def get_caller(request: Request, session: SessionDep, caller: AnyCallerDep) -> Principal:
    """The caller identified by the bearer token (raises NotAuthenticated), who must be the operator or of the
    course the path names (raises CourseNotFound: another course's is not found)."""
    caller.require_member(get_scope(request, session).course.id)
    return caller


CallerDep = Annotated[Principal, Depends(get_caller)]


async def get_course(request: Request, _caller: CallerDep) -> Course:
    """The course the path names, once the caller is known to be of it."""
    scope: Scope = request.state.scope
    return scope.course


CourseDep = Annotated[Course, Depends(get_course)]


async def get_operator(caller: AnyCallerDep) -> Principal:
    """The caller, who must be the operator."""
    caller.require_operator()
    return caller


OperatorDep = Annotated[Principal, Depends(get_operator)]


async def get_course_instructor(caller: CallerDep) -> Principal:
    """The caller, who must be an instructor of the course the path names, or the operator."""
    caller.require_course_instructor()
    return caller


CourseInstructorDep = Annotated[Principal, Depends(get_course_instructor)]


async def get_assignment(request: Request, _caller: CallerDep) -> Assignment:
    """The assignment the path names (the default's without a prefix), once the caller is known to be of its
    course."""
    scope: Scope = request.state.scope
    if scope.assignment is None:  # a course's own route has no assignment: a route is not mounted so
        raise RuntimeError("an assignment's dependency on a course's route")
    return scope.assignment


AssignmentDep = Annotated[Assignment, Depends(get_assignment)]


async def get_disclosure(caller: CallerDep, assignment: AssignmentDep) -> Disclosure:
    """What the caller may see of the assignment's reports: everything (staff) or the student's view."""
    return disclosure_for(caller, assignment)


DisclosureDep = Annotated[Disclosure, Depends(get_disclosure)]


async def get_instructor(caller: CallerDep) -> Principal:
    """The caller, who must be of the course's staff (an instructor or a TA) or the operator."""
    caller.require_instructor()
    return caller


InstructorDep = Annotated[Principal, Depends(get_instructor)]


async def get_student(caller: CallerDep) -> Student:
    """The calling student (staff and the operator are refused)."""
    return caller.require_student()


StudentDep = Annotated[Student, Depends(get_student)]


def get_any_page_caller(request: Request, session: SessionDep, settings: SettingsDep) -> Principal | None:
    """The web page's signed-in caller (from the session cookie, or an LTI launch's session carried in the
    page's links), of whatever course, or None when signed out: for the pages of no course (the list of
    courses) and those whose course the route checks itself."""
    launched = request.query_params.get(SESSION_PARAMETER, "")
    caller: Principal | None
    if launched.startswith(SESSION_PREFIX):
        caller = session_caller(session, launched, request.cookies.get(BROWSER_COOKIE))
        request.state.lti_caller = caller
        if caller is not None and "course" not in request.path_params:
            # the default pages of a launch are its course's and its link's assignment's
            request.state.scope = launch_scope(session, caller)
    else:
        token = request.cookies.get(SESSION_COOKIE)
        try:
            caller = authenticate(session, settings, token) if token else None
        except NotAuthenticated:
            caller = None
    return caller


AnyPageCallerDep = Annotated[Principal | None, Depends(get_any_page_caller)]


def get_page_caller(request: Request, session: SessionDep, caller: AnyPageCallerDep) -> Principal | None:
    """The web page's signed-in caller (:func:`get_any_page_caller`), or None when signed out. The pages are
    the assignment's their path names (``ASSIGNMENT_PAGES``), else the default course's (an LTI launch's:
    its course's): a caller of another course is refused there (CourseNotFound)."""
    if caller is not None:
        caller.require_member(get_scope(request, session).course.id)
    return caller


PageCallerDep = Annotated[Principal | None, Depends(get_page_caller)]


def get_page_assignment(request: Request, session: SessionDep, _caller: PageCallerDep) -> Assignment:
    """The assignment of the pages: the one their path names, else an LTI launch's link's, else the
    default's (the caller is known first: a launch's session decides the scope of the unprefixed pages)."""
    assignment = get_scope(request, session).assignment
    assert assignment is not None  # the default scope and a launch's have their assignment
    return assignment


PageAssignmentDep = Annotated[Assignment, Depends(get_page_assignment)]
