"""Storing uploads to an assignment as queued jobs, and reading them back for their owner or the staff."""

from __future__ import annotations

import math
from collections.abc import Sequence
from datetime import timedelta

from sqlalchemy import func, select
from sqlalchemy.orm import Session, defer, joinedload

from api.auth import Principal
from api.courses import seed_policy_of
from api.disclosure import Disclosure, problem_view, report_view, withholds_any
from api.errors import CourseNotFound, GradingInProgress, RateLimited, SubmissionNotFound
from api.jobs.job_queue import Dispatcher
from api.models import Assignment, JobStatus, Student, Submission, utcnow
from api.schemas import OverrideShown, SubmissionDetail, SubmissionSummary
from api.settings import SeedPolicy, Settings
from api.students import MAX_ID, find_student
from api.uploads import CheckedUpload
from grader.seeds import held_out_seed

RATE_WINDOW = timedelta(seconds=60)
MAX_SEED = 2**31 - 1


def create_submission(
    session: Session,
    settings: Settings,
    assignment: Assignment,
    student: Student,
    upload: CheckedUpload,
    dispatcher: Dispatcher,
) -> Submission:
    """Store an upload to an assignment as a queued grading job, then tell the workers (the row is stored
    first: an upload accepted while the broker is down is enqueued later by the reconciler).

    Args:
        session: A database session (committed here).
        settings: Service settings (rate limit).
        assignment: The assignment (its seed policy).
        student: The uploading student, enrolled in the assignment's course.
        upload: The checked file.
        dispatcher: Tells the workers about the new job.

    Returns:
        The stored submission, status queued.

    Raises:
        RateLimited: The student already uploaded GYMGRADE_RATE_LIMIT_PER_MINUTE files to the assignment in
            the last minute.
    """
    if student.course_id != assignment.course_id:  # the routes' scopes see to it; never mix two courses
        raise CourseNotFound("no such assignment among your course's; open it from your own course")
    now = utcnow()
    recent = session.execute(
        select(func.count(Submission.id), func.min(Submission.created_at)).where(
            Submission.assignment_id == assignment.id,
            Submission.student_id == student.id,
            Submission.created_at > now - RATE_WINDOW,
        )
    ).one()
    count, oldest = recent
    if count >= settings.rate_limit_per_minute:
        wait = math.ceil((oldest + RATE_WINDOW - now).total_seconds()) if oldest is not None else 60
        raise RateLimited(
            f"at most {settings.rate_limit_per_minute} uploads per minute; try again in {max(wait, 1)} s",
            retry_after_seconds=max(wait, 1),
        )
    fixed = seed_policy_of(assignment) is SeedPolicy.FIXED
    seed = assignment.seed if fixed else held_out_seed(MAX_SEED + 1)
    submission = Submission(
        assignment_id=assignment.id,
        student_id=student.id,
        filename=upload.display_name,
        sha256=upload.sha256,
        content=upload.content,
        size=len(upload.content),
        seed=seed,
        status=JobStatus.QUEUED.value,
        created_at=now,
        attempts=0,
        progress=[],
    )
    session.add(submission)
    session.commit()
    dispatcher.submitted(submission.id)
    return submission


def regrade(session: Session, submissions: list[Submission], dispatcher: Dispatcher) -> list[int]:
    """Queue graded (or failed) submissions again, each on its own recorded seed; their reports are replaced
    when the workers finish, and the instructor's overrides stay (they are kept apart).

    Raises:
        GradingInProgress: One of them is queued or being graded already (nothing is queued then).
    """
    busy = [item for item in submissions if item.status in (JobStatus.QUEUED.value, JobStatus.RUNNING.value)]
    if busy:
        raise GradingInProgress(
            f"submission {busy[0].id} is {busy[0].status} already: it is graded as soon as a worker is free; regrade it once it is done or failed"  # noqa: E501
        )
    for item in submissions:
        item.status = JobStatus.QUEUED.value
        item.attempts = 0
        item.lease_owner = None
        item.lease_expires_at = None
        item.started_at = None
        item.finished_at = None
        item.progress = []
        item.report = None
        item.error = None
        item.score = None
        item.max_score = None
    session.commit()
    for item in submissions:
        dispatcher.submitted(item.id)
    return [item.id for item in submissions]


