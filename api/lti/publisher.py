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

A round sends its due rows in parallel, at most ``GYMGRADE_LTI_PUBLISH_CONCURRENCY`` at once to each
platform (and at most ``MAX_SENDERS`` in all), each sender with its own database session, which gives its
connection back while the platform answers; every sender reuses the platform's access token
(:class:`api.lti.services.AccessTokens` asks for one once), and a link's line item is made by one sender
while the others of the link wait.
"""

from __future__ import annotations

import logging
import threading
from collections import defaultdict
from collections.abc import Iterator, Sequence
from concurrent.futures import ThreadPoolExecutor
from contextlib import contextmanager
from dataclasses import dataclass, field
from datetime import datetime, timedelta
from typing import Any

from sqlalchemy import func, select, update
from sqlalchemy.orm import Session, sessionmaker

from api.courses import gradebook_policy_of
from api.gradebook import final_grades, final_total, kept_submissions, with_reports
from api.lti.claims import SCOPE_LINEITEM, SCOPE_LINEITEM_READONLY, SCOPE_SCORE
from api.lti.outbound import Outbound, OutboundPolicy
from api.lti.services import AccessTokens, Grant, ServiceFailed, line_item, publish_score
from api.models import (
    Assignment,
    JobStatus,
    LtiLink,
    LtiMember,
    LtiPlatform,
    LtiScore,
    LtiUser,
    Override,
    Student,
    Submission,
    utcnow,
)
from api.settings import Settings

log = logging.getLogger(__name__)

MAX_RETRY_SECONDS = 600.0
CLAIM_SECONDS = 120.0
"""A claimed row is left alone by other servers this long (a send takes at most a few HTTP timeouts)."""
MAX_SENDERS = 16
"""The most scores one server sends at once over every platform: each sender holds a database session
(the engine's pool of 30 connections is shared with the requests)."""


PENDING, SENT, RETRYING, FAILED = "pending", "sent", "retrying", "failed"
"""A row's states: to send; the platform holds its score; refused, sent again later; refused
``GYMGRADE_LTI_PUBLISH_ATTEMPTS`` times (still sent again every 10 minutes, and shown to the instructor)."""


@dataclass(frozen=True)
class PublishPolicy:
    """How scores are published: how often a refused one is retried (which score is kept is each
    assignment's gradebook policy)."""

    attempts: int
    retry_seconds: float
    concurrency: int = 8
    """The most scores sent to one platform at once."""

    @classmethod
    def of(cls, settings: Settings) -> PublishPolicy:
        """The policy the settings give."""
        return cls(
            settings.lti_publish_attempts, settings.lti_retry_seconds, settings.lti_publish_concurrency
        )

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
    computes it (``api.gradebook.final_grades``).

    Only the enrolments the decisions can change are computed so, with their reports read: every one under a
    late policy, else those with an override of the assignment; the others' total is the machine's score
    (``final_total``'s without decisions). A round every two seconds thus reads no report where nobody was
    overridden (10,000 learners' reports were about 130 MB of JSON a round; bench/lti_publisher.py).
    """
    assignment = session.get_one(Assignment, assignment_id)
    late = assignment.late_policy is not None
    if late:
        decided = kept
    else:
        overridden = set(
            session.scalars(select(Override.student_id).where(Override.assignment_id == assignment_id))
        )
        decided = {student_id: row for student_id, row in kept.items() if student_id in overridden}
    finals = final_grades(session, assignment, with_reports(session, decided)) if decided else {}
    return {
        student_id: final_total(finals[student_id], row, late=late) if student_id in finals else row.score
        for student_id, row in kept.items()
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
            Submission.sha256,
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


@dataclass
class _Round:
    """What the senders of one round share: the slots of each platform (``concurrency`` sends in flight at
    most) and a lock per link, so that its line item is made once."""

    concurrency: int
    _guard: threading.Lock = field(default_factory=threading.Lock)
    _slots: dict[int, threading.BoundedSemaphore] = field(default_factory=dict)
    _links: defaultdict[int, threading.Lock] = field(default_factory=lambda: defaultdict(threading.Lock))

    @contextmanager
    def slot(self, platform_id: int) -> Iterator[None]:
        """Hold one of the platform's slots while sending to it."""
        with self._guard:
            slots = self._slots.setdefault(platform_id, threading.BoundedSemaphore(self.concurrency))
        with slots:
            yield

    def link_lock(self, link_id: int) -> threading.Lock:
        """The lock of a link's line item."""
        with self._guard:
            return self._links[link_id]


def send_due(sessions: sessionmaker[Session], tokens: AccessTokens, policy: PublishPolicy) -> int:
    """Send every row that is due (pending, or retrying and waited enough), at most ``policy.concurrency``
    at once to each platform; return how many were accepted."""
    now = utcnow()
    with sessions() as session:
        due = session.execute(
            select(LtiScore.id, LtiScore.next_attempt_at, LtiLink.platform_id)
            .join(LtiMember, LtiMember.id == LtiScore.member_id)
            .join(LtiLink, LtiLink.id == LtiMember.link_id)
            .where(LtiScore.status.in_((PENDING, RETRYING, FAILED)), LtiScore.next_attempt_at <= now)
            .order_by(LtiScore.id)
        ).all()
    if not due:
        return 0
    shared = _Round(policy.concurrency)
    platforms = len({row.platform_id for row in due})
    senders = max(1, min(MAX_SENDERS, policy.concurrency * platforms, len(due)))
    with ThreadPoolExecutor(max_workers=senders, thread_name_prefix="gymgrade-lti-send") as pool:
        accepted = pool.map(
            lambda row: _claim_and_send(sessions, tokens, policy, shared, row, now), _interleaved(due)
        )
        return sum(accepted)


def _interleaved(due: Sequence[Any]) -> list[Any]:
    """The due rows taking the platforms in turn, so that one platform's waits hold back no other's."""
    by_platform: dict[int, list[Any]] = defaultdict(list)
    for row in due:
        by_platform[row.platform_id].append(row)
    queues = list(by_platform.values())
    return [queue[index] for index in range(max(map(len, queues))) for queue in queues if index < len(queue)]


def _claim_and_send(
    sessions: sessionmaker[Session],
    tokens: AccessTokens,
    policy: PublishPolicy,
    shared: _Round,
    due: Any,
    now: datetime,
) -> int:
    with shared.slot(due.platform_id), sessions() as session:
        claimed = session.execute(
            update(LtiScore)
            .where(LtiScore.id == due.id, LtiScore.next_attempt_at == due.next_attempt_at)
            .values(next_attempt_at=now + timedelta(seconds=CLAIM_SECONDS))
        )
        session.commit()
        if claimed.rowcount != 1:  # type: ignore[attr-defined]
            return 0
        # One query for the row and what its send reads: _send's gets then find them in the session.
        row = session.execute(
            select(LtiScore, LtiMember, LtiLink, LtiUser, LtiPlatform)
            .join(LtiMember, LtiMember.id == LtiScore.member_id)
            .join(LtiLink, LtiLink.id == LtiMember.link_id)
            .join(LtiUser, LtiUser.id == LtiMember.user_id)
            .join(LtiPlatform, LtiPlatform.id == LtiLink.platform_id)
            .where(LtiScore.id == due.id)
        ).one()[0]
        return _send(session, tokens, policy, shared, row)


def _scopes(link: LtiLink) -> tuple[str, ...]:
    """The AGS scopes to ask for: those the launch granted (an LMS may refuse any other), score always."""
    wanted = (SCOPE_LINEITEM, SCOPE_LINEITEM_READONLY, SCOPE_SCORE)
    return tuple(scope for scope in wanted if scope in link.ags_scopes or scope == SCOPE_SCORE)


def _line_item(session: Session, shared: _Round, link: LtiLink, grant: Grant, maximum: float) -> str:
    """The link's line item URL, found or made by one sender while the others of the link wait."""
    with shared.link_lock(link.id):
        session.refresh(link)
        if not link.lineitem_url:
            link.lineitem_url = line_item(link, grant, score_maximum=maximum)
            session.commit()
        return link.lineitem_url


def _send(
    session: Session, tokens: AccessTokens, policy: PublishPolicy, shared: _Round, row: LtiScore
) -> int:
    member = session.get(LtiMember, row.member_id)
    assert member is not None  # a foreign key
    link = session.get(LtiLink, member.link_id)
    user = session.get(LtiUser, member.user_id)
    assert link is not None and user is not None
    platform = session.get(LtiPlatform, link.platform_id)
    assert platform is not None
    sending = (row.submission_id, row.score)
    try:
        grant = tokens.token(session, platform, _scopes(link))
        lineitem_url = link.lineitem_url
        if not lineitem_url:
            if row.max_score is None:
                raise ServiceFailed("the link has no line item yet; it is made with the first score")
            lineitem_url = _line_item(session, shared, link, grant, row.max_score)
        session.commit()  # the connection goes back to the pool while the platform answers
        publish_score(
            lineitem_url,
            grant,
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
        return send_due(self._sessions, self._tokens, self._policy)

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
