"""POST and GET /students/{name}/overrides: the instructor's last word on a student's score, kept with who
and when. A student's token is refused."""

from __future__ import annotations

from fastapi import APIRouter

from api.deps import AssignmentDep, InstructorDep, SessionDep
from api.errors import (
    CourseNotFound,
    InstructorOnly,
    InvalidRequest,
    MalformedBody,
    NotAuthenticated,
    NothingGradedYet,
    StudentNotFound,
    SubmissionNotFound,
    UploadTooLarge,
)
from api.handlers import error_responses
from api.models import Override
from api.overrides import list_overrides, record_override
from api.schemas import OverrideCreate, OverrideView

router = APIRouter(tags=["overrides"])


def _view(override: Override, student: str) -> OverrideView:
    return OverrideView(
        id=override.id,
        student=student,
        submission_id=override.submission_id,
        problem=override.problem,
        points=override.points,
        reason=override.reason,
        author=override.author,
        created_at=override.created_at,
    )


@router.post(
    "/students/{name}/overrides",
    status_code=201,
    response_model=OverrideView,
    responses=error_responses(
        MalformedBody,
        NotAuthenticated,
        CourseNotFound,
        InstructorOnly,
        StudentNotFound,
        SubmissionNotFound,
        NothingGradedYet,
        UploadTooLarge,
        InvalidRequest,
    ),
)
def post_override(
    name: str, body: OverrideCreate, session: SessionDep, assignment: AssignmentDep, instructor: InstructorDep
) -> OverrideView:
    """Override a student's score for one problem (or their total), with a reason; every gradebook then
    shows it, the machine's verdict and the reason in the row's note."""
    override = record_override(
        session,
        assignment,
        student_name=name,
        problem=body.problem,
        points=body.points,
        reason=body.reason,
        author=instructor.name,
        submission_id=body.submission_id,
    )
    return _view(override, name)


@router.get(
    "/students/{name}/overrides",
    response_model=list[OverrideView],
    responses=error_responses(
        NotAuthenticated, CourseNotFound, InstructorOnly, StudentNotFound, InvalidRequest
    ),
)
def get_overrides(
    name: str, session: SessionDep, assignment: AssignmentDep, _instructor: InstructorDep
) -> list[OverrideView]:
    """Every override of a student, oldest first (the latest per problem and upload counts)."""
    return [_view(override, name) for override in list_overrides(session, assignment, name)]
