"""Scores to the LMS (LTI AGS) from a durable outbox: one ``lti_scores`` row per (link, member); a link opens
one assignment, and a member's score is their enrolment's in that assignment's course, of that assignment
only.

The row holds the kept score (``score`` None: nothing graded yet, a submission is being graded: the LMS
is told ``Submitted``/``Pending`` without a score; once graded, ``Completed``/``FullyGraded`` with it).

Each round (``GYMGRADE_LTI_PUBLISH_SECONDS``) first brings every row up to the final score of the submission
the assignment's gradebook policy keeps now: the instructor's overrides and the late penalty applied, as every
gradebook file computes it (``api.gradebook.final_grades``), read from the rows (the only truth: a regrade, a
better upload, an override or a changed late policy changes it, and the LMS is sent the new score), then
sends the rows that are due. A row is sent only while the kept score differs from the one the platform
last accepted, so the same score is never sent as two results; a refused send is retried with doubling
waits and its error shown to the instructor (``GET /lti/scores``), never touching the grading. Several
servers may run this: a row is claimed with a conditional UPDATE before it is sent.
"""

from __future__ import annotations

import logging
import threading
from dataclasses import dataclass
from datetime import datetime, timedelta
from typing import Any

from sqlalchemy import func, select, update
from sqlalchemy.orm import Session, sessionmaker

from api.courses import gradebook_policy_of
from api.gradebook import final_grades, final_total, kept_submissions
from api.lti.claims import SCOPE_LINEITEM, SCOPE_LINEITEM_READONLY, SCOPE_SCORE
from api.lti.outbound import Outbound, OutboundPolicy
from api.lti.services import AccessTokens, ServiceFailed, line_item, publish_score
from api.models import (
    Assignment,
    JobStatus,
    LtiLink,
    LtiMember,
    LtiPlatform,
    LtiScore,
    LtiUser,
    Student,
    Submission,
    utcnow,
)
from api.settings import Settings

log = logging.getLogger(__name__)

MAX_RETRY_SECONDS = 600.0
CLAIM_SECONDS = 120.0
"""A claimed row is left alone by other servers this long (a send takes at most a few HTTP timeouts)."""


PENDING, SENT, RETRYING, FAILED = "pending", "sent", "retrying", "failed"
"""A row's states: to send; the platform holds its score; refused, sent again later; refused
``GYMGRADE_LTI_PUBLISH_ATTEMPTS`` times (still sent again every 10 minutes, and shown to the instructor)."""


@dataclass(frozen=True)
class PublishPolicy:
    """How scores are published: how often a refused one is retried (which score is kept is each
    assignment's gradebook policy)."""

    attempts: int
    retry_seconds: float

    @classmethod
    def of(cls, settings: Settings) -> PublishPolicy:
        """The policy the settings give."""
        return cls(settings.lti_publish_attempts, settings.lti_retry_seconds)

    def wait(self, attempts: int) -> float:
        """Seconds before the next send after ``attempts`` refused ones (doubling, at most 10 minutes)."""
        return float(min(self.retry_seconds * 2 ** max(attempts - 1, 0), MAX_RETRY_SECONDS))


def sync_outbox(session: Session) -> int:
    """Bring each member's row to the score its link's assignment keeps now; return how many rows changed."""
    members = session.execute(
        select(LtiMember.id, Student.id, LtiLink.assignment_id, LtiLink.lineitem_url)
        .join(LtiLink, LtiLink.id == LtiMember.link_id)
        .join(Assignment, Assignment.id == LtiLink.assignment_id)
        .join(
            Student,
            (Student.lti_user_id == LtiMember.user_id) & (Student.course_id == Assignment.course_id),
        )
    ).all()
    if not members:
        return 0
    wanted_by_assignment = {
        assignment_id: _kept(
            session, assignment_id, {student for _, student, a, _ in members if a == assignment_id}
        )
        for assignment_id in {assignment_id for _, _, assignment_id, _ in members}
    }
    finals = {
        assignment_id: _final_totals(session, assignment_id, kept)
        for assignment_id, (kept, _) in wanted_by_assignment.items()
    }
    rows = {row.member_id: row for row in session.scalars(select(LtiScore))}
    changed = 0
    now = utcnow()
    for member_id, student_id, assignment_id, lineitem_url in members:
        kept, in_progress = wanted_by_assignment[assignment_id]
        chosen = kept.get(student_id)
        if chosen is not None:
            wanted: tuple[int, float | None, float | None] = (
                chosen.id,
                float(finals[assignment_id][student_id] or 0.0),
                float(chosen.max_score or 0.0),
            )
        elif student_id in in_progress and lineitem_url and _holds_no_score(rows.get(member_id)):
            # Nothing graded (a first upload, or the only one being regraded): the LMS is told a submission
            # is being graded, without a score, unless it holds one (which that would erase). Only where
            # the line item exists: making one needs the score's maximum.
            wanted = (in_progress[student_id], None, None)
        else:
            continue
        row = rows.get(member_id)
        if row is not None and (row.submission_id, row.score, row.max_score) == wanted:
            continue
        if row is None:
            row = LtiScore(member_id=member_id, attempts=0)
            session.add(row)
        row.submission_id, row.score, row.max_score = wanted
        row.timestamp = now  # later than any score sent before: an LMS keeps the newest
        already = (row.sent_submission_id, row.sent_score) == wanted[:2]
        row.status = SENT if already else PENDING
        row.attempts, row.next_attempt_at, row.error = 0, now, None
        changed += 1
    session.commit()
    return changed


