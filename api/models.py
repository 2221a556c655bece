"""The database tables: courses with their staff, students (enrolments) and assignments; each assignment's
submissions (each submission row is also its grading job), overrides and extensions; the LTI tool's state.

A course is one class of the department; its ``students`` rows are its enrolments (a person in two courses
is two rows, with two tokens or, under LTI, one platform user in two contexts). An assignment names what is
graded and how (lab, edition, configuration, seed policy, due date, gradebook and late policy); every
submission, override and extension belongs to one assignment and one enrolment of its course. Course 1 with
its assignment 1 is the embedded default, whose configuration follows the service's settings
(``api.courses.sync_default``): what a database of before courses migrates into."""

from __future__ import annotations

from datetime import UTC, datetime
from enum import StrEnum
from typing import Any

from sqlalchemy import (
    JSON,
    Boolean,
    DateTime,
    Float,
    ForeignKey,
    Integer,
    LargeBinary,
    String,
    Text,
    UniqueConstraint,
)
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


class Course(Base):
    """A course of the department: its staff, students (enrolments) and assignments. Under LTI it is one
    context of one deployment of a platform (made by its first staff launch); else made by the operator."""

    __tablename__ = "courses"
    __table_args__ = (
        UniqueConstraint(
            "lti_platform_id", "lti_deployment_id", "lti_context_id", name="uq_courses_lti_context"
        ),
    )

    id: Mapped[int] = mapped_column(Integer, primary_key=True)
    slug: Mapped[str] = mapped_column(String(64), unique=True)
    title: Mapped[str] = mapped_column(String(200))
    lti_platform_id: Mapped[int | None] = mapped_column(ForeignKey("lti_platforms.id"), nullable=True)
    lti_deployment_id: Mapped[str | None] = mapped_column(String(255), nullable=True)
    lti_context_id: Mapped[str | None] = mapped_column(String(255), nullable=True)
    created_at: Mapped[datetime] = mapped_column(DateTime, default=utcnow)


class Assignment(Base):
    """What one course grades and how: the lab and edition, the assignment configuration (points and
    visibility; None: the edition's bundled one), the seed policy, the due date of ``after_due_date``
    problems, the gradebook policy and the late policy (``[late]`` without extensions: those are rows)."""

    __tablename__ = "assignments"
    __table_args__ = (UniqueConstraint("course_id", "slug", name="uq_assignments_course_slug"),)

    id: Mapped[int] = mapped_column(Integer, primary_key=True)
    course_id: Mapped[int] = mapped_column(ForeignKey("courses.id"), index=True)
    slug: Mapped[str] = mapped_column(String(64))
    title: Mapped[str] = mapped_column(String(200))
    lab: Mapped[str | None] = mapped_column(String(32), nullable=True)
    edition: Mapped[str | None] = mapped_column(String(32), nullable=True)
    config_toml: Mapped[str | None] = mapped_column(Text, nullable=True)
    seed_policy: Mapped[str] = mapped_column(String(16))
    seed: Mapped[int] = mapped_column(Integer)
    release_seeds: Mapped[bool] = mapped_column(Boolean)
    due_date: Mapped[datetime | None] = mapped_column(DateTime, nullable=True)
    gradebook_policy: Mapped[str] = mapped_column(String(16))
    late_policy: Mapped[dict[str, Any] | None] = mapped_column(JSON, nullable=True)
    created_at: Mapped[datetime] = mapped_column(DateTime, default=utcnow)


class Staff(Base):
    """A course's instructor or teaching assistant: with an API token (only its SHA-256 is stored), or a
    platform user whose launches from the course's context are staff launches."""

    __tablename__ = "staff"
    __table_args__ = (UniqueConstraint("course_id", "lti_user_id", name="uq_staff_course_lti_user"),)

    id: Mapped[int] = mapped_column(Integer, primary_key=True)
    course_id: Mapped[int] = mapped_column(ForeignKey("courses.id"), index=True)
    role: Mapped[str] = mapped_column(String(16))
    name: Mapped[str] = mapped_column(String(100))
    token_sha256: Mapped[str | None] = mapped_column(String(64), unique=True, nullable=True)
    lti_user_id: Mapped[int | None] = mapped_column(ForeignKey("lti_users.id"), nullable=True)
    created_at: Mapped[datetime] = mapped_column(DateTime, default=utcnow)


