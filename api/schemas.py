"""Request and response bodies of the HTTP API (they make up its OpenAPI schema)."""

from __future__ import annotations

from datetime import UTC, datetime
from enum import Enum
from typing import Annotated, Any, Literal

from pydantic import AfterValidator, BaseModel, BeforeValidator, ConfigDict, Field

from api.students import MAX_NAME_CHARS, name_pattern
from grader.lab.editions import EDITIONS

Status = Literal["queued", "running", "done", "failed"]
MAX_CONFIG_CHARS = 64 * 1024
"""The longest assignment configuration accepted (the bundled ones are under 8,000 characters)."""


def _as_utc(moment: datetime) -> datetime:
    # The database stores naive UTC times; an RFC 3339 date-time must carry its offset.
    return moment if moment.tzinfo is not None else moment.replace(tzinfo=UTC)


UtcDateTime = Annotated[datetime, AfterValidator(_as_utc)]


def _document_name_rule(schema: dict[str, Any]) -> None:
    # Documentation only: api.students.normalise_name checks names with messages a person can act on.
    schema["properties"]["name"]["pattern"] = name_pattern()


class StudentCreate(BaseModel):
    """A new student."""

    model_config = ConfigDict(json_schema_extra=_document_name_rule)

    name: str = Field(
        description=(
            f"Unique display name: 1 to {MAX_NAME_CHARS} characters once whitespace around it is trimmed, none of them a control, format (bidi, zero-width), private-use or line-separator character."  # noqa: E501
        ),
        examples=["Ada Lovelace"],
    )


class StudentCreated(BaseModel):
    """The new student and their bearer token (shown once; only its SHA-256 is stored)."""

    id: int = Field(description="The enrolment's id: what its overrides and extensions are keyed by.")
    name: str
    token: str


class EnrolmentView(BaseModel):
    """A student's enrolment in a course: its id (what overrides and extensions are keyed by) and its name."""

    id: int
    name: str
    lti: bool = Field(
        description="True for a platform user of the course's LMS context (an LTI launch or roster)."
    )


class SubmissionAccepted(BaseModel):
    """An upload that was stored and queued for grading."""

    id: int
    status: Literal["queued"] = "queued"


class SubmissionSummary(BaseModel):
    """One submission in a listing."""

    id: int
    student: str
    filename: str = Field(description="The uploaded file's sanitised name (display only).")
    sha256: str
    status: Status
    score: float | None = None
    max_score: float | None = None
    created_at: UtcDateTime
    finished_at: UtcDateTime | None = None


class OverrideShown(BaseModel):
    """An override as the student's submission shows it: the problem, the instructor's points and why."""

    problem: str
    points: float
    reason: str
    created_at: UtcDateTime


class SubmissionDetail(SubmissionSummary):
    """A submission with its live progress and, once done, its report."""

    seed: int | None = Field(
        description="The grading seed; null for students unless the instructor released the seeds."
    )
    started_at: UtcDateTime | None = None
    attempts: int
    progress: list[dict[str, Any]] = Field(
        default_factory=list, description="Problems finished so far (each as in the report's `problems`)."
    )
    report: dict[str, Any] | None = Field(
        default=None,
        description="The grader's report, when status is done. "
        "Students see null seeds unless released, and problems withheld by their visibility (hidden, after_due_date before the due date) with status 'withheld', a note for feedback and a null score, as is then the total.",  # noqa: E501
    )
    error: str | None = Field(default=None, description="Why grading failed, when status is failed.")
    overrides: list[OverrideShown] = Field(
        default_factory=list,
        description="The instructor's overrides that count for this upload, latest per problem (a student sees none of a withheld problem, and no total override while one is withheld).",  # noqa: E501
    )


class Health(BaseModel):
    """Service health."""

    status: Literal["ok"] = "ok"
    database: str
    queued: int
    running: int
    workers: int = Field(
        description="Gradings this server process runs at once (GYMGRADE_WORKERS; 0: the cluster grades)."
    )


