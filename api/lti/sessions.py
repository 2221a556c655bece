"""The browser sessions LTI launches open: a token (only its SHA-256 stored) resolved to its caller."""

from __future__ import annotations

import logging
import re

from sqlalchemy import select
from sqlalchemy.orm import Session

from api.auth import Principal
from api.courses import DEFAULT_COURSE_ID
from api.models import Assignment, LtiLink, LtiSession, LtiUser, Student, utcnow
from api.security import token_digest

SESSION_PREFIX = "ggl_"
"""How a launch session's token starts (a student's bearer token starts with ``gg_``)."""
SESSION_PARAMETER = "lti_session"
"""The query parameter carrying the session in links and forms: an LMS iframe may get no cookie at all."""


def session_caller(session: Session, token: str) -> Principal | None:
    """The caller of an unexpired launch session (a student, or the context's staff as instructor)."""
    row = session.scalars(select(LtiSession).where(LtiSession.token_sha256 == token_digest(token))).first()
    if row is None or row.expires_at < utcnow():
        return None
    user = session.get(LtiUser, row.user_id)
    if user is None:
        return None
    student = _enrolment(session, row, user)
    name = student.name if student is not None else user.name
    return Principal(
        name=name,
        student=student,
        frame_origin=row.frame_origin,
        session_token=token,
        lti_link_id=row.link_id,
    )


def _enrolment(session: Session, row: LtiSession, user: LtiUser) -> Student | None:
    """The enrolment the session's user is in the course of the link it was launched from (None: staff)."""
    link = session.get(LtiLink, row.link_id) if row.link_id is not None else None
    course_id = session.get_one(Assignment, link.assignment_id).course_id if link else DEFAULT_COURSE_ID
    query = select(Student).where(Student.course_id == course_id, Student.lti_user_id == user.id)
    return session.scalars(query).first()


_IN_A_URL = re.compile(rf"({SESSION_PARAMETER}=)[^&\s\"']+")


def redacted(text: str) -> str:
    """``text`` with every ``lti_session=...`` value replaced (a session token is a password)."""
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