def get_submission(
    session: Session, caller: Principal, assignment: Assignment, submission_id: int
) -> Submission:
    """The submission ``submission_id`` of the assignment if the caller may see it.

    Raises:
        SubmissionNotFound: It does not exist, is another assignment's, or is another student's
            (indistinguishable on purpose).
    """
    in_range = 1 <= submission_id <= MAX_ID
    submission = (
        session.get(Submission, submission_id, options=[joinedload(Submission.student)]) if in_range else None
    )
    if (
        submission is None
        or submission.assignment_id != assignment.id
        or (caller.student is not None and submission.student_id != caller.student.id)
    ):
        raise SubmissionNotFound(
            f"no submission {submission_id} among yours; list them with GET /submissions"
        )
    return submission


def list_submissions(
    session: Session,
    caller: Principal,
    assignment: Assignment,
    student_name: str | None = None,
    *,
    enrolment: Student | None = None,
) -> list[Submission]:
    """The caller's submissions to the assignment (all of them, or one student's, for its staff: the
    ``enrolment``, or the course's student called ``student_name``), newest first. Their files and progress
    are not read (a listing shows neither), nor, for the staff, their reports: staff see every problem
    (``api.disclosure.FULL``), so no total is withheld from them and :func:`summary` reads no report (a
    report is a row's largest column: 100 of them were most of a staff listing's time,
    bench/service_scale.py)."""
    unread = [Submission.content, Submission.progress, *([Submission.report] if caller.is_instructor else [])]
    query = (
        select(Submission)
        .options(joinedload(Submission.student), *(defer(column) for column in unread))
        .where(Submission.assignment_id == assignment.id)
        .order_by(Submission.id.desc())
    )
    if caller.student is not None:
        query = query.where(Submission.student_id == caller.student.id)
    elif enrolment is not None:
        query = query.where(Submission.student_id == enrolment.id)
    elif student_name is not None:
        student = find_student(session, assignment.course_id, student_name)
        query = query.where(Submission.student_id == student.id)
    return list(session.scalars(query))


def count_by_status(session: Session) -> dict[str, int]:
    """How many submissions are in each job status."""
    rows = session.execute(select(Submission.status, func.count(Submission.id)).group_by(Submission.status))
    return {status: count for status, count in rows}


def summary(submission: Submission, disclosure: Disclosure) -> SubmissionSummary:
    """The listing view of a submission (no total score where ``disclosure`` withholds a problem; the report
    is not read where it shows everything)."""
    withheld = not disclosure.everything and withholds_any(submission.report, disclosure)
    return SubmissionSummary(
        id=submission.id,
        student=submission.student.name,
        filename=submission.filename,
        sha256=submission.sha256,
        status=submission.status,  # type: ignore[arg-type]
        score=None if withheld else submission.score,
        max_score=submission.max_score,
        created_at=submission.created_at,
        finished_at=submission.finished_at,
    )


def detail(
    submission: Submission, disclosure: Disclosure, overrides: Sequence[OverrideShown] = ()
) -> SubmissionDetail:
    """A submission with its progress while running, its report once done and the instructor's overrides
    that count for it (``api.overrides.overrides_shown``), as ``disclosure`` allows."""
    report = submission.report if submission.status == JobStatus.DONE.value else None
    return SubmissionDetail(
        **summary(submission, disclosure).model_dump(),
        seed=submission.seed if disclosure.seeds else None,
        started_at=submission.started_at,
        attempts=submission.attempts,
        progress=[problem_view(problem, disclosure) for problem in submission.progress],
        report=report_view(report, disclosure) if report is not None else None,
        error=submission.error,
        overrides=list(overrides),
    )