class FieldProblem(BaseModel):
    """One part of a request that breaks the schema."""

    location: list[str | int] = Field(
        description='Where it is: ["body", "name"], ["path", "submission_id"], ["query", "student"], ...',
        examples=[["body", "name"]],
    )
    message: str = Field(description="What was expected there and what was found.")
    type: str = Field(description="The kind of problem, stable for programs: missing, int_parsing, ...")


class ErrorBody(BaseModel):
    """Every error response of the API, whatever its status: what went wrong and what to do."""

    detail: str = Field(description="What was expected, what was found, and what to do; shown to people.")
    problems: list[FieldProblem] | None = Field(
        default=None,
        description="Only on 422 for a request that breaks the schema: each offending field, for programs.",
    )


class OverrideCreate(BaseModel):
    """An instructor's override of a student's score for one problem (or their total)."""

    model_config = ConfigDict(extra="forbid")

    problem: str = Field(
        min_length=1,
        max_length=64,
        description="A problem id of the student's report, or `total`.",
        examples=["car"],
    )
    points: float = Field(
        ge=0.0, allow_inf_nan=False, description="The points given (at most what it is worth)."
    )
    reason: str = Field(min_length=1, max_length=1000, description="Why, shown beside the machine's verdict.")
    submission_id: int | None = Field(
        default=None,
        ge=1,
        le=2**31 - 1,
        description="One upload's override (it counts while the gradebook shows that upload); none: the student's.",  # noqa: E501
    )


class OverrideView(BaseModel):
    """A recorded override, with who made it and when."""

    id: int
    enrolment: int = Field(description="The enrolment's id (GET .../students lists them).")
    student: str
    submission_id: int | None
    problem: str
    points: float
    reason: str
    author: str = Field(description="Who made it (the instructor).")
    created_at: UtcDateTime


SLUG_PATTERN = r"^[a-z0-9][a-z0-9-]{0,63}$"
"""A course's or assignment's slug, as its URLs show it (``/courses/{course}/assignments/{assignment}``)."""
Slug = Annotated[str, Field(pattern=SLUG_PATTERN, description="Lower-case letters, digits and dashes.")]
Name = Annotated[
    str,
    Field(
        min_length=1,
        max_length=MAX_NAME_CHARS,
        description="A title or a person's name. "
        "It is shown without the whitespace around it and without control, format, private-use or line-separator characters.",  # noqa: E501
    ),
]


class CourseCreate(BaseModel):
    """A new course (the operator's)."""

    slug: Slug
    title: Name


class CourseView(BaseModel):
    """A course."""

    id: int
    slug: str
    title: str


class StaffCreate(BaseModel):
    """A new member of a course's staff: an instructor, or a teaching assistant (``ta``)."""

    name: Name
    role: Literal["instructor", "ta"] = "instructor"


class StaffCreated(BaseModel):
    """The new staff member (or a new token of theirs) and their bearer token, which reaches their course only
    with their role's rights (shown once; only its SHA-256 is stored)."""

    id: int = Field(description="The staff member's id: revoke the token with DELETE .../staff/{id}/token.")
    name: str
    role: Literal["instructor", "ta"]
    token: str


class StaffView(BaseModel):
    """A member of a course's staff (never their token)."""

    id: int
    name: str
    role: Literal["instructor", "ta"]
    token: bool = Field(description="True while the member has an API token (false: none yet, or revoked).")
    lti: bool = Field(
        description="True for a platform user whose launches from the course's context are staff's."
    )


def _written(value: object) -> object:
    # An RFC 3339 date-time is text: a number is not read as seconds since 1970.
    if not isinstance(value, str | datetime):
        raise ValueError("expected an ISO 8601 date-time such as 2026-03-01T23:59:00-05:00")
    return value


WrittenDateTime = Annotated[datetime, BeforeValidator(_written), AfterValidator(_as_utc)]
"""A date-time given as text (UTC when it has no offset)."""


