"""The database tables: students and their submissions (each submission row is also its grading job)."""

from __future__ import annotations

from datetime import UTC, datetime
from enum import StrEnum
from typing import Any

from sqlalchemy import JSON, DateTime, Float, ForeignKey, Integer, LargeBinary, String, Text, UniqueConstraint
from sqlalchemy.orm import DeclarativeBase, Mapped, mapped_column, relationship


def utcnow() -> datetime:
    """The current time in UTC without tzinfo: what every timestamp column holds, on SQLite and PostgreSQL."""
    return datetime.now(UTC).replace(tzinfo=None)


class JobStatus(StrEnum):
    """Where a submission's grading stands: queued -> running -> done or failed."""

    QUEUED = "queued"
    RUNNING = "running"
    DONE = "done"
    FAILED = "failed"


class Base(DeclarativeBase):
    """Declarative base of the service's tables."""


class Student(Base):
    """A student; only the SHA-256 of their token is stored."""

    __tablename__ = "students"

    id: Mapped[int] = mapped_column(Integer, primary_key=True)
    name: Mapped[str] = mapped_column(String(100), unique=True)
    token_sha256: Mapped[str] = mapped_column(String(64), unique=True)
    created_at: Mapped[datetime] = mapped_column(DateTime, default=utcnow)

    submissions: Mapped[list[Submission]] = relationship(back_populates="student")


class Submission(Base):
    """An uploaded file, its grading job state, and its report once graded."""

    __tablename__ = "submissions"

    id: Mapped[int] = mapped_column(Integer, primary_key=True)
    student_id: Mapped[int] = mapped_column(ForeignKey("students.id"), index=True)
    filename: Mapped[str] = mapped_column(String(100))
    sha256: Mapped[str] = mapped_column(String(64))
    content: Mapped[bytes] = mapped_column(LargeBinary)
    size: Mapped[int] = mapped_column(Integer)
    seed: Mapped[int] = mapped_column(Integer)
    status: Mapped[str] = mapped_column(String(16), index=True, default=JobStatus.QUEUED.value)
    created_at: Mapped[datetime] = mapped_column(DateTime, default=utcnow, index=True)
    started_at: Mapped[datetime | None] = mapped_column(DateTime, nullable=True)
    finished_at: Mapped[datetime | None] = mapped_column(DateTime, nullable=True)
    lease_owner: Mapped[str | None] = mapped_column(String(100), nullable=True)
    lease_expires_at: Mapped[datetime | None] = mapped_column(DateTime, nullable=True)
    attempts: Mapped[int] = mapped_column(Integer, default=0)
    progress: Mapped[list[dict[str, Any]]] = mapped_column(JSON, default=list)
    report: Mapped[dict[str, Any] | None] = mapped_column(JSON, nullable=True)
    error: Mapped[str | None] = mapped_column(Text, nullable=True)
    score: Mapped[float | None] = mapped_column(Float, nullable=True)
    max_score: Mapped[float | None] = mapped_column(Float, nullable=True)

    student: Mapped[Student] = relationship(back_populates="submissions")


class Override(Base):
    """An instructor's override of one student's score for a problem (or their ``total``), with its reason,
    who made it and when. Every override is kept; for a student, problem and upload the latest counts."""

    __tablename__ = "overrides"

    id: Mapped[int] = mapped_column(Integer, primary_key=True)
    student_id: Mapped[int] = mapped_column(ForeignKey("students.id"), index=True)
    submission_id: Mapped[int | None] = mapped_column(ForeignKey("submissions.id"), nullable=True)
    problem: Mapped[str] = mapped_column(String(64))
    points: Mapped[float] = mapped_column(Float)
    reason: Mapped[str] = mapped_column(Text)
    author: Mapped[str] = mapped_column(String(100))
    created_at: Mapped[datetime] = mapped_column(DateTime, default=utcnow)


class LtiKey(Base):
    """One of the tool's own RSA signing keys (LTI 1.3): the newest unretired one signs; retired ones stay
    published and accepted for ``LTI_KEY_GRACE_SECONDS`` so launches and platform caches in flight hold."""

    __tablename__ = "lti_keys"

    id: Mapped[int] = mapped_column(Integer, primary_key=True)
    kid: Mapped[str] = mapped_column(String(100), unique=True)
    private_pem: Mapped[str] = mapped_column(Text)
    created_at: Mapped[datetime] = mapped_column(DateTime, default=utcnow)
    retired_at: Mapped[datetime | None] = mapped_column(DateTime, nullable=True)


class LtiPlatform(Base):
    """A platform (LMS) registered with the tool: manually or by LTI Dynamic Registration."""

    __tablename__ = "lti_platforms"
    __table_args__ = (UniqueConstraint("issuer", "client_id", name="uq_lti_platforms_issuer_client"),)

    id: Mapped[int] = mapped_column(Integer, primary_key=True)
    issuer: Mapped[str] = mapped_column(String(500))
    client_id: Mapped[str] = mapped_column(String(255))
    deployment_ids: Mapped[list[str]] = mapped_column(JSON, default=list)
    jwks_url: Mapped[str] = mapped_column(String(1000))
    auth_url: Mapped[str] = mapped_column(String(1000))
    token_url: Mapped[str] = mapped_column(String(1000))
    created_at: Mapped[datetime] = mapped_column(DateTime, default=utcnow)
    frame_ancestors: Mapped[list[str]] = mapped_column(JSON, default=list, server_default="[]")
    """Origins besides the launch's own that may frame the tool (every ancestor: an LMS's page framing
    the page that frames the tool), set at registration."""