def _final_totals(session: Session, assignment_id: int, kept: dict[int, Any]) -> dict[int, float | None]:
    """The final total of each kept submission: overrides and late penalty applied, as every gradebook file
    computes it (``api.gradebook.final_grades``)."""
    assignment = session.get_one(Assignment, assignment_id)
    late = assignment.late_policy is not None
    return {
        student_id: final_total(final, kept[student_id], late=late)
        for student_id, final in final_grades(session, assignment, kept).items()
    }


def _kept(session: Session, assignment_id: int, students: set[int]) -> tuple[dict[int, Any], dict[int, int]]:
    """The submission of the assignment each of ``students`` is represented by, and their newest one being
    graded (by enrolment id)."""
    assignment = session.get_one(Assignment, assignment_id)
    graded = session.execute(
        select(
            Submission.id,
            Submission.student_id,
            Submission.score,
            Submission.max_score,
            Submission.created_at,
            Submission.report,
        )
        .where(
            Submission.assignment_id == assignment_id,
            Submission.status == JobStatus.DONE.value,
            Submission.student_id.in_(students),
        )
        .order_by(Submission.id)
    ).all()
    in_progress = dict(
        session.execute(
            select(Submission.student_id, func.max(Submission.id))
            .where(
                Submission.assignment_id == assignment_id,
                Submission.status.in_((JobStatus.QUEUED.value, JobStatus.RUNNING.value)),
                Submission.student_id.in_(students),
            )
            .group_by(Submission.student_id)
        ).all()
    )
    return kept_submissions(graded, gradebook_policy_of(assignment)), in_progress


def _holds_no_score(row: LtiScore | None) -> bool:
    return row is None or row.sent_score is None


def send_due(session: Session, tokens: AccessTokens, policy: PublishPolicy) -> int:
    """Send every row that is due (pending, or retrying and waited enough); return how many were accepted."""
    now = utcnow()
    due = list(
        session.scalars(
            select(LtiScore).where(
                LtiScore.status.in_((PENDING, RETRYING, FAILED)), LtiScore.next_attempt_at <= now
            )
        )
    )
    accepted = 0
    for row in due:
        claimed = session.execute(
            update(LtiScore)
            .where(LtiScore.id == row.id, LtiScore.next_attempt_at == row.next_attempt_at)
            .values(next_attempt_at=now + timedelta(seconds=CLAIM_SECONDS))
        )
        session.commit()
        if claimed.rowcount != 1:  # type: ignore[attr-defined]
            continue
        session.refresh(row)
        accepted += _send(session, tokens, policy, row)
    return accepted


def _scopes(link: LtiLink) -> tuple[str, ...]:
    """The AGS scopes to ask for: those the launch granted (an LMS may refuse any other), score always."""
    wanted = (SCOPE_LINEITEM, SCOPE_LINEITEM_READONLY, SCOPE_SCORE)
    return tuple(scope for scope in wanted if scope in link.ags_scopes or scope == SCOPE_SCORE)


