"""Who is calling: the instructor (one configured token) or a student (a stored token digest)."""

from __future__ import annotations

from dataclasses import dataclass

from sqlalchemy import select
from sqlalchemy.orm import Session

from api.errors import InstructorOnly, NotAuthenticated, StudentOnly
from api.models import Student
from api.security import same_secret, token_digest
from api.settings import Settings


@dataclass(frozen=True)
class Principal:
    """The authenticated caller; ``student`` is None for the instructor."""

    name: str
    student: Student | None
    frame_origin: str | None = None
    """The LMS origins that may frame the pages (an LTI launch's session); None: no framing."""
    session_token: str | None = None
    """An LTI launch's session token, carried in the pages' links (None: the cookie or bearer token)."""
    lti_link_id: int | None = None
    """The LTI resource link the session was launched from."""

    @property
    def is_instructor(self) -> bool:
        """True for the instructor."""
        return self.student is None

    def require_instructor(self) -> None:
        """Raise InstructorOnly unless the caller is the instructor."""
        if not self.is_instructor:
            raise InstructorOnly("this endpoint needs the instructor's token; a student token was sent")

    def require_student(self) -> Student:
        """The caller's student record; raise StudentOnly for the instructor."""
        if self.student is None:
            raise StudentOnly(
                "submissions are uploaded with a student's token; the instructor token was sent"
            )
        return self.student


def authenticate(session: Session, settings: Settings, token: str | None) -> Principal:
    """Resolve a bearer token to its owner.

    Args:
        session: A database session.
        settings: Service settings (the instructor token).
        token: The token sent, or None.

    Returns:
        The caller.

    Raises:
        NotAuthenticated: No token, or nobody's token.
    """
    if not token:
        raise NotAuthenticated("no token sent; expected `Authorization: Bearer <your token>`")
    instructor = settings.instructor_token
    if instructor is not None and same_secret(token, instructor.get_secret_value()):
        return Principal(name="instructor", student=None)
    digest = token_digest(token)
    student = session.scalars(select(Student).where(Student.token_sha256 == digest)).first()
    if student is None or not same_secret(student.token_sha256, digest):
        raise NotAuthenticated(
            "the token sent belongs to nobody; check it or ask the instructor for a new one"
        )
    return Principal(name=student.name, student=student)
