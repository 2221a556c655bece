"""POST /students: a course's instructor (or the operator) enrols a student and receives their token; GET
/students: the course's enrolments with their ids, for its staff."""

from __future__ import annotations

from fastapi import APIRouter

from api.deps import CourseDep, CourseInstructorDep, InstructorDep, SessionDep
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
from api.schemas import EnrolmentView, StudentCreate, StudentCreated
from api.students import create_student, enrolments_of

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
    return StudentCreated(id=student.id, name=student.name, token=token)


@router.get(
    "/students",
    response_model=list[EnrolmentView],
    responses=error_responses(NotAuthenticated, InstructorOnly, CourseNotFound, InvalidRequest),
)
def get_students(session: SessionDep, _staff: InstructorDep, course: CourseDep) -> list[EnrolmentView]:
    """The course's enrolments by name, each with the id its overrides and extensions are keyed by."""
    return [
        EnrolmentView(id=student.id, name=student.name, lti=student.lti_user_id is not None)
        for student in enrolments_of(session, course.id)
    ]
