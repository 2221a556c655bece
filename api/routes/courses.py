"""Courses, their staff and assignments: the operator creates a course and its first staff; a course's
instructors add staff and assignments. Each course's students, submissions, gradebook and overrides are the
routes of ``students``, ``submissions``, ``gradebook`` and ``overrides`` under ``/courses/{course}`` (and
``/assignments/{assignment}``), wired in ``api.main``."""

from __future__ import annotations

from fastapi import APIRouter, Depends, Response

from api.courses import (
    assignment_values,
    assignments_of,
    courses_of,
    create_assignment,
    create_course,
    create_staff,
    find_staff,
    new_staff_token,
    revoke_staff_token,
    staff_of,
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
    StaffNotFound,
    UploadTooLarge,
)
from api.handlers import error_responses
from api.models import Assignment, Course, Staff
from api.schemas import (
    AssignmentCreate,
    AssignmentView,
    CourseCreate,
    CourseView,
    StaffCreate,
    StaffCreated,
    StaffView,
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
        config=assignment.config_toml,
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
    return StaffCreated(id=staff.id, name=staff.name, role=body.role, token=token)


def _staff_view(staff: Staff) -> StaffView:
    return StaffView(
        id=staff.id,
        name=staff.name,
        role=staff.role,  # type: ignore[arg-type]  # a StaffRole value, checked by StaffView
        token=staff.token_sha256 is not None,
        lti=staff.lti_user_id is not None,
    )


@course_router.get(
    "/staff",
    response_model=list[StaffView],
    responses=error_responses(NotAuthenticated, InstructorOnly, CourseNotFound, InvalidRequest),
)
def get_staff(session: SessionDep, _instructor: CourseInstructorDep, course: CourseDep) -> list[StaffView]:
    """The course's staff, oldest first, with whether each has an API token (never the token)."""
    return [_staff_view(staff) for staff in staff_of(session, course)]


@course_router.post(
    "/staff/{staff_id}/token",
    status_code=201,
    response_model=StaffCreated,
    responses=error_responses(
        NotAuthenticated, InstructorOnly, CourseNotFound, StaffNotFound, InvalidRequest
    ),
)
def post_staff_token(
    staff_id: int, session: SessionDep, _instructor: CourseInstructorDep, course: CourseDep
) -> StaffCreated:
    """A new API token for a staff member (their old one stops working), shown only this once."""
    staff = find_staff(session, course, staff_id)
    token = new_staff_token(session, staff)
    return StaffCreated(id=staff.id, name=staff.name, role=staff.role, token=token)  # type: ignore[arg-type]


@course_router.delete(
    "/staff/{staff_id}/token",
    status_code=204,
    response_class=Response,
    responses=error_responses(
        NotAuthenticated, InstructorOnly, CourseNotFound, StaffNotFound, InvalidRequest
    ),
)
def delete_staff_token(
    staff_id: int, session: SessionDep, _instructor: CourseInstructorDep, course: CourseDep
) -> Response:
    """Revoke a staff member's API token: a request with it is refused from now on (401). Nothing to revoke
    is no error."""
    revoke_staff_token(session, find_staff(session, course, staff_id))
    return Response(status_code=204)


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
    """Add an assignment to the course: the lab and edition its uploads are graded as, its configuration
    (points, visibility), seeds, due date, gradebook and late policy. Its routes are under
    /courses/{course}/assignments/{assignment}."""
    return _assignment_view(course, create_assignment(session, course, assignment_values(body)))


@course_router.get(
    "/assignments",
    response_model=list[AssignmentView],
    responses=error_responses(NotAuthenticated, CourseNotFound, InvalidRequest),
)
def get_assignments(session: SessionDep, _caller: CallerDep, course: CourseDep) -> list[AssignmentView]:
    """The course's assignments, oldest first."""
    return [_assignment_view(course, assignment) for assignment in assignments_of(session, course)]
