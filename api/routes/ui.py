"""The web pages: sign in with a token, upload, watch the checks complete, read feedback and plots."""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, File, Form, Request, UploadFile
from fastapi.responses import RedirectResponse, Response
from sqlalchemy.orm import Session

from api.auth import Principal, authenticate
from api.courses import DEFAULT_COURSE_ID
from api.deps import (
    SESSION_COOKIE,
    ContextDep,
    DispatcherDep,
    PageAssignmentDep,
    PageCallerDep,
    SessionDep,
    SettingsDep,
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

FINAL_STATUSES = frozenset({JobStatus.DONE.value, JobStatus.FAILED.value})


@router.get("/")
def home(
    request: Request,
    session: SessionDep,
    caller: PageCallerDep,
    settings: SettingsDep,
    assignment: PageAssignmentDep,
) -> Response:
    """The start page: the sign-in form, or the caller's submissions and the upload form."""
    if caller is None:
        return page(request, "signin.html", {})
    return _home(request, session, caller, settings, assignment, None)


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
    the default go on to their course's page."""
    try:
        caller = authenticate(session, settings, token.strip())
    except NotAuthenticated as error:
        return page(request, "signin.html", {"error": str(error)}, status_code=401)
    elsewhere = caller.is_instructor and caller.course() not in (None, DEFAULT_COURSE_ID)
    response = RedirectResponse("/ui/courses" if elsewhere else "/", status_code=303)
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


@router.post("/ui/submissions")
def upload(
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
    return RedirectResponse(f"/ui/submissions/{submission.id}{session_query(caller)}", status_code=303)


@router.get("/ui/submissions/{submission_id}")
def submissionpage(
    request: Request,
    submission_id: int,
    session: SessionDep,
    caller: PageCallerDep,
    assignment: PageAssignmentDep,
) -> Response:
    """A submission's page; its live part is refreshed from the fragment below until grading ends."""
    return _submission(request, "submission.html", session, signed_in(caller), assignment, submission_id)


@router.get("/ui/submissions/{submission_id}/live")
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
    return page(request, template, {"submission": view, "final": view.status in FINAL_STATUSES})


@router.post("/ui/overrides")
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
        "override_message": message, "override_error": error,
    }  # fmt: skip
    return page(request, "home.html", context, status_code=422 if error else 200)


@router.get("/ui/gradebook.csv")
def gradebook_download(session: SessionDep, assignment: PageAssignmentDep, caller: PageCallerDep) -> Response:
    """The gradebook for the signed-in instructor."""
    signed_in(caller).require_instructor()
    return Response(
        gradebook_csv(session, assignment),
        media_type="text/csv; charset=utf-8",
        headers={"Content-Disposition": 'attachment; filename="gradebook.csv"'},
    )
