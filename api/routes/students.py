"""POST /students: a course's instructor (or the operator) enrols a student and receives their token."""

from __future__ import annotations

from fastapi import APIRouter

from api.deps import CourseDep, CourseInstructorDep, SessionDep
from api.errors import (
    CourseNotFound,
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
        CourseNotFound,
        StudentExists,
        UploadTooLarge,
        InvalidRequest,
        InvalidStudentName,
    ),
)
def post_student(
    body: StudentCreate, session: SessionDep, _instructor: CourseInstructorDep, course: CourseDep
) -> StudentCreated:
    """Enrol a student in the course; the token in the response is shown only this once."""
    student, token = create_student(session, course.id, body.name)
    return StudentCreated(name=student.name, token=token)
