"""Courses, their staff and assignments: made by the operator (and a course's instructors), found from a
request's path (:func:`scope_of`), the embedded default kept as the settings say, and what an assignment's
row means to the rest of the service (its late policy with the extensions of its enrolments).

The embedded default is course 1 (``default``) with assignment 1 (``default``): what `gymgrade serve`
with ``GYMGRADE_INSTRUCTOR_TOKEN`` serves, and what a database of before courses migrated into. Its lab,
edition, seed policy, seed release, due date, gradebook policy and late policy are the settings'
(``GYMGRADE_LAB``, ``GYMGRADE_EDITION``, ...): :func:`sync_default` writes them into its row at every
start, so the row is what grading, disclosure and the gradebook read for every assignment alike.
"""

from __future__ import annotations

from dataclasses import dataclass
from datetime import UTC, datetime
from typing import Any

from sqlalchemy import select
from sqlalchemy.exc import IntegrityError
from sqlalchemy.orm import Session

from api.auth import Principal
from api.errors import CourseExists, CourseNotFound, InvalidRequest, StaffNotFound
from api.models import Assignment, Course, Extension, LtiLink, Staff, Student
from api.schemas import AssignmentCreate
from api.security import new_token, token_digest
from api.settings import GradebookPolicy, SeedPolicy, Settings
from api.students import MAX_ID, printable
from grader.classroom.late import LatePolicy, read_late_policy
from grader.seeds import held_out_seed

DEFAULT_COURSE_ID = 1
DEFAULT_ASSIGNMENT_ID = 1
"""The embedded default's rows (made by migration 0004)."""


def default_values(settings: Settings) -> dict[str, Any]:
    """The default assignment's columns as the settings give them."""
    late = read_late_policy(settings.late_policy) if settings.late_policy is not None else None
    return {
        "lab": settings.lab,
        "edition": settings.edition,
        "seed_policy": settings.seed_policy.value,
        "seed": settings.seed,
        "release_seeds": settings.release_seeds,
        "due_date": settings.due_date.astimezone(UTC).replace(tzinfo=None) if settings.due_date else None,
        "gradebook_policy": settings.gradebook_policy.value,
        "late_policy": late.model_dump(mode="json") if late is not None else None,
    }


def sync_default(session: Session, settings: Settings) -> Assignment:
    """Bring the default assignment's row to the settings (written only where it differs: several processes
    start at once).

    Args:
        session: A database session (committed here when something changed).
        settings: The service settings.

    Returns:
        The default assignment.
    """
    assignment = session.get_one(Assignment, DEFAULT_ASSIGNMENT_ID)
    changed = False
    for column, value in default_values(settings).items():
        if getattr(assignment, column) != value:
            setattr(assignment, column, value)
            changed = True
    if changed:
        session.commit()
    return assignment


def default_assignment(session: Session) -> Assignment:
    """The embedded default assignment (course 1's assignment 1)."""
    return session.get_one(Assignment, DEFAULT_ASSIGNMENT_ID)


def seed_policy_of(assignment: Assignment) -> SeedPolicy:
    """How the assignment's grading seeds are chosen."""
    return SeedPolicy(assignment.seed_policy)


def gradebook_policy_of(assignment: Assignment) -> GradebookPolicy:
    """Which graded submission of each enrolment the assignment's gradebook (and the LMS) keeps."""
    return GradebookPolicy(assignment.gradebook_policy)


def due_date_of(assignment: Assignment) -> datetime | None:
    """The due date of the assignment's ``after_due_date`` problems (aware, UTC), None when unset."""
    return assignment.due_date.replace(tzinfo=UTC) if assignment.due_date is not None else None


def identity(student_id: int) -> str:
    """How an enrolment is named to ``grader.classroom``'s decisions (overrides, extensions): its id."""
    return str(student_id)


def late_policy_of(session: Session, assignment: Assignment) -> LatePolicy | None:
    """The assignment's late policy, its extensions keyed by enrolment (:func:`identity`), None without one.

    The extensions are the assignment's ``extensions`` rows; a default assignment's
    ``GYMGRADE_LATE_POLICY`` file may still name students (``[late.extensions]``, as before courses): each
    name is read as the course's enrolment of that name, and a row of the same enrolment wins.
    """
    if assignment.late_policy is None:
        return None
    table = dict(assignment.late_policy)
    named: dict[str, Any] = table.pop("extensions", None) or {}
    extensions: dict[str, Any] = {}
    if named:
        students = session.execute(
            select(Student.id, Student.name).where(
                Student.course_id == assignment.course_id, Student.name.in_(list(named))
            )
        ).all()
        extensions.update({identity(row.id): named[row.name] for row in students})
    for row in session.scalars(select(Extension).where(Extension.assignment_id == assignment.id)):
        extensions[identity(row.student_id)] = row.due.replace(tzinfo=UTC).isoformat()
    return LatePolicy.model_validate({**table, "extensions": extensions})


