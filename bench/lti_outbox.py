"""LTI score publishing: what one idle round of the server's publisher costs (issue 37).

Every `GYMGRADE_LTI_PUBLISH_SECONDS` (2 s) the server brings each LMS member's outbox row up to the
score its link's assignment keeps (`api.lti.publisher.sync_outbox`), reading the graded submissions of
every member. This measures that round on SQLite for one LMS course (a course bound to an LTI context, its
assignment keeping the best upload, one resource link to it) of STUDENTS learners (platform users, enrolled
and members of the link) with SUBMISSIONS graded uploads each (no overrides, no late policy), when nothing
changed (the usual case: checked to change no row) and when every row is made (the first round), and the
tool key's first generation (encrypted, as a production server stores it). Usage: ``python
bench/lti_outbox.py [--students 300] [--submissions 10] [--rounds 20] [--write]`` (``--write`` replaces
the section in bench/RESULTS.md).
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from cryptography.fernet import Fernet
from pydantic import SecretStr
from sqlalchemy import select
from sqlalchemy.orm import Session, sessionmaker

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from results_section import replace_section  # noqa: E402

from api.courses import assignment_values, create_assignment, create_course  # noqa: E402
from api.database import make_engine, make_session_factory, migrate  # noqa: E402
from api.lti.claims import SCOPE_LINEITEM, SCOPE_SCORE  # noqa: E402
from api.lti.keys import protect_keys, signing_key  # noqa: E402
from api.lti.publisher import sync_outbox  # noqa: E402
from api.models import LtiLink, LtiMember, LtiPlatform, LtiScore, LtiUser, Student, Submission, utcnow  # noqa: E402
from api.schemas import AssignmentCreate  # noqa: E402
from api.settings import Settings  # noqa: E402

HEADING = "## LTI score outbox (issue 37)"
LMS = "https://lms.example"
MAX_SCORE = 6.0


@dataclass(frozen=True)
class Figures:
    """What one run measured (seconds)."""

    first_rows: int
    first: float
    idle: list[float]
    key: float


def populate(sessions: sessionmaker[Session], students: int, submissions: int) -> None:
    """An LMS course of ``students`` learners with ``submissions`` graded uploads each, as launches and a
    roster import leave it: the platform, a course bound to its context, the course's assignment (keeping
    the best upload) and the resource link opening it with its line item, and per learner a platform user,
    their enrolment and their membership of the link."""
    with sessions() as session:
        lms = LtiPlatform(
            issuer=LMS,
            client_id="bench",
            deployment_ids=["d"],
            jwks_url=f"{LMS}/jwks",
            auth_url=f"{LMS}/auth",
            token_url=f"{LMS}/token",
        )
        session.add(lms)
        session.flush()
        course = create_course(session, "rl-2026", "Reinforcement learning 2026")
        course.lti_platform_id, course.lti_deployment_id, course.lti_context_id = lms.id, "d", "context-1"
        assignment = create_assignment(
            session,
            course,
            assignment_values(
                AssignmentCreate(slug="opengym", title="OpenGym AI lab", gradebook_policy="best")
            ),
        )
        link = LtiLink(
            platform_id=lms.id,
            assignment_id=assignment.id,
            deployment_id="d",
            context_id="context-1",
            resource_link_id="link-1",
            title=assignment.title,
            lineitems_url=f"{LMS}/lineitems",
            lineitem_url=f"{LMS}/lineitems/1",
            ags_scopes=[SCOPE_LINEITEM, SCOPE_SCORE],
            custom={},
        )
        session.add(link)
        session.flush()
        for number in range(students):
            user = LtiUser(platform_id=lms.id, sub=f"learner-{number}", name=f"Learner {number}")
            session.add(user)
            session.flush()
            student = Student(
                course_id=course.id, name=user.name, token_sha256=f"{number:064d}", lti_user_id=user.id
            )
            session.add(student)
            session.flush()
            session.add(LtiMember(link_id=link.id, user_id=user.id))
            for upload in range(submissions):
                session.add(
                    Submission(
                        assignment_id=assignment.id,
                        student_id=student.id,
                        filename="opengym.py",
                        sha256=f"{upload:064d}",
                        content=b"x" * 2000,
                        size=2000,
                        seed=upload,
                        status="done",
                        score=float((number + upload) % 7),
                        max_score=MAX_SCORE,
                        finished_at=utcnow(),
                        progress=[],
                        report={"problems": [{"id": "p", "score": 1.0}] * 8},
                    )
                )
        session.commit()


def outbox(session: Session) -> list[tuple[Any, ...]]:
    """Every outbox row, all its columns."""
    return [tuple(row) for row in session.execute(select(*LtiScore.__table__.columns).order_by(LtiScore.id))]


def measure(directory: Path, students: int, submissions: int, rounds: int) -> Figures:
    """Populate a new SQLite database in ``directory``, make the tool's key, run the first round and then
    ``rounds`` idle ones (each checked to change no outbox row)."""
    settings = Settings(
        data_dir=directory,
        development=True,
        key_encryption_key=SecretStr(Fernet.generate_key().decode("ascii")),
    )
    engine = make_engine(settings)
    try:
        migrate(engine)
        sessions = make_session_factory(engine)
        protect_keys(sessions, settings)
        populate(sessions, students, submissions)
        with sessions() as session:
            started = time.perf_counter()
            signing_key(session)
            key = time.perf_counter() - started
            started = time.perf_counter()
            first_rows = sync_outbox(session)
            first = time.perf_counter() - started
            if first_rows != students:
                raise RuntimeError(
                    f"the first round made {first_rows} rows; expected one per learner ({students})"
                )
            before = outbox(session)
            idle = []
            for number in range(rounds):
                started = time.perf_counter()
                changed = sync_outbox(session)
                idle.append(time.perf_counter() - started)
                after = outbox(session)
                if changed or after != before:
                    raise RuntimeError(
                        f"idle round {number + 1} changed {changed} rows "
                        f"({sum(a != b for a, b in zip(before, after, strict=True))} differ); expected none"
                    )
    finally:
        engine.dispose()
    return Figures(first_rows, first, idle, key)


def section(args: argparse.Namespace, figures: Figures) -> str:
    """The RESULTS.md section."""
    return (
        f"{HEADING}\n\n"
        f"`python bench/lti_outbox.py --students {args.students} --submissions {args.submissions} "
        f"--rounds {args.rounds}`, {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, "
        f"{platform.machine()} ({os.cpu_count()} cores, shared; load average {os.getloadavg()[0]:.1f} "
        f"while measured), Python {platform.python_version()}, SQLite: one LMS course (its assignment "
        f"keeping the best upload, one link), {args.students} learners, "
        f"{args.students * args.submissions} graded submissions, no overrides, no late policy.\n\n"
        "| what | seconds |\n|---|---|\n"
        f"| first round ({figures.first_rows} rows made) | {figures.first:.3f} |\n"
        f"| idle round, median of {args.rounds} (no row changed: checked) | "
        f"{statistics.median(figures.idle):.3f} |\n"
        f"| idle round, slowest | {max(figures.idle):.3f} |\n"
        f"| the tool's RSA-2048 key, generated, encrypted and stored once | {figures.key:.3f} |\n\n"
        "An idle round every 2 s (`GYMGRADE_LTI_PUBLISH_SECONDS`) reads the members and their graded rows' "
        "ids and scores (not the reports: no overrides, no late policy).\n"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--students", type=int, default=300)
    parser.add_argument("--submissions", type=int, default=10)
    parser.add_argument("--rounds", type=int, default=20)
    parser.add_argument("--write", action="store_true")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as directory:
        figures = measure(Path(directory), args.students, args.submissions, args.rounds)
    text = section(args, figures)
    print(text)
    if args.write:
        replace_section(HEADING, text)


if __name__ == "__main__":
    main()