class LateTable(BaseModel):
    """An assignment's late policy, as the assignment configuration's ``[late]`` table (extensions apart)."""

    due: WrittenDateTime = Field(description="The due time, ISO 8601 (UTC when no offset is given).")
    penalty_per_day: float = Field(ge=0.0, le=1.0, strict=True)
    max_penalty: float = Field(default=1.0, ge=0.0, le=1.0, strict=True)
    grace_minutes: float = Field(default=0.0, ge=0.0, le=7 * 24 * 60, strict=True)


class ExtensionCreate(BaseModel):
    """An enrolment's own due time for the assignment's late policy."""

    model_config = ConfigDict(extra="forbid")

    due: WrittenDateTime = Field(
        description="The enrolment's due time, ISO 8601 (UTC when no offset is given)."
    )
    reason: str = Field(min_length=1, max_length=1000, description="Why, kept with who granted it.")


class ExtensionView(BaseModel):
    """An enrolment's extension of one assignment, with who granted it and when."""

    enrolment: int
    student: str
    due: UtcDateTime
    reason: str
    author: str
    created_at: UtcDateTime


EditionName = Enum("EditionName", {name: name for name in EDITIONS}, type=str)  # type: ignore[misc]
"""The editions of every lab (grader/lab/editions)."""


class AssignmentCreate(BaseModel):
    """A new assignment of a course: what is graded (lab, edition) and how."""

    slug: Slug
    title: Name
    edition: EditionName | None = Field(
        default=None,
        description="The edition every upload is graded as; its lab follows from it. "
        "Unset: the first edition, classic.",
    )
    seed_policy: Literal["random", "fixed"] = "random"
    seed: int | None = Field(
        default=None,
        ge=1,
        le=2**31 - 1,
        description="The fixed policy's seed (never the practice seed 0); unset: a secret one is drawn.",
    )
    release_seeds: bool = Field(default=False, strict=True)
    due_date: WrittenDateTime | None = Field(
        default=None, description="When after_due_date problems are shown."
    )
    gradebook_policy: Literal["latest", "best"] = "latest"
    late: LateTable | None = None
    config: str | None = Field(
        default=None,
        max_length=MAX_CONFIG_CHARS,
        description="The assignment configuration (points, visibility, checks' numbers and limits) as the text of a TOML file like grader/lab/assignment.toml (`gymgrade grade --config`'s); its edition is the assignment's. "  # noqa: E501
        "Unset: the edition's bundled configuration.",
    )


class AssignmentView(BaseModel):
    """An assignment of a course."""

    id: int
    course: str
    slug: str
    title: str
    lab: str | None
    edition: str | None
    seed_policy: str
    release_seeds: bool
    due_date: UtcDateTime | None
    gradebook_policy: str
    late: dict[str, Any] | None
    config: str | None = Field(
        description="The assignment configuration's TOML text; null: the edition's bundled one."
    )


class LtiLinkView(BaseModel):
    """A resource link of an LMS course that opens the assignment: its platform, context, title, line item and
    custom parameters."""

    model_config = ConfigDict(from_attributes=True)

    id: int
    platform_id: int
    context_id: str
    resource_link_id: str
    title: str
    lineitem_url: str | None
    custom: dict[str, str]


class RosterImported(BaseModel):
    """What a roster import (LTI Names and Role Provisioning) found: learners (each now has an enrolment and a
    gradebook row), staff, and members skipped (inactive, or of no role the tool knows)."""

    learners: int
    staff: int
    skipped: int


class LtiScoreView(BaseModel):
    """One student's score publishing to the LMS for a link: the kept (final) score, the one the LMS holds,
    the publishing's state, its attempts and last error."""

    student: str
    link_id: int
    submission_id: int
    score: float | None
    max_score: float | None
    sent_score: float | None
    status: Literal["pending", "sent", "retrying", "failed"]
    attempts: int
    error: str | None
