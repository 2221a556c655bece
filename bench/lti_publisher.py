"""LTI score publishing at a department's scale: 10,000 pending scores to a platform answering in 100 ms
(issue 45).

Starts a throw-away PostgreSQL cluster and a fake platform on loopback (its own process: uvicorn, every
token and score request answered after ``--delay`` seconds, each score counted by user), fills the
database with COURSES courses, each with one assignment, one LTI link with its line item and its share of
``--scores`` learners with one graded submission each, then runs the real publisher
(`api.lti.publisher.ScorePublisher`, as `gymgrade serve` runs it, `GYMGRADE_LTI_PUBLISH_CONCURRENCY`
sends at once) until every score is sent. Then two more rounds (nothing may be sent again), then 100
learners' scores change (regraded higher): exactly those are sent once more. Target: 10,000 scores within
five minutes, no second send of an unchanged score.

Usage: ``python bench/lti_publisher.py [--scores 10000] [--delay 0.1] [--concurrency 8] [--write]``
(``--write`` replaces the section in bench/RESULTS.md).
"""

from __future__ import annotations

import argparse
import asyncio
import multiprocessing
import os
import platform
import sys
import tempfile
import time
from collections import Counter
from collections.abc import Callable
from pathlib import Path
from typing import Any

import httpx
from cryptography.fernet import Fernet
from pydantic import SecretStr

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tests" / "api"))

from api_testing import free_port  # noqa: E402
from results_section import replace_section  # noqa: E402
from service_scale import (  # noqa: E402
    REPORT_VARIANTS,
    connect,
    migrated_database,
    postgres,
    real_report,
    store_report_variants,
)

from api.database import make_engine, make_session_factory  # noqa: E402
from api.lti.keys import protect_keys  # noqa: E402
from api.lti.publisher import ScorePublisher  # noqa: E402
from api.settings import Settings  # noqa: E402

HEADING = "## LTI publisher at a department's scale (issue 45)"
COURSES = 20
CHANGED = 100
TARGET_SECONDS = 300.0
WAIT_SECONDS = 1800.0


def serve_platform(port: int, delay: float) -> None:
    """The fake platform (run in its own process): tokens and scores answered after ``delay`` seconds."""
    import uvicorn
    from starlette.applications import Starlette
    from starlette.requests import Request
    from starlette.responses import JSONResponse
    from starlette.routing import Route

    sends: Counter[str] = Counter()
    given: dict[str, float] = {}
    tokens = [0]
    in_flight = [0, 0]

    async def token(_request: Request) -> JSONResponse:
        await asyncio.sleep(delay)
        tokens[0] += 1
        return JSONResponse({"access_token": f"t{tokens[0]}", "token_type": "bearer", "expires_in": 3600})

    async def score(request: Request) -> JSONResponse:
        in_flight[0] += 1
        in_flight[1] = max(in_flight[1], in_flight[0])
        body = await request.json()
        await asyncio.sleep(delay)
        in_flight[0] -= 1
        sends[body["userId"]] += 1
        given[body["userId"]] = body.get("scoreGiven")
        return JSONResponse({}, status_code=200)

    async def counts(_request: Request) -> JSONResponse:
        return JSONResponse(
            {"sends": dict(sends), "given": given, "tokens": tokens[0], "most_in_flight": in_flight[1]}
        )

    app = Starlette(
        routes=[
            Route("/token", token, methods=["POST"]),
            Route("/lineitems/{item}/scores", score, methods=["POST"]),
            Route("/counts", counts, methods=["GET"]),
        ]
    )
    uvicorn.run(app, host="127.0.0.1", port=port, log_level="warning", access_log=False)


