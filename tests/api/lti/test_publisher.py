"""The score outbox: which score each LMS member gets, when it is sent again, and when never."""

from __future__ import annotations

import time
from collections.abc import Iterator
from datetime import timedelta
from typing import Any

import pytest
from api_testing import BOTH_DATABASES, SettingsFactory
from cryptography.fernet import Fernet
from scores_platform import ScoresPlatform
from sqlalchemy import event, select
from sqlalchemy.orm import Session

from api.courses import DEFAULT_ASSIGNMENT_ID, DEFAULT_COURSE_ID
from api.database import make_engine, make_session_factory, migrate
from api.lti.claims import SCOPE_LINEITEM, SCOPE_SCORE
from api.lti.keys import protect_keys
from api.lti.publisher import (
    FAILED,
    PENDING,
    RETRYING,
    SENT,
    PublishPolicy,
    ScorePublisher,
    publishing_status,
    sync_outbox,
)
from api.models import (
    Assignment,
    LtiLink,
    LtiMember,
    LtiPlatform,
    LtiScore,
    LtiUser,
    Student,
    Submission,
    utcnow,
)
from api.overrides import record_override
from api.settings import GradebookPolicy


@pytest.fixture
def session(make_settings: SettingsFactory) -> Iterator[Session]:
    engine = make_engine(make_settings())
    migrate(engine)
    with make_session_factory(engine)() as opened:
        yield opened
    engine.dispose()


def _member(session: Session, name: str, lineitem_url: str | None = None) -> tuple[Student, LtiMember]:
    platform = session.query(LtiPlatform).first()
    if platform is None:
        platform = LtiPlatform(
            issuer="https://lms.example",
            client_id="c",
            deployment_ids=["d"],
            jwks_url="https://lms.example/jwks",
            auth_url="https://lms.example/auth",
            token_url="https://lms.example/token",
        )
        session.add(platform)
        session.flush()
        session.add(
            LtiLink(
                platform_id=platform.id,
                deployment_id="d",
                context_id="course",
                resource_link_id="link",
                assignment_id=DEFAULT_ASSIGNMENT_ID,
                title="",
                ags_scopes=[],
                custom={},
            )
        )
        session.flush()
    link = session.query(LtiLink).one()
    link.lineitem_url = lineitem_url
    user = LtiUser(platform_id=platform.id, sub="sub-" + name, name=name)
    session.add(user)
    session.flush()
    student = Student(
        course_id=DEFAULT_COURSE_ID, name=name, token_sha256=name.ljust(64, "0"), lti_user_id=user.id
    )
    session.add(student)
    session.flush()
    member = LtiMember(link_id=link.id, user_id=user.id)
    session.add(member)
    session.commit()
    return student, member


def _graded(session: Session, student: Student, score: float, status: str = "done") -> Submission:
    row = Submission(
        assignment_id=DEFAULT_ASSIGNMENT_ID,
        student_id=student.id,
        filename="opengym.py",
        sha256="0" * 64,
        content=b"x",
        size=1,
        seed=1,
        status=status,
        score=score if status == "done" else None,
        max_score=3.0 if status == "done" else None,
        finished_at=utcnow(),
        progress=[],
    )
    session.add(row)
    session.commit()
    return row


def _sync(session: Session, policy: GradebookPolicy) -> int:
    """One outbox round with the default assignment keeping its ``policy``'s score."""
    session.get_one(Assignment, DEFAULT_ASSIGNMENT_ID).gradebook_policy = policy.value
    session.commit()
    return sync_outbox(session)


def _row(session: Session, member: LtiMember) -> LtiScore:
    session.expire_all()
    return session.query(LtiScore).filter_by(member_id=member.id).one()


def _as_sent(session: Session, member: LtiMember) -> None:
    row = _row(session, member)
    row.sent_submission_id, row.sent_score, row.status = row.submission_id, row.score, SENT
    session.commit()