@dataclass(frozen=True)
class Scope:
    """What a request is about: a course, and one of its assignments (None on a course's own routes)."""

    course: Course
    assignment: Assignment | None


def scope_of(session: Session, course_slug: str | None, assignment_slug: str | None) -> Scope:
    """The course and assignment a request's path names; the embedded default's when it names none.

    Raises:
        CourseNotFound: No course, or no assignment of it, has that slug.
    """
    if course_slug is None:
        return Scope(session.get_one(Course, DEFAULT_COURSE_ID), default_assignment(session))
    course = session.scalars(select(Course).where(Course.slug == course_slug)).first()
    if course is None:
        raise CourseNotFound(f"no course {course_slug!r} among yours; list yours with GET /courses")
    if assignment_slug is None:
        return Scope(course, None)
    assignment = session.scalars(
        select(Assignment).where(Assignment.course_id == course.id, Assignment.slug == assignment_slug)
    ).first()
    if assignment is None:
        raise CourseNotFound(
            f"no assignment {assignment_slug!r} in course {course_slug!r}; list them with GET /courses/{course_slug}/assignments"  # noqa: E501
        )
    return Scope(course, assignment)


def create_course(session: Session, slug: str, title: str) -> Course:
    """Make a course (committed).

    Raises:
        CourseExists: The slug is taken.
    """
    course = Course(slug=slug, title=printable(title, slug))
    session.add(course)
    _commit_new(session, f"a course with slug {slug!r} exists already; choose another slug")
    return course


def create_staff(session: Session, course: Course, name: str, role: str) -> tuple[Staff, str]:
    """Add an instructor or teaching assistant to a course, with their token (committed).

    Returns:
        The staff row and the token in clear (never stored; only its SHA-256 is).
    """
    token = new_token()
    staff = Staff(
        course_id=course.id, role=role, name=printable(name, role), token_sha256=token_digest(token)
    )
    session.add(staff)
    session.commit()
    return staff, token


def assignment_values(body: AssignmentCreate) -> dict[str, Any]:
    """The columns of a new assignment as ``body`` asks (for :func:`create_assignment`): its lab follows from
    its edition, a fixed policy without a seed draws a secret one, dates are kept in UTC.

    Raises:
        InvalidRequest: A date falls outside the years 1 to 9999 once in UTC.
    """
    values = body.model_dump(exclude={"late", "due_date", "edition", "seed", "config"})
    values["lab"], values["edition"] = None, body.edition.value if body.edition is not None else None
    values["config_toml"] = body.config
    values["seed"] = body.seed if body.seed is not None else held_out_seed(2**31 - 1)
    try:
        values["due_date"] = body.due_date.astimezone(UTC).replace(tzinfo=None) if body.due_date else None
        values["late_policy"] = body.late.model_dump(mode="json") if body.late is not None else None
        if body.late is not None:
            body.late.due.astimezone(UTC)
    except OverflowError:
        message = "a date in UTC falls outside the years 1 to 9999; give a date within them"
        raise InvalidRequest(message, [(["body", "due_date"], message, "value_error")]) from None
    return values


def staff_of(session: Session, course: Course) -> list[Staff]:
    """The course's staff, oldest first."""
    return list(session.scalars(select(Staff).where(Staff.course_id == course.id).order_by(Staff.id)))


def find_staff(session: Session, course: Course, staff_id: int) -> Staff:
    """The course's staff member with id ``staff_id``.

    Raises:
        StaffNotFound: The course has no staff member of that id.
    """
    staff = session.get(Staff, staff_id) if 1 <= staff_id <= MAX_ID else None
    if staff is None or staff.course_id != course.id:
        raise StaffNotFound(
            f"no staff member {staff_id} in course {course.slug!r}; list them with GET /courses/{course.slug}/staff"  # noqa: E501
        )
    return staff


def new_staff_token(session: Session, staff: Staff) -> str:
    """Give a staff member a new API token, the old one (if any) no longer accepted (committed).

    Returns:
        The token in clear (never stored; only its SHA-256 is).
    """
    token = new_token()
    staff.token_sha256 = token_digest(token)
    session.commit()
    return token


