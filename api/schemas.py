"""Request and response bodies of the HTTP API (they make up its OpenAPI schema)."""

from __future__ import annotations

from datetime import datetime
from typing import Any, Literal

from pydantic import BaseModel, Field

Status = Literal["queued", "running", "done", "failed"]


class StudentCreate(BaseModel):
    """A new student."""

    name: str = Field(
        description="Unique display name, 1 to 100 printable characters.", examples=["Ada Lovelace"]
    )


class StudentCreated(BaseModel):
    """The new student and their bearer token (shown once; only its SHA-256 is stored)."""

    name: str
    token: str


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
    created_at: datetime
    finished_at: datetime | None = None


class SubmissionDetail(SubmissionSummary):
    """A submission with its live progress and, once done, its report."""

    seed: int | None = Field(
        description="The grading seed; null for students unless the instructor released the seeds."
    )
    started_at: datetime | None = None
    attempts: int
    progress: list[dict[str, Any]] = Field(
        default_factory=list, description="Problems finished so far (each as in the report's `problems`)."
    )
    report: dict[str, Any] | None = Field(
        default=None,
        description="The grader's report, when status is done. Students see null seeds unless released, "
        "and problems withheld by their visibility (hidden, after_due_date before the due date) with "
        "status 'withheld', a note for feedback and a null score, as is then the total.",
    )
    error: str | None = Field(default=None, description="Why grading failed, when status is failed.")


class Health(BaseModel):
    """Service health."""

    status: Literal["ok"] = "ok"
    database: str
    queued: int
    running: int


class ErrorBody(BaseModel):
    """Every error response: what went wrong and what to do."""

    detail: str
