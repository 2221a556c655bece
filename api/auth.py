"""Who is calling: the operator (one configured token), a course's staff (instructor or teaching assistant,
a stored token digest) or a course's student (a stored token digest), and what each may reach.

The operator is the service's: ``GYMGRADE_OPERATOR_TOKEN`` (or ``GYMGRADE_INSTRUCTOR_TOKEN``, its name for a
single course), which creates courses and their first staff and acts as the instructor of every course (the
embedded default course's, as before courses). A staff member or student belongs to one course; anything of
another course is not found for them. A staff member's API token is revoked by forgetting its digest.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum

from sqlalchemy import select
from sqlalchemy.orm import Session

from api.errors import CourseNotFound, InstructorOnly, NotAuthenticated, OperatorOnly, StudentOnly
from api.models import Staff, Student
from api.security import same_secret, token_digest
from api.settings import Settings


class StaffRole(StrEnum):
    """A course's staff: the instructor manages it; a teaching assistant sees and grades."""

    INSTRUCTOR = "instructor"
    TA = "ta"


@dataclass(frozen=True)
class Principal:
    """The authenticated caller; ``student`` is None for the operator and for staff."""

    name: str
    student: Student | None
    frame_origin: str | None = None
    """The LMS origins that may frame the pages (an LTI launch's session); None: no framing."""
    session_token: str | None = None
    """An LTI launch's session token, carried in the pages' links (None: the cookie or bearer token)."""
    lti_link_id: int | None = None
    """The LTI resource link the session was launched from."""
    course_id: int | None = None
    """The staff member's course (a student's is their enrolment's); None with no student: the operator."""
    role: StaffRole = StaffRole.INSTRUCTOR
    """What a staff member may do in their course (the operator is every course's instructor)."""

    @property
    def is_instructor(self) -> bool:
        """True for staff (instructors, teaching assistants) and the operator: they see every report whole."""
        return self.student is None

    @property
    def is_operator(self) -> bool:
        """True for the operator."""
        return self.student is None and self.course_id is None

    @property
    def manages_course(self) -> bool:
        """True for a course's instructors and the operator: they add its staff, assignments and students."""
        return self.is_instructor and self.role is StaffRole.INSTRUCTOR

    def course(self) -> int | None:
        """The caller's course (None: the operator, of every course)."""
        return self.student.course_id if self.student is not None else self.course_id

    def require_member(self, course_id: int) -> None:
        """Raise CourseNotFound unless the caller is the operator or of course ``course_id``."""
        mine = self.course()
        if mine is not None and mine != course_id:
            raise CourseNotFound("no such course or assignment among yours; list yours with GET /courses")

    def require_instructor(self) -> None:
        """Raise InstructorOnly unless the caller is staff (an instructor, a TA, or the operator)."""
        if not self.is_instructor:
            raise InstructorOnly("this endpoint needs the course staff's token; a student token was sent")

    def require_course_instructor(self) -> None:
        """Raise InstructorOnly unless the caller is an instructor of their course or the operator."""
        self.require_instructor()
        if not self.manages_course:
            raise InstructorOnly(
                "this endpoint needs an instructor's token; a teaching assistant's was sent: ask the course's instructor"  # noqa: E501
            )

    def require_operator(self) -> None:
        """Raise OperatorOnly unless the caller is the operator."""
        if not self.is_operator:
            raise OperatorOnly(
                "this endpoint needs the operator's token (GYMGRADE_OPERATOR_TOKEN); "
                "a course's token was sent"
            )

    def require_student(self) -> Student:
        """The caller's student record; raise StudentOnly for staff and the operator."""
        if self.student is None:
            raise StudentOnly(
                "submissions are uploaded with a student's token; a staff or operator token was sent"
            )
        return self.student


def authenticate(session: Session, settings: Settings, token: str | None) -> Principal:
    """Resolve a bearer token to its owner.

    Args:
        session: A database session.
        settings: Service settings (the operator's token, ``Settings.operator``).
        token: The token sent, or None.

    Returns:
        The caller.

    Raises:
        NotAuthenticated: No token, or nobody's token.
    """
    if not token:
        raise NotAuthenticated("no token sent; expected `Authorization: Bearer <your token>`")
    operator = settings.operator
    if operator is not None and same_secret(token, operator.get_secret_value()):
        return Principal(name="instructor", student=None)
    digest = token_digest(token)
    staff = session.scalars(select(Staff).where(Staff.token_sha256 == digest)).first()
    if staff is not None and same_secret(staff.token_sha256 or "", digest):
        return Principal(name=staff.name, student=None, course_id=staff.course_id, role=StaffRole(staff.role))
    student = session.scalars(select(Student).where(Student.token_sha256 == digest)).first()
    if student is None or not same_secret(student.token_sha256, digest):
        raise NotAuthenticated(
            "the token sent belongs to nobody; check it or ask the instructor for a new one"
        )
    return Principal(name=student.name, student=student)
