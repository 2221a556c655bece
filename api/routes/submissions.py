"""Uploading submissions and reading their grading status and reports."""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, File, Query, UploadFile

from api.deps import CallerDep, DisclosureDep, SessionDep, SettingsDep, StudentDep
from api.schemas import ErrorBody, SubmissionAccepted, SubmissionDetail, SubmissionSummary
from api.submissions import create_submission, detail, get_submission, list_submissions, summary
from api.uploads import check_upload

router = APIRouter(tags=["submissions"])


@router.post(
    "/submissions",
    status_code=202,
    response_model=SubmissionAccepted,
    responses={
        401: {"model": ErrorBody},
        403: {"model": ErrorBody},
        411: {"model": ErrorBody},
        413: {"model": ErrorBody},
        422: {"model": ErrorBody},
        429: {"model": ErrorBody},
    },
)
def post_submission(
    session: SessionDep,
    settings: SettingsDep,
    student: StudentDep,
    file: Annotated[UploadFile, File(description="The student's opengym.py (UTF-8 Python source).")],
) -> SubmissionAccepted:
    """Upload a file for grading; poll GET /submissions/{id} for the result."""
    content = file.file.read(settings.max_upload_bytes + 1)
    upload = check_upload(file.filename, content, max_bytes=settings.max_upload_bytes)
    submission = create_submission(session, settings, student, upload)
    return SubmissionAccepted(id=submission.id)


@router.get(
    "/submissions/{submission_id}",
    response_model=SubmissionDetail,
    responses={401: {"model": ErrorBody}, 404: {"model": ErrorBody}},
)
def get_one_submission(
    submission_id: int, session: SessionDep, caller: CallerDep, disclosure: DisclosureDep
) -> SubmissionDetail:
    """A submission's status, the problems finished so far, and its report once done."""
    return detail(get_submission(session, caller, submission_id), disclosure)


@router.get(
    "/submissions",
    response_model=list[SubmissionSummary],
    responses={401: {"model": ErrorBody}, 404: {"model": ErrorBody}},
)
def get_submissions(
    session: SessionDep,
    caller: CallerDep,
    disclosure: DisclosureDep,
    student: str | None = Query(default=None, description="Instructor only: one student's submissions."),
) -> list[SubmissionSummary]:
    """The caller's submissions, newest first (the instructor sees everyone's)."""
    return [summary(item, disclosure) for item in list_submissions(session, caller, student)]