def revoke_staff_token(session: Session, staff: Staff) -> None:
    """Revoke a staff member's API token: its digest is forgotten, so the next request with it is nobody's
    (committed). Their LTI launches, if any, still sign them in."""
    staff.token_sha256 = None
    session.commit()


def create_assignment(session: Session, course: Course, values: dict[str, Any]) -> Assignment:
    """Add an assignment to a course (committed): ``values`` are its columns but ``course_id``.

    Raises:
        InvalidRequest: The lab or edition is unknown, or the edition is not of the lab.
        CourseExists: The course has an assignment with that slug.
    """
    from grader.lab.editions.choice import service_edition  # the packs import the checks: only here
    from grader.lab.editions.errors import LabConflict, UnknownEdition, UnknownLab

    if values.get("config_toml") is not None:
        values = {**values, **_configured(values["config_toml"], values.get("edition"))}
    try:
        service_edition(values.get("edition"), values.get("lab"))
    except (UnknownEdition, UnknownLab, LabConflict) as error:
        field = "edition" if isinstance(error, UnknownEdition) else "lab"
        raise InvalidRequest(str(error), [(["body", field], str(error), "value_error")]) from None
    assignment = Assignment(
        course_id=course.id, **{**values, "title": printable(values["title"], values["slug"])}
    )
    session.add(assignment)
    _commit_new(
        session, f"course {course.slug!r} has an assignment {values['slug']!r} already; choose another slug"
    )
    return assignment


def _configured(text: str, edition: str | None) -> dict[str, Any]:
    """An assignment's configuration checked as ``gymgrade grade --config`` checks a file, and the edition it
    grades: ``config_toml`` and ``edition`` of the assignment's row.

    The configuration's edition is the assignment's: one that names none (``edition``, ``lab``) is given the
    assignment's ``edition`` (its first line); one that names another is refused; without ``edition`` the
    assignment grades the configuration's.

    Raises:
        InvalidRequest: The text is not an assignment configuration, or grades another edition.
    """
    import tomllib

    from grader.errors import ConfigError
    from grader.lab.assignment import config_from_data
    from grader.lab.editions.errors import LabConflict, UnknownEdition, UnknownLab

    def refused(message: str) -> InvalidRequest:
        return InvalidRequest(message, [(["body", "config"], message, "value_error")])

    try:
        data = tomllib.loads(text)
        if edition is not None and data.get("edition") is None and data.get("lab") is None:
            text = f'edition = "{edition}"\n' + text
            data = {**data, "edition": edition}
        config = config_from_data(data, where="the assignment's config")
    except tomllib.TOMLDecodeError as error:
        raise refused(f"config is not TOML ({error}): send an assignment configuration file's text") from None
    except RecursionError:  # tomllib reads nested arrays and tables recursively
        raise refused("config nests arrays or tables too deeply to be an assignment configuration") from None
    except (ConfigError, UnknownEdition, UnknownLab, LabConflict) as error:
        raise refused(f"config is not an assignment configuration: {error}") from None
    if edition is not None and config.edition != edition:
        raise refused(
            f"config grades edition {config.edition!r}, the assignment edition {edition!r}: "
            "make them agree, or leave one of them out"
        )
    return {"config_toml": text, "edition": config.edition}


def _commit_new(session: Session, taken: str) -> None:
    try:
        session.commit()
    except IntegrityError:
        session.rollback()
        raise CourseExists(taken) from None


def courses_of(session: Session, course_id: int | None) -> list[Course]:
    """Every course (the operator's, ``course_id`` None), or the one course of a staff member or student."""
    query = select(Course).order_by(Course.id)
    if course_id is not None:
        query = query.where(Course.id == course_id)
    return list(session.scalars(query))


def assignments_of(session: Session, course: Course) -> list[Assignment]:
    """The course's assignments, oldest first."""
    return list(
        session.scalars(select(Assignment).where(Assignment.course_id == course.id).order_by(Assignment.id))
    )


def launch_scope(session: Session, caller: Principal) -> Scope:
    """The course and assignment of an LTI launch's pages: its course, and the assignment of the link it was
    launched from (without one, the course's first assignment).

    Raises:
        CourseNotFound: The course has no assignment yet.
    """
    course = session.get_one(Course, caller.course() or DEFAULT_COURSE_ID)
    assignment = None
    if caller.lti_link_id is not None:
        link = session.get(LtiLink, caller.lti_link_id)
        assignment = session.get(Assignment, link.assignment_id) if link is not None else None
    if assignment is None:
        first = assignments_of(session, course)
        if not first:
            raise CourseNotFound("this course has no assignment yet: open one from the LMS")
        assignment = first[0]
    return Scope(course, assignment)
