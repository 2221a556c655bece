"""POST /students: the instructor creates a student and receives their token."""

from __future__ import annotations

from fastapi import APIRouter

from api.deps import AssignmentDep, InstructorDep, SessionDep
from api.errors import (
    InstructorOnly,
    InvalidRequest,
    InvalidStudentName,
    MalformedBody,
    NotAuthenticated,
    StudentExists,
    UploadTooLarge,
)
from api.handlers import error_responses
from api.schemas import StudentCreate, StudentCreated
from api.students import create_student

router = APIRouter(tags=["students"])


@router.post(
    "/students",
    status_code=201,
    response_model=StudentCreated,
    responses=error_responses(
        MalformedBody,
        NotAuthenticated,
        InstructorOnly,
        StudentExists,
        UploadTooLarge,
        InvalidRequest,
        InvalidStudentName,
    ),
)
def post_student(
    body: StudentCreate, session: SessionDep, assignment: AssignmentDep, _instructor: InstructorDep
) -> StudentCreated:
    """Create a student; the token in the response is shown only this once."""
    student, token = create_student(session, assignment.course_id, body.name)
    return StudentCreated(name=student.name, token=token)
