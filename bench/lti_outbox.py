"""LTI score publishing: what one idle round of the server's publisher costs (issue 37).

Every `GYMGRADE_LTI_PUBLISH_SECONDS` (2 s) the server brings each LMS member's outbox row up to the
score the gradebook policy keeps (`api.lti.publisher.sync_outbox`), reading the graded submissions of
every member. This measures that round on SQLite for a course of STUDENTS students with SUBMISSIONS graded
uploads each, when nothing changed (the usual case) and when every row changes (the first round), and the
tool key's first generation. Usage: ``python bench/lti_outbox.py [--students 300] [--submissions 10]
[--rounds 20] [--write]`` (``--write`` replaces the section in bench/RESULTS.md).
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from results_section import replace_section  # noqa: E402

from api.database import make_engine, make_session_factory, migrate  # noqa: E402
from api.lti.keys import signing_key  # noqa: E402
from api.lti.publisher import sync_outbox  # noqa: E402
from api.models import LtiLink, LtiMember, LtiPlatform, LtiUser, Student, Submission, utcnow  # noqa: E402
from api.settings import GradebookPolicy, Settings  # noqa: E402

HEADING = "## LTI score outbox (issue 37)"


def populate(sessions: object, students: int, submissions: int) -> None:
    with sessions() as session:  # type: ignore[operator]
        lms = LtiPlatform(
            issuer="https://lms.example",
            client_id="c",
            deployment_ids=["d"],
            jwks_url="https://lms.example/j",
            auth_url="https://lms.example/a",
            token_url="https://lms.example/t",
        )
        session.add(lms)
        session.flush()
        link = LtiLink(
            platform_id=lms.id,
            deployment_id="d",
            context_id="c",
            resource_link_id="l",
            title="",
            ags_scopes=[],
            custom={},
        )
        session.add(link)
        session.flush()
        for number in range(students):
            student = Student(name=f"student {number}", token_sha256=f"{number:064d}")
            session.add(student)
            session.flush()
            user = LtiUser(platform_id=lms.id, sub=f"sub-{number}", student_id=student.id, name=student.name)
            session.add(user)
            session.flush()
            session.add(LtiMember(link_id=link.id, user_id=user.id))
            for upload in range(submissions):
                session.add(
                    Submission(
                        student_id=student.id,
                        filename="opengym.py",
                        sha256="0" * 64,
                        content=b"x" * 2000,
                        size=2000,
                        seed=upload,
                        status="done",
                        score=float(upload % 7),
                        max_score=6.0,
                        finished_at=utcnow(),
                        progress=[],
                        report={"problems": [{"id": "p", "score": 1.0}] * 8},
                    )
                )
        session.commit()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--students", type=int, default=300)
    parser.add_argument("--submissions", type=int, default=10)
    parser.add_argument("--rounds", type=int, default=20)
    parser.add_argument("--write", action="store_true")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as directory:
        engine = make_engine(Settings(data_dir=Path(directory), development=True))
        migrate(engine)
        sessions = make_session_factory(engine)
        populate(sessions, args.students, args.submissions)
        with sessions() as session:
            started = time.perf_counter()
            signing_key(session)
            key_seconds = time.perf_counter() - started
            started = time.perf_counter()
            first_changed = sync_outbox(session, GradebookPolicy.BEST)
            first = time.perf_counter() - started
            idle = []
            for _ in range(args.rounds):
                started = time.perf_counter()
                changed = sync_outbox(session, GradebookPolicy.BEST)
                idle.append(time.perf_counter() - started)
                assert changed == 0
        engine.dispose()
    text = (
        f"{HEADING}\n\n"
        f"`python bench/lti_outbox.py --students {args.students} --submissions {args.submissions} "
        f"--rounds {args.rounds}` on {platform.machine()} ({os.cpu_count()} cores, load average "
        f"{os.getloadavg()[0]:.1f} while measured), Python {platform.python_version()}, SQLite, "
        f"{args.students * args.submissions} graded submissions:\n\n"
        "| what | seconds |\n|---|---|\n"
        f"| first round ({first_changed} rows made) | {first:.3f} |\n"
        f"| idle round, median of {args.rounds} (nothing changed) | {statistics.median(idle):.3f} |\n"
        f"| idle round, slowest | {max(idle):.3f} |\n"
        f"| the tool's RSA-2048 key, generated and stored once | {key_seconds:.3f} |\n\n"
        "An idle round every 2 s (`GYMGRADE_LTI_PUBLISH_SECONDS`) reads the members and their graded rows' "
        "ids and scores (not the reports).\n"
    )
    print(text)
    if args.write:
        replace_section(HEADING, text)


if __name__ == "__main__":
    main()
