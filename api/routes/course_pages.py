"""The web pages of courses: the operator lists and creates courses; a course's staff see its assignments and
staff, and its instructors (and the operator) add assignments and staff; its students see its assignments.
Each assignment links to its own pages (``api.routes.ui``, under ``ASSIGNMENT_PAGES``). The same rules and
functions as the API's ``/courses`` routes (``api.courses``), the same sign-in as every page
(``api.routes.ui``)."""

from __future__ import annotations

import tomllib
from typing import Annotated, Any, TypeVar

from fastapi import APIRouter, Form, Request
from fastapi.responses import RedirectResponse, Response
from pydantic import BaseModel, ValidationError
from sqlalchemy.orm import Session

from api.auth import Principal, StaffRole
from api.courses import (
    assignment_values,
    assignments_of,
    courses_of,
    create_assignment,
    create_course,
    create_staff,
    scope_of,
    staff_of,
)
from api.deps import ASSIGNMENT_PAGES, AnyPageCallerDep, CoursePath, SessionDep
from api.errors import CourseExists, InvalidRequest
from api.handlers import status_of
from api.models import Assignment, Course
from api.schemas import SLUG_PATTERN, AssignmentCreate, CourseCreate, EditionName, StaffCreate
from api.web import page, session_query, signed_in
from grader.lab.assignment import config_from_data, load_config
from grader.lab.editions.choice import service_edition

router = APIRouter(include_in_schema=False)

Model = TypeVar("Model", bound=BaseModel)

FIELD_LABELS = {
    "slug": "Short name",
    "title": "Title",
    "name": "Name",
    "role": "Role",
    "edition": "Edition",
    "seed_policy": "Seeds",
    "due_date": "Due date",
    "gradebook_policy": "Gradebook keeps",
}
"""How the forms name each field of the API's models in their error messages."""


@router.get("/ui/courses")
def courses_page(request: Request, session: SessionDep, caller: AnyPageCallerDep) -> Response:
    """The courses the signed-in caller may reach (a staff member's or student's own, the operator's every
    one), and the operator's form for a new one."""
    return _courses(request, session, signed_in(caller))


@router.post("/ui/courses")
def course_form(
    request: Request,
    session: SessionDep,
    caller: AnyPageCallerDep,
    slug: Annotated[str, Form()] = "",
    title: Annotated[str, Form()] = "",
) -> Response:
    """Create a course (the operator's), then show its page, where its first staff are added."""
    operator = _staff(caller)
    operator.require_operator()
    try:
        body = _parsed(CourseCreate, {"slug": slug.strip(), "title": title})
        course = create_course(session, body.slug, body.title)
    except (InvalidRequest, CourseExists) as refused:
        return _courses(request, session, operator, refused, {"slug": slug, "title": title})
    return RedirectResponse(f"/ui/courses/{course.slug}{session_query(operator)}", status_code=303)


@router.get("/ui/courses/{course}")
def course_page(
    request: Request, course: CoursePath, session: SessionDep, caller: AnyPageCallerDep
) -> Response:
    """A course: its assignments (each a link to its pages) and, for its staff, its staff and for its
    instructors the forms that add them."""
    member = signed_in(caller)
    return _course(request, session, member, _course_of(session, member, course))


@router.post("/ui/courses/{course}/assignments")
def assignment_form(
    request: Request,
    course: CoursePath,
    session: SessionDep,
    caller: AnyPageCallerDep,
    slug: Annotated[str, Form()] = "",
    title: Annotated[str, Form()] = "",
    edition: Annotated[str, Form()] = "",
    seed_policy: Annotated[str, Form()] = "random",
    release_seeds: Annotated[str, Form()] = "",
    due_date: Annotated[str, Form()] = "",
    gradebook_policy: Annotated[str, Form()] = "latest",
) -> Response:
    """Add an assignment to the course (its instructors and the operator), then show the course again."""
    instructor = _staff(caller)
    found = _course_of(session, instructor, course)
    instructor.require_course_instructor()
    written = {
        "slug": slug, "title": title, "edition": edition, "seed_policy": seed_policy,
        "release_seeds": release_seeds, "due_date": due_date, "gradebook_policy": gradebook_policy,
    }  # fmt: skip
    fields: dict[str, Any] = {
        "slug": slug.strip(), "title": title, "edition": edition or None, "seed_policy": seed_policy,
        "release_seeds": release_seeds == "on", "due_date": due_date or None,
        "gradebook_policy": gradebook_policy,
    }  # fmt: skip
    try:
        assignment = create_assignment(session, found, assignment_values(_parsed(AssignmentCreate, fields)))
    except (InvalidRequest, CourseExists) as refused:
        return _course(request, session, instructor, found, assignment_error=refused, written=written)
    notice = f"Assignment {assignment.slug} added."
    return _course(request, session, instructor, found, notice=notice)


