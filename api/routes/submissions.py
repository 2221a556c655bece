"""Uploading submissions and reading their grading status and reports."""

from __future__ import annotations

from typing import Annotated, Any

from fastapi import APIRouter, File, Query, Request, Response, UploadFile

from api.deps import (
    AssignmentDep,
    CallerDep,
    DisclosureDep,
    DispatcherDep,
    InstructorDep,
    SessionDep,
    SettingsDep,
    StudentDep,
)
from api.errors import (
    CourseNotFound,
    GradingInProgress,
    InstructorOnly,
    InvalidRequest,
    InvalidUpload,
    LengthRequired,
    MalformedBody,
    NotAuthenticated,
    RateLimited,
    StudentNotFound,
    StudentOnly,
    SubmissionNotFound,
    UploadTooLarge,
)
from api.handlers import error_responses
from api.overrides import overrides_shown
from api.schemas import SubmissionAccepted, SubmissionDetail, SubmissionSummary
from api.students import find_enrolment
from api.submissions import create_submission, detail, get_submission, list_submissions, regrade, summary
from api.uploads import check_upload, upload_rules

router = APIRouter(tags=["submissions"])

UPLOAD_OPERATION = "post_submission_submissions_post"
GET_ONE_OPERATION = "get_one_submission_submissions__submission_id__get"
"""The operation ids FastAPI first generated; generated clients name their methods after them."""

ACCEPTED_RESPONSE: dict[str, Any] = {
    "description": "Stored and queued for grading; follow `Location` (or the link) to its status and report.",
    "headers": {
        "Location": {
            "description": "The submission's URL, /submissions/{id}.",
            "required": True,
            "schema": {"type": "string", "format": "uri-reference"},
        }
    },
    "links": {
        "GetSubmission": {
            "operationId": GET_ONE_OPERATION,
            "parameters": {"submission_id": "$response.body#/id"},
            "description": "The new submission's grading status, progress and report.",
        }
    },
}


@router.post(
    "/submissions",
    status_code=202,
    response_model=SubmissionAccepted,
    operation_id=UPLOAD_OPERATION,
    responses={
        202: ACCEPTED_RESPONSE,
        **error_responses(
            MalformedBody,
            NotAuthenticated,
            CourseNotFound,
            StudentOnly,
            LengthRequired,
            UploadTooLarge,
            InvalidRequest,
            InvalidUpload,
            RateLimited,
        ),
    },
)
def post_submission(
    request: Request,
    response: Response,
    session: SessionDep,
    settings: SettingsDep,
    dispatcher: DispatcherDep,
    assignment: AssignmentDep,
    student: StudentDep,
    file: Annotated[UploadFile, File()],
) -> SubmissionAccepted:
    """Upload a file for grading; poll GET /submissions/{id} for the result."""
    content = file.file.read(settings.max_upload_bytes + 1)
    upload = check_upload(file.filename, content, max_bytes=settings.max_upload_bytes)
    submission = create_submission(session, settings, assignment, student, upload, dispatcher)
    response.headers["Location"] = f"{request.url.path}/{submission.id}"  # under the assignment's prefix too
    return SubmissionAccepted(id=submission.id)


@router.get(
    "/submissions/{submission_id}",
    response_model=SubmissionDetail,
    operation_id=GET_ONE_OPERATION,
    responses=error_responses(NotAuthenticated, CourseNotFound, SubmissionNotFound, InvalidRequest),
)
def get_one_submission(
    submission_id: int,
    session: SessionDep,
    assignment: AssignmentDep,
    caller: CallerDep,
    disclosure: DisclosureDep,
) -> SubmissionDetail:
    """A submission's status, the problems finished so far, and its report once done."""
    submission = get_submission(session, caller, assignment, submission_id)
    return detail(submission, disclosure, overrides_shown(session, submission, disclosure))