class Student(Base):
    """A student's enrolment in one course: a name unique in the course, a token (only its SHA-256 is
    stored) and, under LTI, the platform user it is (one enrolment per course: (platform, deployment,
    context, sub))."""

    __tablename__ = "students"
    __table_args__ = (
        UniqueConstraint("course_id", "name", name="uq_students_course_name"),
        UniqueConstraint("course_id", "lti_user_id", name="uq_students_course_lti_user"),
    )

    id: Mapped[int] = mapped_column(Integer, primary_key=True)
    course_id: Mapped[int] = mapped_column(ForeignKey("courses.id"), index=True)
    name: Mapped[str] = mapped_column(String(100))
    token_sha256: Mapped[str] = mapped_column(String(64), unique=True)
    lti_user_id: Mapped[int | None] = mapped_column(ForeignKey("lti_users.id"), nullable=True)
    created_at: Mapped[datetime] = mapped_column(DateTime, default=utcnow)

    submissions: Mapped[list[Submission]] = relationship(back_populates="student")


class Submission(Base):
    """An uploaded file, its grading job state, and its report once graded."""

    __tablename__ = "submissions"

    id: Mapped[int] = mapped_column(Integer, primary_key=True)
    assignment_id: Mapped[int] = mapped_column(ForeignKey("assignments.id"), index=True)
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
    """An instructor's override of one enrolment's score for a problem (or their ``total``) of one
    assignment, with its reason, who made it and when. Every override is kept; for an enrolment, problem
    and upload the latest counts."""

    __tablename__ = "overrides"

    id: Mapped[int] = mapped_column(Integer, primary_key=True)
    assignment_id: Mapped[int] = mapped_column(ForeignKey("assignments.id"), index=True)
    student_id: Mapped[int] = mapped_column(ForeignKey("students.id"), index=True)
    submission_id: Mapped[int | None] = mapped_column(ForeignKey("submissions.id"), nullable=True)
    problem: Mapped[str] = mapped_column(String(64))
    points: Mapped[float] = mapped_column(Float)
    reason: Mapped[str] = mapped_column(Text)
    author: Mapped[str] = mapped_column(String(100))
    created_at: Mapped[datetime] = mapped_column(DateTime, default=utcnow)


class Extension(Base):
    """An enrolment's own due time for one assignment's late policy, with who granted it and why."""

    __tablename__ = "extensions"
    __table_args__ = (
        UniqueConstraint("assignment_id", "student_id", name="uq_extensions_assignment_student"),
    )

    id: Mapped[int] = mapped_column(Integer, primary_key=True)
    assignment_id: Mapped[int] = mapped_column(ForeignKey("assignments.id"))
    student_id: Mapped[int] = mapped_column(ForeignKey("students.id"))
    due: Mapped[datetime] = mapped_column(DateTime)
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
    """A platform user, keyed by (platform, sub): in each course, an enrolment (``Student.lti_user_id``) or
    a staff row (``Staff.lti_user_id``)."""

    __tablename__ = "lti_users"
    __table_args__ = (UniqueConstraint("platform_id", "sub", name="uq_lti_users_platform_sub"),)

    id: Mapped[int] = mapped_column(Integer, primary_key=True)
    platform_id: Mapped[int] = mapped_column(ForeignKey("lti_platforms.id"))
    sub: Mapped[str] = mapped_column(String(255))
    name: Mapped[str] = mapped_column(String(255))


class LtiLink(Base):
    """A resource link of a platform's deployment and context, keyed by (platform, deployment, link id):
    the assignment it opens, its Advantage service URLs and the assignment's line item there."""

    __tablename__ = "lti_links"
    __table_args__ = (
        UniqueConstraint(
            "platform_id", "deployment_id", "resource_link_id", name="uq_lti_links_platform_deployment_link"
        ),
    )

    id: Mapped[int] = mapped_column(Integer, primary_key=True)
    platform_id: Mapped[int] = mapped_column(ForeignKey("lti_platforms.id"))
    assignment_id: Mapped[int] = mapped_column(ForeignKey("assignments.id"), index=True)
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
    """A signed-in browser after a launch: only the SHA-256 of its token is stored. It reaches the course of
    the launch's context only (``course_id``; None in a session of before courses: the default course), as
    that course's staff or as its enrolment."""

    __tablename__ = "lti_sessions"

    id: Mapped[int] = mapped_column(Integer, primary_key=True)
    token_sha256: Mapped[str] = mapped_column(String(64), unique=True)
    user_id: Mapped[int] = mapped_column(ForeignKey("lti_users.id"))
    course_id: Mapped[int | None] = mapped_column(ForeignKey("courses.id"), nullable=True)
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