@router.post("/ui/courses/{course}/staff")
def staff_form(
    request: Request,
    course: CoursePath,
    session: SessionDep,
    caller: AnyPageCallerDep,
    name: Annotated[str, Form()] = "",
    role: Annotated[str, Form()] = StaffRole.INSTRUCTOR.value,
) -> Response:
    """Add an instructor or a teaching assistant (the course's instructors and the operator); their token is
    shown on the page that answers, this once."""
    instructor = _staff(caller)
    found = _course_of(session, instructor, course)
    instructor.require_course_instructor()
    try:
        body = _parsed(StaffCreate, {"name": name, "role": role})
    except InvalidRequest as refused:
        return _course(request, session, instructor, found, staff_error=refused, written={"name": name})
    staff, token = create_staff(session, found, body.name, body.role)
    response = _course(request, session, instructor, found, created=(staff.name, body.role, token))
    response.headers["Cache-Control"] = "no-store"  # the token is on this page only
    return response


def _staff(caller: Principal | None) -> Principal:
    staff = signed_in(caller)
    staff.require_instructor()
    return staff


def _course_of(session: Session, caller: Principal, slug: str) -> Course:
    course = scope_of(session, slug, None).course
    caller.require_member(course.id)
    return course


def _parsed(model: type[Model], fields: dict[str, Any]) -> Model:
    """``fields`` read as the API reads its body, or InvalidRequest naming each field as the form does."""
    try:
        return model.model_validate(fields)
    except ValidationError as error:
        problems = [
            (["body", *problem["loc"]], problem["msg"], problem["type"]) for problem in error.errors()
        ]
        message = "; ".join(
            f"{FIELD_LABELS.get(str(problem['loc'][0]), problem['loc'][0]) if problem['loc'] else 'form'}: "
            f"{_readable(problem['msg'])}"
            for problem in error.errors()
        )
        raise InvalidRequest(message, problems) from None


def _readable(message: str) -> str:
    if SLUG_PATTERN in message:
        return "lower-case letters, digits and dashes (at most 64, the first a letter or digit), e.g. rl-2026"
    return message


def _courses(
    request: Request,
    session: Session,
    caller: Principal,
    refused: InvalidRequest | CourseExists | None = None,
    written: dict[str, str] | None = None,
) -> Response:
    context = {
        "caller": caller, "courses": courses_of(session, caller.course()), "error": refused,
        "written": written or {},
    }  # fmt: skip
    return page(request, "courses.html", context, status_code=status_of(refused) if refused else 200)


def _course(
    request: Request,
    session: Session,
    caller: Principal,
    course: Course,
    *,
    assignment_error: InvalidRequest | CourseExists | None = None,
    staff_error: InvalidRequest | None = None,
    written: dict[str, str] | None = None,
    notice: str | None = None,
    created: tuple[str, str, str] | None = None,
) -> Response:
    refused = assignment_error or staff_error
    context = {
        "caller": caller,
        "course": course,
        "assignments": [
            _assignment_row(course, assignment) for assignment in assignments_of(session, course)
        ],
        "staff": staff_of(session, course) if caller.is_instructor else [],
        "manages": caller.manages_course,
        "editions": [edition.value for edition in EditionName],
        "assignment_error": assignment_error,
        "staff_error": staff_error,
        "written": written or {},
        "notice": notice,
        "created": created,
    }
    return page(request, "course.html", context, status_code=status_of(refused) if refused else 200)


def _assignment_row(course: Course, assignment: Assignment) -> dict[str, Any]:
    """What the course page shows of an assignment: where its pages are, its settings and each problem's
    points and visibility."""
    choice = service_edition(assignment.edition, assignment.lab)
    if assignment.config_toml is not None:
        config = config_from_data(
            tomllib.loads(assignment.config_toml), where=f"assignment {assignment.slug}"
        )
    else:
        config = load_config(choice.config)
    problems = [
        {"id": problem_id, "points": settings.points, "visibility": settings.visibility}
        for problem_id, settings in config.problems.items()
        if settings.enabled
    ]
    return {
        "row": assignment,
        "lab": choice.lab.name,
        "edition": choice.edition.name,
        "problems": problems,
        "points": sum(problem["points"] for problem in problems),
        "pages": ASSIGNMENT_PAGES.format(course=course.slug, assignment=assignment.slug),
    }