class LtiSpentToken(Base):
    """A single-use token of the tool's own (registration ticket, lab picker form) once used, by ``jti``,
    kept until it expires."""

    __tablename__ = "lti_spent_tokens"

    jti: Mapped[str] = mapped_column(String(100), primary_key=True)
    purpose: Mapped[str] = mapped_column(String(32))
    expires_at: Mapped[datetime] = mapped_column(DateTime, index=True)


class LtiNonce(Base):
    """A launch's nonce, stored when the launch is accepted: a second launch with it is a replay."""

    __tablename__ = "lti_nonces"

    nonce: Mapped[str] = mapped_column(String(255), primary_key=True)
    platform_id: Mapped[int] = mapped_column(ForeignKey("lti_platforms.id"))
    expires_at: Mapped[datetime] = mapped_column(DateTime, index=True)


class LtiUser(Base):
    """A platform user, keyed by (platform, sub): a learner's student row, or none for staff."""

    __tablename__ = "lti_users"
    __table_args__ = (UniqueConstraint("platform_id", "sub", name="uq_lti_users_platform_sub"),)

    id: Mapped[int] = mapped_column(Integer, primary_key=True)
    platform_id: Mapped[int] = mapped_column(ForeignKey("lti_platforms.id"))
    sub: Mapped[str] = mapped_column(String(255))
    student_id: Mapped[int | None] = mapped_column(ForeignKey("students.id"), nullable=True, unique=True)
    name: Mapped[str] = mapped_column(String(255))


class LtiLink(Base):
    """A resource link of a platform's context, with its Advantage service URLs and its line item."""

    __tablename__ = "lti_links"
    __table_args__ = (UniqueConstraint("platform_id", "resource_link_id", name="uq_lti_links_platform_link"),)

    id: Mapped[int] = mapped_column(Integer, primary_key=True)
    platform_id: Mapped[int] = mapped_column(ForeignKey("lti_platforms.id"))
    deployment_id: Mapped[str] = mapped_column(String(255))
    context_id: Mapped[str] = mapped_column(String(255))
    resource_link_id: Mapped[str] = mapped_column(String(255))
    title: Mapped[str] = mapped_column(String(255), default="")
    lineitems_url: Mapped[str | None] = mapped_column(String(1000), nullable=True)
    lineitem_url: Mapped[str | None] = mapped_column(String(1000), nullable=True)
    ags_scopes: Mapped[list[str]] = mapped_column(JSON, default=list)
    memberships_url: Mapped[str | None] = mapped_column(String(1000), nullable=True)
    custom: Mapped[dict[str, Any]] = mapped_column(JSON, default=dict)


class LtiMember(Base):
    """A student of a link (by launch or roster import): the platform user the link's scores go to."""

    __tablename__ = "lti_members"
    __table_args__ = (UniqueConstraint("link_id", "user_id", name="uq_lti_members_link_user"),)

    id: Mapped[int] = mapped_column(Integer, primary_key=True)
    link_id: Mapped[int] = mapped_column(ForeignKey("lti_links.id"), index=True)
    user_id: Mapped[int] = mapped_column(ForeignKey("lti_users.id"))


class LtiSession(Base):
    """A signed-in browser after a launch: only the SHA-256 of its token is stored; no student = staff."""

    __tablename__ = "lti_sessions"

    id: Mapped[int] = mapped_column(Integer, primary_key=True)
    token_sha256: Mapped[str] = mapped_column(String(64), unique=True)
    user_id: Mapped[int] = mapped_column(ForeignKey("lti_users.id"))
    link_id: Mapped[int | None] = mapped_column(ForeignKey("lti_links.id"), nullable=True)
    frame_origin: Mapped[str] = mapped_column(String(500))
    browser_sha256: Mapped[str | None] = mapped_column(String(64), nullable=True)
    """The SHA-256 of the browser cookie's secret the session works with (api/lti/binding.py); None: a
    session opened through the platform's storage, by a browser keeping no cookie."""
    expires_at: Mapped[datetime] = mapped_column(DateTime)


class LtiScore(Base):
    """The outbox of one (link, member): the score the policy keeps, the one the platform last accepted,
    and the publishing's state (pending, sent, retrying, failed) with its next attempt and last error."""

    __tablename__ = "lti_scores"

    id: Mapped[int] = mapped_column(Integer, primary_key=True)
    member_id: Mapped[int] = mapped_column(ForeignKey("lti_members.id"), unique=True)
    submission_id: Mapped[int] = mapped_column(ForeignKey("submissions.id"))
    score: Mapped[float | None] = mapped_column(Float, nullable=True)
    max_score: Mapped[float | None] = mapped_column(Float, nullable=True)
    timestamp: Mapped[datetime] = mapped_column(DateTime)
    sent_submission_id: Mapped[int | None] = mapped_column(Integer, nullable=True)
    sent_score: Mapped[float | None] = mapped_column(Float, nullable=True)
    status: Mapped[str] = mapped_column(String(16), index=True)
    attempts: Mapped[int] = mapped_column(Integer, default=0)
    next_attempt_at: Mapped[datetime] = mapped_column(DateTime)
    error: Mapped[str | None] = mapped_column(Text, nullable=True)
