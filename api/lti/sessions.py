"""The browser sessions LTI launches open: a token (only its SHA-256 stored) resolved to its caller."""

from __future__ import annotations

from sqlalchemy import select
from sqlalchemy.orm import Session

from api.auth import Principal
from api.models import LtiSession, LtiUser, Student, utcnow
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
    student = session.get(Student, user.student_id) if user.student_id is not None else None
    name = student.name if student is not None else user.name
    return Principal(
        name=name,
        student=student,
        frame_origin=row.frame_origin,
        session_token=token,
        lti_link_id=row.link_id,
    )
