"""Courses, their staff and assignments: the operator creates a course and its first staff; a course's
instructors add staff and assignments. Each course's students, submissions, gradebook and overrides are the
routes of ``students``, ``submissions``, ``gradebook`` and ``overrides`` under ``/courses/{course}`` (and
``/assignments/{assignment}``), wired in ``api.main``."""

from __future__ import annotations

from fastapi import APIRouter, Depends

from api.courses import (
    assignment_values,
    assignments_of,
    courses_of,
    create_assignment,
    create_course,
    create_staff,
)
from api.deps import (
    AnyCallerDep,
    CallerDep,
    CourseDep,
    CourseInstructorDep,
    OperatorDep,
    SessionDep,
    in_course,
)
from api.errors import (
    CourseExists,
    CourseNotFound,
    InstructorOnly,
    InvalidRequest,
    MalformedBody,
    NotAuthenticated,
    OperatorOnly,
    UploadTooLarge,
)
from api.handlers import error_responses
from api.models import Assignment, Course
from api.schemas import (
    AssignmentCreate,
    AssignmentView,
    CourseCreate,
    CourseView,
    StaffCreate,
    StaffCreated,
)
from grader.lab.editions.choice import service_edition

router = APIRouter(tags=["courses"])
course_router = APIRouter(tags=["courses"], prefix="/courses/{course}", dependencies=[Depends(in_course)])
"""The routes of one course (its slug in the path)."""


def _course_view(course: Course) -> CourseView:
    return CourseView(id=course.id, slug=course.slug, title=course.title)


def _assignment_view(course: Course, assignment: Assignment) -> AssignmentView:
    return AssignmentView(
        id=assignment.id,
        course=course.slug,
        slug=assignment.slug,
        title=assignment.title,
        lab=service_edition(assignment.edition, assignment.lab).lab.name,
        edition=assignment.edition,
        seed_policy=assignment.seed_policy,
        release_seeds=assignment.release_seeds,
        due_date=assignment.due_date,
        gradebook_policy=assignment.gradebook_policy,
        late=assignment.late_policy,
    )


@router.post(
    "/courses",
    status_code=201,
    response_model=CourseView,
    responses=error_responses(
        MalformedBody,
        NotAuthenticated,
        OperatorOnly,
        CourseExists,
        UploadTooLarge,
        InvalidRequest,
    ),
)
def post_course(body: CourseCreate, session: SessionDep, _operator: OperatorDep) -> CourseView:
    """Create a course (the operator's); add its first staff with POST /courses/{course}/staff."""
    return _course_view(create_course(session, body.slug, body.title))


@router.get(
    "/courses",
    response_model=list[CourseView],
    responses=error_responses(NotAuthenticated, InvalidRequest),
)
def get_courses(session: SessionDep, caller: AnyCallerDep) -> list[CourseView]:
    """The courses the caller may reach: every one for the operator, else the caller's own."""
    return [_course_view(course) for course in courses_of(session, caller.course())]


@course_router.post(
    "/staff",
    status_code=201,
    response_model=StaffCreated,
    responses=error_responses(
        MalformedBody,
        NotAuthenticated,
        InstructorOnly,
        CourseNotFound,
        UploadTooLarge,
        InvalidRequest,
    ),
)
def post_staff(
    body: StaffCreate, session: SessionDep, _instructor: CourseInstructorDep, course: CourseDep
) -> StaffCreated:
    """Add an instructor or a teaching assistant to the course (the operator, or the course's instructor);
    the token in the response is shown only this once and reaches this course only."""
    staff, token = create_staff(session, course, body.name, body.role)
    return StaffCreated(name=staff.name, role=body.role, token=token)


@course_router.post(
    "/assignments",
    status_code=201,
    response_model=AssignmentView,
    responses=error_responses(
        MalformedBody,
        NotAuthenticated,
        InstructorOnly,
        CourseNotFound,
        CourseExists,
        UploadTooLarge,
        InvalidRequest,
    ),
)
def post_assignment(
    body: AssignmentCreate, session: SessionDep, _instructor: CourseInstructorDep, course: CourseDep
) -> AssignmentView:
    """Add an assignment to the course: the lab and edition its uploads are graded as, its seeds, due date,
    gradebook and late policy. Its routes are under /courses/{course}/assignments/{assignment}."""
    return _assignment_view(course, create_assignment(session, course, assignment_values(body)))


@course_router.get(
    "/assignments",
    response_model=list[AssignmentView],
    responses=error_responses(NotAuthenticated, CourseNotFound, InvalidRequest),
)
def get_assignments(session: SessionDep, _caller: CallerDep, course: CourseDep) -> list[AssignmentView]:
    """The course's assignments, oldest first."""
    return [_assignment_view(course, assignment) for assignment in assignments_of(session, course)]