def populate(url: str, lms: str, scores: int, report: dict[str, Any]) -> None:
    """COURSES courses, each an assignment and an LTI link with its line item, and ``scores`` learners
    (users, enrolments, link members) with one graded submission each (``report``, scores varied)."""
    per_course = -(-scores // COURSES)
    with connect(url) as db:
        store_report_variants(db, report)
        db.execute(
            "INSERT INTO lti_platforms (issuer, client_id, deployment_ids, jwks_url, auth_url, token_url, "
            "created_at, frame_ancestors) VALUES (%(lms)s::text, 'bench', '[\"d\"]', "
            "%(lms)s::text || '/jwks', %(lms)s::text || '/auth', %(lms)s::text || '/token', now(), '[]')",
            {"lms": lms},
        )
        db.execute(
            "INSERT INTO courses (id, slug, title, lti_platform_id, lti_deployment_id, lti_context_id, "
            "created_at) SELECT n, 'course-' || n, 'Course ' || n, p.id, 'd', 'context-' || n, now() "
            "FROM generate_series(2, %(last)s) n CROSS JOIN lti_platforms p",
            {"last": COURSES + 1},
        )
        db.execute(
            "INSERT INTO assignments (course_id, slug, title, lab, edition, seed_policy, seed, "
            "release_seeds, gradebook_policy, created_at) "
            "SELECT c.id, 'opengym', 'OpenGym AI lab', NULL, 'rl1', 'random', c.id, false, 'latest', now() "
            "FROM courses c WHERE c.id > 1"
        )
        db.execute(
            "INSERT INTO lti_links (platform_id, assignment_id, deployment_id, context_id, resource_link_id, "
            "title, lineitems_url, lineitem_url, ags_scopes, memberships_url, custom) "
            "SELECT c.lti_platform_id, a.id, 'd', c.lti_context_id, 'link-' || c.id, a.title, "
            "%(lms)s::text || '/lineitems', %(lms)s::text || '/lineitems/' || c.id, "
            "'[\"https://purl.imsglobal.org/spec/lti-ags/scope/score\"]', NULL, '{}' "
            "FROM courses c JOIN assignments a ON a.course_id = c.id WHERE c.id > 1",
            {"lms": lms},
        )
        db.execute(
            "INSERT INTO lti_users (platform_id, sub, name) SELECT p.id, 'learner-' || n, 'Learner ' || n "
            "FROM generate_series(1, %(scores)s) n CROSS JOIN lti_platforms p",
            {"scores": scores},
        )
        db.execute(
            "INSERT INTO students (course_id, name, token_sha256, lti_user_id, created_at) "
            "SELECT 2 + (u.id - 1) / %(per)s, u.name, md5(u.sub) || md5(u.sub || 'x'), u.id, now() "
            "FROM lti_users u",
            {"per": per_course},
        )
        db.execute(
            "INSERT INTO lti_members (link_id, user_id) SELECT l.id, s.lti_user_id FROM students s "
            "JOIN assignments a ON a.course_id = s.course_id JOIN lti_links l ON l.assignment_id = a.id"
        )
        db.execute(
            "INSERT INTO submissions (assignment_id, student_id, filename, sha256, content, size, seed, "
            "status, created_at, started_at, finished_at, attempts, progress, report, score, max_score) "
            "SELECT a.id, s.id, 'opengym.py', md5(s.id::text) || md5(s.name), '\\x00', 1, s.id, 'done', "
            "now(), now(), now(), 1, r.progress, r.report, r.score, r.max_score "
            "FROM students s JOIN assignments a ON a.course_id = s.course_id "
            "JOIN bench_reports r ON r.variant = s.id %% %(variants)s",
            {"variants": REPORT_VARIANTS},
        )
        db.execute("VACUUM ANALYZE")


def statuses(url: str) -> Counter[str]:
    """The outbox rows by state."""
    with connect(url) as db:
        return Counter(dict(db.execute("SELECT status, count(*) FROM lti_scores GROUP BY status").fetchall()))


def wait_until(condition: Callable[[], bool], what: str) -> None:
    """Poll ``condition`` every half second (at most WAIT_SECONDS)."""
    deadline = time.monotonic() + WAIT_SECONDS
    while not condition():
        if time.monotonic() > deadline:
            raise RuntimeError(f"{what}: not within {WAIT_SECONDS:.0f} s")
        time.sleep(0.5)


def run(args: argparse.Namespace) -> dict[str, Any]:
    """Fill, publish, check; the figures."""
    port = free_port()
    lms = f"http://127.0.0.1:{port}"
    platform_process = multiprocessing.Process(target=serve_platform, args=(port, args.delay), daemon=True)
    platform_process.start()
    try:
        with postgres() as cluster:
            url = migrated_database(cluster)
            populate(url, lms, args.scores, real_report(args.report))
            wait_until(lambda: _answers(lms), "the fake platform to answer")
            settings = Settings(
                database_url=url,
                data_dir=Path(tempfile.gettempdir()),
                instructor_token=SecretStr("bench-operator-" + "q" * 24),
                lti_allow_http=True,
                lti_allowed_networks="127.0.0.0/8",
                key_encryption_key=SecretStr(Fernet.generate_key().decode("ascii")),
                lti_publish_seconds=1.0,
                lti_publish_concurrency=args.concurrency,
            )
            engine = make_engine(settings)
            sessions = make_session_factory(engine)
            protect_keys(sessions, settings)
            publisher = ScorePublisher(sessions, settings)
            load_before = os.getloadavg()
            cpu_before = time.process_time()
            started = time.monotonic()
            publisher.start()
            try:
                wait_until(lambda: statuses(url)["sent"] >= args.scores, "every score sent")
                seconds = time.monotonic() - started
                cpu = time.process_time() - cpu_before
                load_after = os.getloadavg()
                rounds = publisher.progress()["rounds"]
                wait_until(lambda: publisher.progress()["rounds"] >= rounds + 2, "two more rounds")
                after_idle = httpx.get(lms + "/counts", timeout=30).json()
                with connect(url) as db:
                    changed = [
                        row[0]
                        for row in db.execute(
                            "UPDATE submissions SET score = score + 0.5 WHERE id IN "
                            "(SELECT id FROM submissions ORDER BY id LIMIT %(changed)s) RETURNING "
                            "(SELECT u.sub FROM students s JOIN lti_users u ON u.id = s.lti_user_id "
                            "WHERE s.id = submissions.student_id)",
                            {"changed": CHANGED},
                        ).fetchall()
                    ]
                resent_at = time.monotonic()
                wait_until(
                    lambda: (
                        sum(httpx.get(lms + "/counts", timeout=30).json()["sends"].values())
                        >= args.scores + len(changed)
                    ),
                    "the changed scores sent again",
                )
                resent_seconds = time.monotonic() - resent_at
                rounds = publisher.progress()["rounds"]
                wait_until(lambda: publisher.progress()["rounds"] >= rounds + 2, "two more rounds")
                final = httpx.get(lms + "/counts", timeout=30).json()
            finally:
                publisher.stop()
                engine.dispose()
    finally:
        platform_process.terminate()
        platform_process.join(30)
    idle_sends = Counter(after_idle["sends"])
    final_sends = Counter(final["sends"])
    expected = {user: 2 if user in set(changed) else 1 for user in final_sends}
    return {
        "seconds": seconds,
        "cpu": cpu,
        "load": (load_before[0], load_after[0]),
        "sent_once": sum(1 for count in idle_sends.values() if count == 1),
        "sent_twice_or_more_before_change": sum(1 for count in idle_sends.values() if count > 1),
        "users_sent": len(final_sends),
        "changed": len(changed),
        "resent_seconds": resent_seconds,
        "changed_sent_twice": sum(1 for user in changed if final_sends[user] == 2),
        "all_as_expected": dict(final_sends) == expected and len(final_sends) == args.scores,
        "changed_values_right": all(final["given"][user] is not None for user in changed),
        "tokens": final["tokens"],
        "most_in_flight": final["most_in_flight"],
    }


def _answers(lms: str) -> bool:
    try:
        return httpx.get(lms + "/counts", timeout=2).status_code == 200
    except httpx.HTTPError:
        return False


def section(args: argparse.Namespace, found: dict[str, Any]) -> str:
    """The RESULTS.md section."""
    verdict = "met" if found["seconds"] <= TARGET_SECONDS and found["all_as_expected"] else "missed"
    return (
        f"{HEADING}\n\n"
        f"`python bench/lti_publisher.py --scores {args.scores} --delay {args.delay:g} --concurrency "
        f"{args.concurrency}`, {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, {platform.machine()} "
        f"({os.cpu_count()} cores, shared; load average {found['load'][0]:.1f} at the start, "
        f"{found['load'][1]:.1f} at the end), Python {platform.python_version()}, PostgreSQL. The real "
        "publisher (`ScorePublisher`, a round every second) against a fake platform on loopback (its own "
        f"process) answering every token and score request after {args.delay * 1000:.0f} ms; {COURSES} "
        f"courses, each a link with its line item, {args.scores} learners with a graded upload each (a real "
        "report of `classic_complete.py`, scores varied); no overrides, no late policy.\n\n"
        "| what | figure |\n|---|---|\n"
        f"| {args.scores} pending scores, from the publisher's start to the last accepted | "
        f"**{found['seconds']:.1f} s** ({args.scores / found['seconds']:.0f} per second; target "
        f"{TARGET_SECONDS:.0f} s: {verdict}) |\n"
        f"| the publisher's CPU (the bench process) over that time | {found['cpu']:.1f} s |\n"
        f"| score requests in flight at once, at most | {found['most_in_flight']} |\n"
        f"| access tokens requested | {found['tokens']} |\n"
        f"| learners sent exactly one score, after two more rounds | {found['sent_once']} of {args.scores} "
        f"(sent twice or more: {found['sent_twice_or_more_before_change']}) |\n"
        f"| {found['changed']} scores changed (regraded higher): sent again, once each | "
        f"{found['changed_sent_twice']} of {found['changed']}, within {found['resent_seconds']:.1f} s; "
        f"every other learner still one send: {'yes' if found['all_as_expected'] else 'NO'} |\n"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scores", type=int, default=10_000)
    parser.add_argument("--delay", type=float, default=0.1)
    parser.add_argument("--concurrency", type=int, default=8)
    parser.add_argument("--report", type=Path, default=None, help="a report JSON to store (else graded now)")
    parser.add_argument("--write", action="store_true")
    args = parser.parse_args()
    found = run(args)
    print(found)
    text = section(args, found)
    print(text)
    if args.write:
        replace_section(HEADING, text)


if __name__ == "__main__":
    main()