def _send(session: Session, tokens: AccessTokens, policy: PublishPolicy, row: LtiScore) -> int:
    member = session.get(LtiMember, row.member_id)
    assert member is not None  # a foreign key
    link = session.get(LtiLink, member.link_id)
    user = session.get(LtiUser, member.user_id)
    assert link is not None and user is not None
    platform = session.get(LtiPlatform, link.platform_id)
    assert platform is not None
    sending = (row.submission_id, row.score)
    try:
        token = tokens.token(session, platform, _scopes(link))
        if not link.lineitem_url:
            if row.max_score is None:
                raise ServiceFailed("the link has no line item yet; it is made with the first score")
            link.lineitem_url = line_item(link, token, score_maximum=row.max_score)
            session.commit()
        publish_score(
            link.lineitem_url,
            token,
            user_id=user.sub,
            score=row.score,
            maximum=row.max_score,
            timestamp=row.timestamp,
        )
    except ServiceFailed as error:
        tokens.forget(platform)
        row.attempts += 1
        row.status = FAILED if row.attempts >= policy.attempts else RETRYING
        row.error = str(error)[:2000]
        row.next_attempt_at = utcnow() + timedelta(seconds=policy.wait(row.attempts))
        session.commit()
        log.warning(
            "LTI score of member %s not published (attempt %s): %s", row.member_id, row.attempts, error
        )
        return 0
    session.refresh(row)
    row.sent_submission_id, row.sent_score = sending
    if (row.submission_id, row.score) == sending:
        row.status, row.error, row.attempts = SENT, None, 0
    session.commit()
    return 1


def publishing_status(
    session: Session, course_id: int | None, assignment_id: int | None = None
) -> list[dict[str, Any]]:
    """Each student's row of the course (None: of every course) and assignment (None: every one of it): the
    kept score, the one the LMS holds, the state, the attempts, the last error."""
    query = (
        select(LtiScore, LtiMember, Student)
        .join(LtiMember, LtiMember.id == LtiScore.member_id)
        .join(LtiLink, LtiLink.id == LtiMember.link_id)
        .join(Assignment, Assignment.id == LtiLink.assignment_id)
        .join(
            Student,
            (Student.lti_user_id == LtiMember.user_id) & (Student.course_id == Assignment.course_id),
        )
        .order_by(Student.name, LtiMember.link_id)
    )
    if course_id is not None:
        query = query.where(Assignment.course_id == course_id)
    if assignment_id is not None:
        query = query.where(Assignment.id == assignment_id)
    rows = session.execute(query).all()
    return [
        {
            "student": student.name,
            "link_id": member.link_id,
            "submission_id": score.submission_id,
            "score": score.score,
            "max_score": score.max_score,
            "sent_score": score.sent_score,
            "status": score.status,
            "attempts": score.attempts,
            "error": score.error,
        }
        for score, member, student in rows
    ]


class ScorePublisher:
    """The server's publishing thread: :func:`sync_outbox` then :func:`send_due`, every period.

    It counts its finished rounds (:meth:`progress`, ``GET /lti/publisher``): an operator sees that publishing
    is alive, and a round that began after a change has seen that change.
    """

    def __init__(self, sessions: sessionmaker[Session], settings: Settings) -> None:
        self._sessions = sessions
        self._policy = PublishPolicy.of(settings)
        self._period = settings.lti_publish_seconds
        self._tokens = AccessTokens(Outbound(OutboundPolicy.of(settings)), settings.lti_hosts)
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name="gymgrade-lti-publisher", daemon=True)
        self._lock = threading.Lock()
        self._rounds = 0
        self._last_round_at: datetime | None = None

    def start(self) -> None:
        """Start publishing."""
        self._thread.start()

    def stop(self) -> None:
        """Stop after the current round."""
        self._stop.set()
        if self._thread.is_alive():
            self._thread.join(timeout=30)

    def run_once(self) -> int:
        """One round; returns the scores the platforms accepted."""
        with self._sessions() as session:
            sync_outbox(session)
            return send_due(session, self._tokens, self._policy)

    def progress(self) -> dict[str, Any]:
        """Whether the thread runs, its period, the rounds finished (failed ones too), the last one's end."""
        with self._lock:
            rounds, last = self._rounds, self._last_round_at
        return {
            "running": self._thread.is_alive(),
            "period_seconds": self._period,
            "rounds": rounds,
            "last_round_at": last,
        }

    def _run(self) -> None:
        while not self._stop.wait(self._period):
            try:
                self.run_once()
            except Exception:
                log.exception("LTI score publishing round failed; trying again next round")
            with self._lock:
                self._rounds += 1
                self._last_round_at = utcnow()