@BOTH_DATABASES
def test_a_regrade_that_changes_the_score_is_sent_again_and_one_that_does_not_is_not(
    session: Session,
) -> None:
    student, member = _member(session, "ada")
    submission = _graded(session, student, 1.0)
    assert _sync(session, GradebookPolicy.LATEST) == 1
    assert (_row(session, member).status, _row(session, member).score) == (PENDING, 1.0)
    _as_sent(session, member)

    submission.status = "queued"  # a regrade: the row is graded again
    session.commit()
    assert _sync(session, GradebookPolicy.LATEST) == 0, "a score still held by the LMS"
    submission.status, submission.score = "done", 1.0
    session.commit()
    assert _sync(session, GradebookPolicy.LATEST) == 0
    assert _row(session, member).status == SENT

    submission.score = 2.0  # the regrade found more
    session.commit()
    assert _sync(session, GradebookPolicy.LATEST) == 1
    assert (_row(session, member).status, _row(session, member).score) == (PENDING, 2.0)


@pytest.mark.parametrize(
    ("policy", "kept"), [(GradebookPolicy.LATEST, 1.0), (GradebookPolicy.BEST, 3.0)], ids=["latest", "best"]
)
def test_the_gradebook_policy_chooses_the_score_sent(
    session: Session, policy: GradebookPolicy, kept: float
) -> None:
    student, member = _member(session, "bea")
    for score in (2.0, 3.0, 1.0):
        _graded(session, student, score)
    _graded(session, student, 0.0, status="failed")
    _graded(session, student, 0.0, status="queued")
    _sync(session, policy)
    assert _row(session, member).score == kept


def test_a_student_without_a_graded_submission_gets_no_row(session: Session) -> None:
    student, _ = _member(session, "cy")
    _graded(session, student, 0.0, status="running")
    assert _sync(session, GradebookPolicy.LATEST) == 0
    assert publishing_status(session, DEFAULT_COURSE_ID) == []


def test_going_back_to_the_score_the_lms_holds_sends_nothing(session: Session) -> None:
    student, member = _member(session, "dee")
    first = _graded(session, student, 2.0)
    _sync(session, GradebookPolicy.BEST)
    _as_sent(session, member)
    later = _graded(session, student, 3.0)
    _sync(session, GradebookPolicy.BEST)
    assert (_row(session, member).status, _row(session, member).submission_id) == (PENDING, later.id)
    later.score = 1.0  # regraded lower before it was sent: the best is the score the LMS holds already
    session.commit()
    _sync(session, GradebookPolicy.BEST)
    row = _row(session, member)
    assert (row.status, row.submission_id, row.score) == (SENT, first.id, 2.0)


def test_the_instructor_sees_each_students_state_and_error(session: Session) -> None:
    student, member = _member(session, "eve")
    _graded(session, student, 1.0)
    _sync(session, GradebookPolicy.LATEST)
    row = _row(session, member)
    row.status, row.attempts, row.error = RETRYING, 2, "publishing the score: the LMS answered 500"
    row.next_attempt_at = utcnow() + timedelta(seconds=4)
    session.commit()
    (shown,) = publishing_status(session, DEFAULT_COURSE_ID)
    assert shown["student"] == "eve"
    assert (shown["status"], shown["attempts"], shown["error"]) == (
        RETRYING,
        2,
        "publishing the score: the LMS answered 500",
    )
    assert shown["sent_score"] is None


@pytest.mark.parametrize(
    ("attempts", "seconds"),
    [(1, 2.0), (2, 4.0), (3, 8.0), (8, 256.0), (9, 512.0), (10, 600.0), (40, 600.0)],
    ids=lambda value: str(value),
)
def test_refused_sends_wait_twice_as_long_each_time_up_to_ten_minutes(attempts: int, seconds: float) -> None:
    assert PublishPolicy(8, 2.0).wait(attempts) == seconds


def test_the_states_are_distinct() -> None:
    assert len({PENDING, SENT, RETRYING, FAILED}) == 4


