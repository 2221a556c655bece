"""The web pages: sign in with a token, upload, watch the checks complete, read feedback and plots.

An assignment's pages (its home page with the upload form or every submission, upload, a submission's page
and live part, overrides, gradebook) are at ``/`` and ``/ui/...`` for the default assignment (or an LTI
launch's), and the same pages again under ``ASSIGNMENT_PAGES`` for any assignment of any course
(:data:`ASSIGNMENT_PAGE_ROUTES` lists them once); the API's dependencies decide who reaches which."""

from __future__ import annotations

from collections.abc import Callable
from typing import Annotated, Any

from fastapi import APIRouter, Depends, File, Form, Request, UploadFile
from fastapi.responses import RedirectResponse, Response
from sqlalchemy.orm import Session

from api.auth import Principal, authenticate
from api.courses import DEFAULT_COURSE_ID
from api.deps import (
    ASSIGNMENT_PAGES,
    SESSION_COOKIE,
    AnyPageCallerDep,
    ContextDep,
    DispatcherDep,
    PageAssignmentDep,
    PageCallerDep,
    SessionDep,
    SettingsDep,
    get_page_assignment,
    get_page_caller,
    get_scope,
    in_assignment,
)
from api.disclosure import disclosure_for
from api.errors import (
    InvalidRequest,
    LtiRequestInvalid,
    NotAuthenticated,
    NothingGradedYet,
    StudentNotFound,
    SubmissionNotFound,
)
from api.gradebook import gradebook_csv
from api.lti.publisher import publishing_status
from api.lti.roster import import_roster
from api.models import Assignment, JobStatus, LtiLink
from api.overrides import overrides_shown, record_override
from api.settings import Settings
from api.submissions import create_submission, detail, get_submission, list_submissions, summary
from api.uploads import check_upload
from api.web import page, session_query, signed_in

router = APIRouter(include_in_schema=False)
assignment_router = APIRouter(
    prefix=ASSIGNMENT_PAGES, dependencies=[Depends(in_assignment)], include_in_schema=False
)
"""The pages of ``ASSIGNMENT_PAGE_ROUTES`` again, for the assignment their path names."""

FINAL_STATUSES = frozenset({JobStatus.DONE.value, JobStatus.FAILED.value})


def home(
    request: Request,
    session: SessionDep,
    caller: AnyPageCallerDep,
    settings: SettingsDep,
) -> Response:
    """The start page: the sign-in form, or the caller's submissions and the upload form; at ``/``, a caller
    of a course other than the default goes on to the courses' pages (their course's assignments)."""
    if caller is None:
        return page(request, "signin.html", {})
    if "assignment" not in request.path_params and caller.session_token is None and _elsewhere(caller):
        return RedirectResponse("/ui/courses", status_code=303)
    assignment = get_page_assignment(request, session, get_page_caller(request, session, caller))
    return _home(request, session, caller, settings, assignment, None)


def _elsewhere(caller: Principal) -> bool:
    """True for a caller (signed in with a token) of a course other than the default, whose start is the
    courses' pages."""
    return caller.course() not in (None, DEFAULT_COURSE_ID)


@router.post("/ui/lti/roster")
def roster_import(
    request: Request, session: SessionDep, context: ContextDep, caller: PageCallerDep
) -> Response:
    """Import the course roster of the link an instructor launched from (Names and Role Provisioning)."""
    instructor = signed_in(caller)
    instructor.require_instructor()
    link = session.get(LtiLink, instructor.lti_link_id) if instructor.lti_link_id is not None else None
    if link is None:
        raise LtiRequestInvalid(
            "the roster is imported from a launch in the LMS; open the tool from the course"
        )
    found = import_roster(session, link, context.access_tokens)
    return page(request, "roster.html", {"caller": instructor, "found": found})


@router.post("/ui/sign-in")
def sign_in(
    request: Request, session: SessionDep, settings: SettingsDep, token: Annotated[str, Form()] = ""
) -> Response:
    """Check the token and keep it in an HttpOnly, SameSite=Strict cookie; the staff of a course other than
    the default go on to their course among the courses' pages."""
    try:
        caller = authenticate(session, settings, token.strip())
    except NotAuthenticated as error:
        return page(request, "signin.html", {"error": str(error)}, status_code=401)
    response = RedirectResponse("/ui/courses" if _elsewhere(caller) else "/", status_code=303)
    response.set_cookie(
        SESSION_COOKIE, token.strip(), httponly=True, samesite="strict", secure=request.url.scheme == "https"
    )
    return response


@router.post("/ui/sign-out")
def sign_out() -> Response:
    """Forget the session cookie."""
    response = RedirectResponse("/", status_code=303)
    response.delete_cookie(SESSION_COOKIE)
    return response


def upload(
    request: Request,
    session: SessionDep,
    settings: SettingsDep,
    dispatcher: DispatcherDep,
    assignment: PageAssignmentDep,
    caller: PageCallerDep,
    file: Annotated[UploadFile, File()],
) -> Response:
    """Upload from the form, then show the submission's page."""
    student = signed_in(caller).require_student()
    content = file.file.read(settings.max_upload_bytes + 1)
    upload = check_upload(file.filename, content, max_bytes=settings.max_upload_bytes)
    submission = create_submission(session, settings, assignment, student, upload, dispatcher)
    shown = f"{pages_of(request)}/submissions/{submission.id}{session_query(caller)}"
    return RedirectResponse(shown, status_code=303)


