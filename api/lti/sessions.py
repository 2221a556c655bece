"""The browser sessions LTI launches open: a token (only its SHA-256 stored) resolved to its caller, in the
browser it is bound to (api/lti/binding.py)."""

from __future__ import annotations

import logging
import re

from sqlalchemy import select
from sqlalchemy.orm import Session

from api.auth import Principal, StaffRole
from api.courses import DEFAULT_COURSE_ID
from api.lti.binding import matches
from api.models import Assignment, LtiLink, LtiSession, LtiUser, Staff, Student, utcnow
from api.security import token_digest

SESSION_PREFIX = "ggl_"
"""How a launch session's token starts (a student's bearer token starts with ``gg_``)."""
SESSION_PARAMETER = "lti_session"
"""The query parameter carrying the session in links and forms: an LMS iframe may get no cookie at all."""


def session_caller(session: Session, token: str, browser_secret: str | None) -> Principal | None:
    """The caller of an unexpired launch session: the staff (instructor or TA) of its launch's course, or
    that course's enrolment, when the browser sends the cookie the session is bound to (``browser_secret``;
    api/lti/binding.py); None when it is neither (or expired, or another browser)."""
    row = session.scalars(select(LtiSession).where(LtiSession.token_sha256 == token_digest(token))).first()
    if row is None or row.expires_at < utcnow():
        return None
    if row.browser_sha256 is not None and not matches(browser_secret, row.browser_sha256):
        return None
    user = session.get(LtiUser, row.user_id)
    if user is None:
        return None
    course_id = _course_of(session, row)
    staff = session.scalars(
        select(Staff).where(Staff.course_id == course_id, Staff.lti_user_id == user.id)
    ).first()
    student = None if staff is not None else _enrolment(session, course_id, user)
    if staff is None and student is None:
        return None
    name = student.name if student is not None else user.name
    return Principal(
        name=name,
        student=student,
        frame_origin=row.frame_origin,
        session_token=token,
        lti_link_id=row.link_id,
        course_id=course_id,
        role=StaffRole(staff.role) if staff is not None else StaffRole.INSTRUCTOR,
    )


def _course_of(session: Session, row: LtiSession) -> int:
    """The course of the session's launch (a session of before courses: its link's, else the default)."""
    if row.course_id is not None:
        return row.course_id
    link = session.get(LtiLink, row.link_id) if row.link_id is not None else None
    return session.get_one(Assignment, link.assignment_id).course_id if link else DEFAULT_COURSE_ID


def _enrolment(session: Session, course_id: int, user: LtiUser) -> Student | None:
    """The user's enrolment in the course (None: none)."""
    query = select(Student).where(Student.course_id == course_id, Student.lti_user_id == user.id)
    return session.scalars(query).first()


SECRET_PARAMETERS = (SESSION_PARAMETER, "ticket", "registration_token")
"""Query parameters whose values are credentials: a session, a registration ticket, a platform's token."""
_IN_A_URL = re.compile(rf"((?:^|[?&\s])(?:{'|'.join(SECRET_PARAMETERS)})=)[^&\s\"']+")


def redacted(text: str) -> str:
    """``text`` with the value of each of :data:`SECRET_PARAMETERS` replaced (they are passwords)."""
    return _IN_A_URL.sub(r"\1[redacted]", text)


class RedactSessions(logging.Filter):
    """Keeps launch session tokens out of the logs (uvicorn's access log prints each URL with its query)."""

    def filter(self, record: logging.LogRecord) -> bool:
        """Redact the record's message arguments and message; never drops a record."""
        if isinstance(record.args, tuple):
            record.args = tuple(redacted(arg) if isinstance(arg, str) else arg for arg in record.args)
        if isinstance(record.msg, str):
            record.msg = redacted(record.msg)
        return True


def redact_access_log() -> None:
    """Install :class:`RedactSessions` on uvicorn's access and error loggers (once)."""
    for name in ("uvicorn.access", "uvicorn.error"):
        logger = logging.getLogger(name)
        if not any(isinstance(existing, RedactSessions) for existing in logger.filters):
            logger.addFilter(RedactSessions())