@pytest.mark.parametrize(
    ("lineitem_url", "expected"),
    [("https://lms.example/lineitems/1", [(PENDING, None)]), (None, [])],
    ids=["the-link-has-a-line-item", "no-line-item-yet"],
)
def test_a_submission_being_graded_is_announced_without_a_score_where_the_line_item_exists(
    session: Session, lineitem_url: str | None, expected: list[tuple[str, float | None]]
) -> None:
    student, member = _member(session, "fay", lineitem_url)
    submission = _graded(session, student, 0.0, status="queued")
    _sync(session, GradebookPolicy.LATEST)
    session.expire_all()
    assert [(row.status, row.score) for row in session.query(LtiScore).all()] == expected
    if not expected:
        return
    _as_sent(session, member)
    submission.status, submission.score, submission.max_score = "done", 2.0, 3.0
    session.commit()
    _sync(session, GradebookPolicy.LATEST)
    assert (_row(session, member).status, _row(session, member).score) == (PENDING, 2.0)


def test_a_new_upload_never_announces_pending_over_a_score_the_lms_holds(session: Session) -> None:
    student, member = _member(session, "gus", "https://lms.example/lineitems/1")
    graded = _graded(session, student, 2.0)
    _sync(session, GradebookPolicy.LATEST)
    _as_sent(session, member)
    _graded(session, student, 0.0, status="running")
    assert _sync(session, GradebookPolicy.LATEST) == 0
    assert (_row(session, member).status, _row(session, member).submission_id) == (SENT, graded.id)


def test_a_regrade_of_the_only_graded_upload_never_announces_pending_over_its_score(session: Session) -> None:
    student, member = _member(session, "hal", "https://lms.example/lineitems/1")
    submission = _graded(session, student, 2.0)
    _sync(session, GradebookPolicy.LATEST)
    _as_sent(session, member)
    submission.status = "running"  # regraded: for a while nothing of the student's is graded
    session.commit()
    assert _sync(session, GradebookPolicy.LATEST) == 0
    assert (_row(session, member).status, _row(session, member).score) == (SENT, 2.0)


def test_the_publisher_counts_its_finished_rounds_and_says_when_it_stopped(
    make_settings: SettingsFactory,
) -> None:
    settings = make_settings(lti_publish_seconds=0.01)
    engine = make_engine(settings)
    migrate(engine)
    publisher = ScorePublisher(make_session_factory(engine), settings)
    assert publisher.progress() == {
        "running": False,
        "period_seconds": 0.01,
        "rounds": 0,
        "last_round_at": None,
    }
    publisher.start()
    try:
        deadline = time.monotonic() + 60  # bounds a hang only: the loop ends at the second round
        while publisher.progress()["rounds"] < 2:
            assert time.monotonic() < deadline, publisher.progress()
            time.sleep(0.01)
        running = publisher.progress()
    finally:
        publisher.stop()
    engine.dispose()
    assert running["running"] and running["last_round_at"] is not None
    stopped = publisher.progress()
    assert not stopped["running"] and stopped["rounds"] >= running["rounds"]
    assert stopped["last_round_at"] >= running["last_round_at"]


def test_the_lms_is_sent_the_final_score_again_when_an_override_or_the_late_policy_changes_it(
    session: Session,
) -> None:
    student, member = _member(session, "ida")
    submission = _graded(session, student, 2.0)
    submission.report = {"problems": [{"id": "car", "score": 2.0, "max_score": 3.0}]}
    assignment = session.get_one(Assignment, DEFAULT_ASSIGNMENT_ID)
    _sync(session, GradebookPolicy.LATEST)
    _as_sent(session, member)
    record_override(
        session, assignment, student_name="ida", problem="car", points=3.0, reason="by hand", author="t"
    )
    assert _sync(session, GradebookPolicy.LATEST) == 1
    assert (_row(session, member).status, _row(session, member).score) == (PENDING, 3.0)
    _as_sent(session, member)
    due = submission.created_at - timedelta(days=1, seconds=1)  # two days late: half the maximum (3) taken
    assignment.late_policy = {"due": due.isoformat() + "+00:00", "penalty_per_day": 0.25}
    session.commit()
    assert _sync(session, GradebookPolicy.LATEST) == 1
    assert (_row(session, member).status, _row(session, member).score) == (PENDING, 1.5)
    assert _sync(session, GradebookPolicy.LATEST) == 0, "an unchanged final score is not sent again"