def submissionpage(
    request: Request,
    submission_id: int,
    session: SessionDep,
    caller: PageCallerDep,
    assignment: PageAssignmentDep,
) -> Response:
    """A submission's page; its live part is refreshed from the fragment below until grading ends."""
    return _submission(request, "submission.html", session, signed_in(caller), assignment, submission_id)


def submission_fragment(
    request: Request,
    submission_id: int,
    session: SessionDep,
    caller: PageCallerDep,
    assignment: PageAssignmentDep,
) -> Response:
    """The live part of a submission's page: status, finished problems, report."""
    return _submission(request, "_live.html", session, signed_in(caller), assignment, submission_id)


def _submission(
    request: Request,
    template: str,
    session: Session,
    caller: Principal,
    assignment: Assignment,
    submission_id: int,
) -> Response:
    disclosure = disclosure_for(caller, assignment)
    submission = get_submission(session, caller, assignment, submission_id)
    view = detail(submission, disclosure, overrides_shown(session, submission, disclosure))
    context = {"submission": view, "final": view.status in FINAL_STATUSES, "pages": pages_of(request)}
    return page(request, template, context)


def override(
    request: Request,
    session: SessionDep,
    settings: SettingsDep,
    assignment: PageAssignmentDep,
    caller: PageCallerDep,
    student: Annotated[str, Form()] = "",
    problem: Annotated[str, Form()] = "",
    points: Annotated[str, Form()] = "",
    reason: Annotated[str, Form()] = "",
    submission_id: Annotated[str, Form()] = "",
) -> Response:
    """The instructor's override form: kept with who and when, or the reason it was refused."""
    staff = signed_in(caller)
    staff.require_instructor()
    try:
        value = float(points)
        upload = int(submission_id) if submission_id.strip() else None
    except ValueError:
        return _home(
            request,
            session,
            staff,
            settings,
            assignment,
            f"points {points!r} is not a number",
            error=True,
        )
    try:
        record_override(
            session, assignment, student_name=student, problem=problem.strip(), points=value, reason=reason,
            author=staff.name, submission_id=upload,
        )  # fmt: skip
    except (InvalidRequest, NothingGradedYet, StudentNotFound, SubmissionNotFound) as refused:
        return _home(request, session, staff, settings, assignment, str(refused), error=True)
    kept = f"{problem} of {student} set to {value:g}: {reason}"
    return _home(request, session, staff, settings, assignment, kept)


def _home(
    request: Request,
    session: Session,
    caller: Principal,
    settings: Settings,
    assignment: Assignment,
    message: str | None,
    *,
    error: bool = False,
) -> Response:
    """The start page of a signed-in caller, with the outcome of an override when there is one."""
    disclosure = disclosure_for(caller, assignment)
    submissions = [summary(item, disclosure) for item in list_submissions(session, caller, assignment)]
    context = {
        "caller": caller, "submissions": submissions, "max_upload_bytes": settings.max_upload_bytes,
        "lms_scores": publishing_status(session, assignment.course_id) if caller.is_instructor else [],
        "override_message": message, "override_error": error, "pages": pages_of(request),
        "scope": get_scope(request, session) if "assignment" in request.path_params else None,
    }  # fmt: skip
    return page(request, "home.html", context, status_code=422 if error else 200)


def gradebook_download(session: SessionDep, assignment: PageAssignmentDep, caller: PageCallerDep) -> Response:
    """The gradebook for the signed-in instructor."""
    signed_in(caller).require_instructor()
    return Response(
        gradebook_csv(session, assignment),
        media_type="text/csv; charset=utf-8",
        headers={"Content-Disposition": 'attachment; filename="gradebook.csv"'},
    )


ASSIGNMENT_PAGE_ROUTES: tuple[tuple[str, str, Callable[..., Response]], ...] = (
    ("GET", "", home),
    ("POST", "/submissions", upload),
    ("GET", "/submissions/{submission_id}", submissionpage),
    ("GET", "/submissions/{submission_id}/live", submission_fragment),
    ("POST", "/overrides", override),
    ("GET", "/gradebook.csv", gradebook_download),
)
"""An assignment's pages: (method, path under ``/ui`` or ``ASSIGNMENT_PAGES``, page); the default
assignment's home page is ``/``."""

for _method, _path, _endpoint in ASSIGNMENT_PAGE_ROUTES:
    router.add_api_route("/ui" + _path if _path else "/", _endpoint, methods=[_method])
    assignment_router.add_api_route(
        _path, _endpoint, methods=[_method], name=f"{_endpoint.__name__}_of_assignment"
    )


def pages_of(request: Request) -> str:
    """Where the pages of the request's assignment are: ``ASSIGNMENT_PAGES`` for the assignment its path
    names, else ``/ui`` (the default assignment's, or an LTI launch's)."""
    params: dict[str, Any] = request.path_params
    if "assignment" in params:
        return ASSIGNMENT_PAGES.format(course=params["course"], assignment=params["assignment"])
    return "/ui"