@router.get(
    "/submissions",
    response_model=list[SubmissionSummary],
    responses=error_responses(NotAuthenticated, CourseNotFound, StudentNotFound, InvalidRequest),
)
def get_submissions(
    session: SessionDep,
    assignment: AssignmentDep,
    caller: CallerDep,
    disclosure: DisclosureDep,
    student: str | None = Query(default=None, description="Instructor only: one student's submissions."),
) -> list[SubmissionSummary]:
    """The caller's submissions, newest first (the instructor sees everyone's)."""
    return [summary(item, disclosure) for item in list_submissions(session, caller, assignment, student)]


def document_upload_rules(openapi: dict[str, Any], max_upload_bytes: int) -> None:
    """Write the upload's rules (:func:`api.uploads.upload_rules`) into the OpenAPI schema, in place.

    Args:
        openapi: The application's OpenAPI schema.
        max_upload_bytes: GYMGRADE_MAX_UPLOAD_BYTES, the limit the schema states.
    """
    content, encoding = upload_rules(max_upload_bytes)
    for path, item in openapi["paths"].items():
        if not path.endswith("/submissions") or "post" not in item:
            continue  # the default assignment's upload, and every assignment's under its prefix
        media = item["post"]["requestBody"]["content"]["multipart/form-data"]
        body_name = media["schema"]["$ref"].rsplit("/", 1)[-1]
        openapi["components"]["schemas"][body_name]["properties"]["file"].update(content)
        media["encoding"] = {"file": encoding}


@router.post(
    "/submissions/{submission_id}/regrade",
    status_code=202,
    response_model=SubmissionAccepted,
    responses=error_responses(
        NotAuthenticated,
        CourseNotFound,
        InstructorOnly,
        SubmissionNotFound,
        GradingInProgress,
        InvalidRequest,
    ),
)
def post_regrade(
    request: Request,
    response: Response,
    submission_id: int,
    session: SessionDep,
    dispatcher: DispatcherDep,
    assignment: AssignmentDep,
    instructor: InstructorDep,
) -> SubmissionAccepted:
    """Grade one upload again on its recorded seed (after a fix to the grader or the configuration); poll
    GET /submissions/{id}. The instructor's overrides stay."""
    regrade(session, [get_submission(session, instructor, assignment, submission_id)], dispatcher)
    response.headers["Location"] = request.url.path.removesuffix("/regrade")
    return SubmissionAccepted(id=submission_id)


@router.post(
    "/students/{name}/regrade",
    status_code=202,
    response_model=list[SubmissionAccepted],
    responses=error_responses(
        NotAuthenticated, CourseNotFound, InstructorOnly, StudentNotFound, GradingInProgress, InvalidRequest
    ),
)
def post_student_regrade(
    name: str,
    session: SessionDep,
    dispatcher: DispatcherDep,
    assignment: AssignmentDep,
    instructor: InstructorDep,
) -> list[SubmissionAccepted]:
    """Grade every upload of one student again, each on its recorded seed; nobody else's is touched."""
    ids = regrade(session, list_submissions(session, instructor, assignment, name), dispatcher)
    return [SubmissionAccepted(id=submission_id) for submission_id in ids]


@router.post(
    "/enrolments/{enrolment}/regrade",
    status_code=202,
    response_model=list[SubmissionAccepted],
    responses=error_responses(
        NotAuthenticated, CourseNotFound, InstructorOnly, StudentNotFound, GradingInProgress, InvalidRequest
    ),
)
def post_enrolment_regrade(
    enrolment: int,
    session: SessionDep,
    dispatcher: DispatcherDep,
    assignment: AssignmentDep,
    instructor: InstructorDep,
) -> list[SubmissionAccepted]:
    """Grade every upload of one enrolment again, each on its recorded seed; nobody else's is touched."""
    student = find_enrolment(session, assignment.course_id, enrolment)
    ids = regrade(session, list_submissions(session, instructor, assignment, enrolment=student), dispatcher)
    return [SubmissionAccepted(id=submission_id) for submission_id in ids]