def test_a_round_sends_each_score_once_at_most_the_concurrency_at_once_with_one_token_and_one_line_item(
    make_settings: SettingsFactory,
) -> None:
    settings = make_settings(
        lti_allow_http=True,
        lti_allowed_networks="127.0.0.0/8",
        key_encryption_key=Fernet.generate_key().decode("ascii"),
        lti_publish_concurrency=3,
    )
    engine = make_engine(settings)
    migrate(engine)
    sessions = make_session_factory(engine)
    protect_keys(sessions, settings)
    with ScoresPlatform(together=3).running() as lms, sessions() as session:
        platform = LtiPlatform(
            issuer=lms.url,
            client_id="c",
            deployment_ids=["d"],
            jwks_url=lms.url + "/jwks",
            auth_url=lms.url + "/auth",
            token_url=lms.url + "/token",
        )
        session.add(platform)
        session.flush()
        link = LtiLink(
            platform_id=platform.id,
            deployment_id="d",
            context_id="course",
            resource_link_id="link",
            assignment_id=DEFAULT_ASSIGNMENT_ID,
            title="",
            lineitems_url=lms.url + "/lineitems",
            ags_scopes=[SCOPE_LINEITEM, SCOPE_SCORE],
            custom={},
        )
        session.add(link)
        session.flush()
        submissions = {}
        for number in range(9):
            user = LtiUser(platform_id=platform.id, sub=f"sub-{number}", name=f"p{number}")
            session.add(user)
            session.flush()
            student = Student(
                course_id=DEFAULT_COURSE_ID,
                name=f"p{number}",
                token_sha256=f"{number:064d}",
                lti_user_id=user.id,
            )
            session.add(student)
            session.add(LtiMember(link_id=link.id, user_id=user.id))
            session.commit()
            submissions[user.sub] = _graded(session, student, float(number % 3))
        publisher = ScorePublisher(sessions, settings)

        assert publisher.run_once() == 9
        assert lms.sends_by_user() == {f"sub-{number}": 1 for number in range(9)}
        assert lms.most_in_flight == 3, "three at once (the barrier lets none through alone), never more"
        assert (lms.tokens_granted, lms.line_items_made) == (1, 1)

        assert publisher.run_once() == 0, "an unchanged score is not sent again"
        submissions["sub-4"].score = 2.5
        session.commit()
        lms.one_at_a_time()
        assert publisher.run_once() == 1
        assert lms.sends_by_user() == {f"sub-{number}": 2 if number == 4 else 1 for number in range(9)}
        assert lms.scores[-1]["scoreGiven"] == 2.5
    engine.dispose()


def test_a_round_reads_the_reports_only_of_learners_an_override_or_a_late_policy_can_change(
    session: Session,
) -> None:
    plain, _ = _member(session, "jo")
    overridden, _ = _member(session, "kim")
    for student in (plain, overridden):
        _graded(session, student, 2.0).report = {"problems": [{"id": "car", "score": 2.0, "max_score": 3.0}]}
    session.commit()
    statements: list[tuple[str, Any]] = []

    def record(_connection: Any, _cursor: Any, statement: str, parameters: Any, *_rest: Any) -> None:
        statements.append((statement, parameters))

    event.listen(session.get_bind(), "before_cursor_execute", record)
    try:
        _sync(session, GradebookPolicy.LATEST)
        assert not [sql for sql, _ in statements if "submissions.report" in sql], "nobody overridden"
        record_override(
            session,
            session.get_one(Assignment, DEFAULT_ASSIGNMENT_ID),
            student_name="kim",
            problem="car",
            points=3.0,
            reason="by hand",
            author="t",
        )
        statements.clear()
        _sync(session, GradebookPolicy.LATEST)
    finally:
        event.remove(session.get_bind(), "before_cursor_execute", record)
    (read,) = [parameters for sql, parameters in statements if "submissions.report" in sql]
    kim = session.scalars(select(Submission.id).where(Submission.student_id == overridden.id)).one()
    assert list(read) == [kim], "the overridden learner's report only"
