"""A department's service at scale: gradebook and student-page latency on PostgreSQL (issue 45).

Starts a throw-away PostgreSQL cluster (Debian's postgresql package, as the tests do) and `gymgrade serve`
(uvicorn, no grading workers) on loopback, fills the database through SQL with 200 courses, 600
assignments, their staff, 10,000 enrolments and 60,000 graded submissions (each with a real report of
`submissions/classic_complete.py`, scores varied, its progress and an 8 KB file: the payload a grading
stores), a few overrides, late policies and extensions, then times, one request at a time from one client
on loopback, what an instructor fetches of one assignment (its gradebook CSV, its submissions list, the
default course's staff page) and what a student reads (their submissions, their latest report, their
pages). Target: p95 within 200 ms.

Usage: ``python bench/service_scale.py [--requests 300] [--report PATH] [--write]``. Without ``--report``
the report is made once by `gymgrade check submissions/classic_complete.py --format json` (about a minute).
``--write`` replaces the section in bench/RESULTS.md.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import random
import shutil
import signal
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import httpx

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tests" / "api"))

from api_testing import PostgresServer, free_port, postgres_bin_dir  # noqa: E402
from results_section import replace_section  # noqa: E402

from api.database import make_engine, migrate  # noqa: E402
from api.settings import Settings  # noqa: E402

HEADING = "## Service at a department's scale (issue 45)"
SAMPLE = ROOT / "submissions" / "classic_complete.py"
OPERATOR_TOKEN = "bench-operator-" + "q" * 24
COURSES, ASSIGNMENTS_PER_COURSE, STUDENTS_PER_COURSE, UPLOADS_PER_ASSIGNMENT = 200, 3, 50, 2
REPORT_VARIANTS = 8
TARGET_MS = 200.0
START_TIMEOUT_SECONDS = 120.0


@contextmanager
def postgres() -> Iterator[PostgresServer]:
    """A PostgreSQL cluster for the bench (stopped and deleted after)."""
    bin_dir = postgres_bin_dir()
    if bin_dir is None:
        raise SystemExit("PostgreSQL is not installed (apt-get install -y postgresql)")
    server = PostgresServer(bin_dir)
    server.start()
    try:
        yield server
    finally:
        server.stop()


def migrated_database(server: PostgresServer) -> str:
    """A new database of the cluster at the newest migration; its SQLAlchemy URL."""
    url: str = server.new_database()
    engine = make_engine(Settings(database_url=url, development=True, data_dir=Path(tempfile.gettempdir())))
    migrate(engine)
    engine.dispose()
    return url


def connect(url: str) -> Any:
    """A psycopg connection (autocommit) to the SQLAlchemy URL's database."""
    import psycopg

    return psycopg.connect(url.replace("postgresql+psycopg://", "postgresql://"), autocommit=True)


def real_report(path: Path | None) -> dict[str, Any]:
    """The report of a real grading of the bundled solution (made now unless ``path`` holds one)."""
    if path is not None:
        report: dict[str, Any] = json.loads(path.read_text(encoding="utf-8"))
        return report
    gymgrade = str(Path(sys.executable).with_name("gymgrade"))
    done = subprocess.run(
        [gymgrade, "check", str(SAMPLE), "--format", "json"], capture_output=True, check=True, timeout=1800
    )
    report = json.loads(done.stdout)
    return report


def report_variants(report: dict[str, Any]) -> list[dict[str, Any]]:
    """``REPORT_VARIANTS`` copies of the report with each problem's score drawn (full, half or none)."""
    draw = random.Random(45)
    variants = []
    for _ in range(REPORT_VARIANTS):
        problems = []
        for problem in report["problems"]:
            share = draw.choice((1.0, 1.0, 0.5, 0.0))
            problems.append({**problem, "score": problem["max_score"] * share})
        variants.append(
            {**report, "problems": problems, "score": sum(problem["score"] for problem in problems)}
        )
    return variants


def store_report_variants(db: Any, report: dict[str, Any]) -> None:
    """The temporary table ``bench_reports`` (variant, report, progress, score, max_score) of the
    connection: ``report_variants(report)``, for the submissions' rows to be made from on the server."""
    db.execute(
        "CREATE TEMPORARY TABLE bench_reports (variant int, report json, progress json, score float, "
        "max_score float)"
    )
    for variant, shaped in enumerate(report_variants(report)):
        db.execute(
            "INSERT INTO bench_reports VALUES (%s, %s::json, %s::json, %s, %s)",
            (
                variant,
                json.dumps(shaped),
                json.dumps(shaped["problems"]),
                shaped["score"],
                shaped["max_score"],
            ),
        )


def student_token(course: int, number: int) -> str:
    """The bench's token of student ``number`` of course ``course`` (its SHA-256 is stored)."""
    return f"bench-student-{course}-{number}"


def staff_token(course: int, role: str) -> str:
    """The bench's token of a course's instructor or first teaching assistant."""
    return f"bench-{role}-{course}"


def populate(url: str, report: dict[str, Any]) -> dict[str, float]:
    """Fill the database (server-side SQL) and return the seconds each table took."""
    content = SAMPLE.read_bytes()
    taken: dict[str, float] = {}
    with connect(url) as db:

        def timed(name: str, statement: str, parameters: dict[str, Any] | None = None) -> None:
            started = time.perf_counter()
            db.execute(statement, parameters or {})
            taken[name] = taken.get(name, 0.0) + time.perf_counter() - started

        timed(
            "courses",
            "INSERT INTO courses (id, slug, title, created_at) SELECT n, 'course-' || lpad(n::text, 3, '0'), "
            "'Course ' || n, now() FROM generate_series(2, %(courses)s) n",
            {"courses": COURSES},
        )
        db.execute("SELECT setval(pg_get_serial_sequence('courses', 'id'), (SELECT max(id) FROM courses))")
        due = "2026-11-20T23:59:00+00:00"
        late = json.dumps({"due": due, "penalty_per_day": 0.1, "max_penalty": 0.5})
        timed(
            "assignments",
            "INSERT INTO assignments (course_id, slug, title, lab, edition, config_toml, seed_policy, seed, "
            "release_seeds, due_date, gradebook_policy, late_policy, created_at) "
            "SELECT c.id, slot.slug, slot.title, slot.lab, slot.edition, NULL, 'random', c.id * 7 + slot.n, "
            "false, NULL, CASE WHEN (c.id + slot.n) %% 2 = 0 THEN 'best' ELSE 'latest' END, "
            "CASE WHEN (c.id + slot.n) %% 3 = 0 THEN %(late)s::json END, now() "
            "FROM courses c CROSS JOIN (VALUES (1, 'opengym', 'OpenGym AI lab', NULL, 'rl1'), "
            "(2, 'rl2', 'Policy Function Iteration', 'rl2', NULL), "
            "(3, 'opengym-classic', 'OpenGym AI lab (classic)', NULL, 'classic')) "
            "AS slot(n, slug, title, lab, edition) "
            "WHERE NOT (c.id = 1 AND slot.n = 1) ORDER BY c.id, slot.n",
            {"late": late},
        )
        timed(
            "staff",
            "INSERT INTO staff (course_id, role, name, token_sha256, created_at) "
            "SELECT c.id, r.role, r.role || ' ' || c.id, "
            "encode(sha256(convert_to('bench-' || r.role || '-' || c.id, 'UTF8')), 'hex'), now() "
            "FROM courses c CROSS JOIN (VALUES ('instructor'), ('ta')) AS r(role)",
        )
        timed(
            "staff",
            "INSERT INTO staff (course_id, role, name, token_sha256, created_at) "
            "SELECT c.id, 'ta', 'second ta ' || c.id, NULL, now() FROM courses c",
        )
        timed(
            "students",
            "INSERT INTO students (course_id, name, token_sha256, created_at) "
            "SELECT c.id, (100000 + c.id * 100 + n)::text, "
            "encode(sha256(convert_to('bench-student-' || c.id || '-' || n, 'UTF8')), 'hex'), now() "
            "FROM courses c CROSS JOIN generate_series(1, %(students)s) n ORDER BY c.id, n",
            {"students": STUDENTS_PER_COURSE},
        )
        store_report_variants(db, report)
        timed(
            "submissions",
            "INSERT INTO submissions (assignment_id, student_id, filename, sha256, content, size, seed, "
            "status, created_at, started_at, finished_at, attempts, progress, report, score, max_score) "
            "SELECT a.id, s.id, 'opengym.py', md5(a.id || '-' || s.id || '-' || k) || md5(s.id::text), "
            "%(content)s, %(size)s, (a.id * 7919 + s.id * 31 + k) %% 2147483647, 'done', u.at, u.at, "
            "u.at + interval '80 seconds', 1, r.progress, r.report, r.score, r.max_score "
            "FROM assignments a JOIN students s ON s.course_id = a.course_id "
            "CROSS JOIN generate_series(1, %(uploads)s) k "
            "JOIN bench_reports r ON r.variant = (a.id * 7 + s.id * 3 + k) %% %(variants)s "
            "CROSS JOIN LATERAL (SELECT timestamp '2026-11-01' + (a.id %% 17) * interval '1 day' "
            "+ (s.id %% 1440 + k * 1440) * interval '1 minute' AS at) u "
            "ORDER BY u.at, a.id, s.id",
            {
                "content": content,
                "size": len(content),
                "uploads": UPLOADS_PER_ASSIGNMENT,
                "variants": REPORT_VARIANTS,
            },
        )
        timed(
            "overrides and extensions",
            "INSERT INTO overrides (assignment_id, student_id, submission_id, problem, points, reason, "
            "author, created_at) SELECT a.id, s.id, NULL, 'car', 1.0, 'checked by hand', 'instructor', now() "
            "FROM assignments a JOIN students s ON s.course_id = a.course_id "
            "WHERE s.id %% 10 = a.id %% 10",
        )
        timed(
            "overrides and extensions",
            "INSERT INTO extensions (assignment_id, student_id, due, reason, author, created_at) "
            "SELECT a.id, s.id, timestamp '2026-11-25 23:59', 'illness', 'instructor', now() "
            "FROM assignments a JOIN students s ON s.course_id = a.course_id "
            "WHERE a.late_policy IS NOT NULL AND s.id %% 25 = a.id %% 25",
        )
        started = time.perf_counter()
        db.execute("VACUUM ANALYZE")
        taken["vacuum analyze"] = time.perf_counter() - started
    return taken


def counts(url: str) -> dict[str, int]:
    """Rows per table, and the database's size in MB."""
    tables = ("courses", "assignments", "staff", "students", "submissions", "overrides", "extensions")
    with connect(url) as db:
        found = {table: int(db.execute(f"SELECT count(*) FROM {table}").fetchone()[0]) for table in tables}
        found["MB"] = int(db.execute("SELECT pg_database_size(current_database())").fetchone()[0]) // 2**20
    return found


@dataclass
class Server:
    """A `gymgrade serve` process on loopback."""

    process: subprocess.Popen[bytes]
    url: str

    def stop(self) -> None:
        """SIGTERM, then SIGKILL of its process group."""
        self.process.terminate()
        try:
            self.process.wait(timeout=30)
        except subprocess.TimeoutExpired:
            os.killpg(self.process.pid, signal.SIGKILL)
            self.process.wait()


def start_server(database_url: str, data_dir: Path, log: Path) -> Server:
    """`gymgrade serve` on the database, no grading workers; waits for /healthz."""
    port = free_port()
    env = {name: value for name, value in os.environ.items() if not name.startswith("GYMGRADE_")}
    env.update(
        {
            "GYMGRADE_DATA_DIR": str(data_dir),
            "GYMGRADE_DATABASE_URL": database_url,
            "GYMGRADE_INSTRUCTOR_TOKEN": OPERATOR_TOKEN,
            "GYMGRADE_WORKERS": "0",
        }
    )
    gymgrade = str(Path(sys.executable).with_name("gymgrade"))
    with log.open("ab") as output:
        process = subprocess.Popen(
            [gymgrade, "serve", "--host", "127.0.0.1", "--port", str(port)],
            env=env,
            stdout=output,
            stderr=subprocess.STDOUT,
            start_new_session=True,
        )
    server = Server(process, f"http://127.0.0.1:{port}")
    deadline = time.monotonic() + START_TIMEOUT_SECONDS
    while time.monotonic() < deadline:
        if process.poll() is not None:
            raise RuntimeError(f"gymgrade serve exited with {process.returncode}; see {log}")
        try:
            if httpx.get(server.url + "/healthz", timeout=2).status_code == 200:
                return server
        except httpx.HTTPError:
            time.sleep(0.2)
    server.stop()
    raise RuntimeError(f"gymgrade serve did not answer within {START_TIMEOUT_SECONDS} s; see {log}")


@dataclass(frozen=True)
class Case:
    """One kind of request: who asks for what."""

    name: str
    request: Callable[[httpx.Client, random.Random, dict[str, Any]], httpx.Response]


def _assignment_path(draw: random.Random, layout: dict[str, Any]) -> tuple[int, str]:
    course = draw.randint(2, COURSES)
    return course, f"/courses/course-{course:03d}/assignments/{draw.choice(layout['slugs'])}"


def _bearer(token: str) -> dict[str, str]:
    return {"Authorization": f"Bearer {token}"}


def _gradebook(client: httpx.Client, draw: random.Random, layout: dict[str, Any]) -> httpx.Response:
    course, path = _assignment_path(draw, layout)
    role = draw.choice(("instructor", "ta"))
    return client.get(path + "/gradebook.csv", headers=_bearer(staff_token(course, role)))


def _canvas_gradebook(client: httpx.Client, draw: random.Random, layout: dict[str, Any]) -> httpx.Response:
    course, path = _assignment_path(draw, layout)
    return client.get(
        path + "/gradebook.csv",
        params={"format": "canvas", "assignment_id": "4321"},
        headers=_bearer(staff_token(course, "instructor")),
    )


def _all_submissions(client: httpx.Client, draw: random.Random, layout: dict[str, Any]) -> httpx.Response:
    course, path = _assignment_path(draw, layout)
    return client.get(path + "/submissions", headers=_bearer(staff_token(course, "instructor")))


def _staff_page(client: httpx.Client, draw: random.Random, layout: dict[str, Any]) -> httpx.Response:
    client.cookies.set("gymgrade_token", staff_token(1, "instructor"))
    try:
        return client.get("/")
    finally:
        client.cookies.clear()


def _student(draw: random.Random) -> tuple[int, str]:
    course = draw.randint(2, COURSES)
    return course, student_token(course, draw.randint(1, STUDENTS_PER_COURSE))


def _own_submissions(client: httpx.Client, draw: random.Random, layout: dict[str, Any]) -> httpx.Response:
    course, token = _student(draw)
    path = f"/courses/course-{course:03d}/assignments/{draw.choice(layout['slugs'])}/submissions"
    return client.get(path, headers=_bearer(token))


def _own_report(client: httpx.Client, draw: random.Random, layout: dict[str, Any]) -> httpx.Response:
    course, token = _student(draw)
    path = f"/courses/course-{course:03d}/assignments/{draw.choice(layout['slugs'])}/submissions"
    listed = client.get(path, headers=_bearer(token)).json()
    return client.get(f"{path}/{listed[0]['id']}", headers=_bearer(token))


def _student_pages(client: httpx.Client, draw: random.Random, layout: dict[str, Any]) -> httpx.Response:
    client.cookies.set("gymgrade_token", student_token(1, draw.randint(1, STUDENTS_PER_COURSE)))
    try:
        return client.get("/")
    finally:
        client.cookies.clear()


def _student_report_page(client: httpx.Client, draw: random.Random, layout: dict[str, Any]) -> httpx.Response:
    number = draw.randint(1, STUDENTS_PER_COURSE)
    submission = layout["default_submissions"][number]
    client.cookies.set("gymgrade_token", student_token(1, number))
    try:
        return client.get(f"/ui/submissions/{submission}")
    finally:
        client.cookies.clear()


CASES = (
    Case("instructor: gradebook CSV (gymgrade's columns), staff token", _gradebook),
    Case("instructor: gradebook CSV (Canvas import)", _canvas_gradebook),
    Case("instructor: the assignment's submissions (JSON)", _all_submissions),
    Case("instructor: the staff page (HTML, default course)", _staff_page),
    Case("student: their submissions (JSON)", _own_submissions),
    Case("student: their latest report (JSON, after the list)", _own_report),
    Case("student: their page (HTML, default course)", _student_pages),
    Case("student: their report page (HTML, default course)", _student_report_page),
)


def layout_of(url: str) -> dict[str, Any]:
    """What the requests pick from: the assignment slugs, the default course's latest upload per student."""
    with connect(url) as db:
        rows = db.execute(
            "SELECT s.name, max(u.id) FROM submissions u JOIN students s ON s.id = u.student_id "
            "WHERE u.assignment_id = 1 GROUP BY s.name"
        ).fetchall()
    latest = {int(name) % 100: submission for name, submission in rows}
    return {"slugs": ["opengym", "rl2", "opengym-classic"], "default_submissions": latest}


def percentile(values: list[float], share: float) -> float:
    """The nearest-rank percentile of ``values``."""
    ordered = sorted(values)
    return ordered[max(0, min(len(ordered) - 1, round(share * len(ordered)) - 1))]


def measure(server: Server, layout: dict[str, Any], requests: int) -> list[dict[str, Any]]:
    """Each case ``requests`` times, one at a time (after 10 warm-up requests); milliseconds per request."""
    rows = []
    with httpx.Client(base_url=server.url, timeout=60) as client:
        for case in CASES:
            draw = random.Random(case.name)
            for _ in range(10):
                case.request(client, draw, layout).raise_for_status()
            timings, sizes = [], []
            load_before = os.getloadavg()[0]
            for _ in range(requests):
                started = time.perf_counter()
                response = case.request(client, draw, layout)
                timings.append((time.perf_counter() - started) * 1000)
                response.raise_for_status()
                sizes.append(len(response.content))
            rows.append(
                {
                    "case": case.name,
                    "p50": percentile(timings, 0.50),
                    "p95": percentile(timings, 0.95),
                    "p99": percentile(timings, 0.99),
                    "max": max(timings),
                    "bytes": statistics.median(sizes),
                    "load": (load_before, os.getloadavg()[0]),
                }
            )
            print(rows[-1], flush=True)
    return rows


def section(
    args: argparse.Namespace,
    found: dict[str, Any],
    taken: dict[str, float],
    rows: list[dict[str, Any]],
    report_bytes: int,
) -> str:
    """The RESULTS.md section."""
    table = "\n".join(
        f"| {row['case']} | {row['p50']:.1f} | {row['p95']:.1f} | {row['p99']:.1f} | {row['max']:.0f} | "
        f"{row['bytes'] / 1024:.0f} KB | {row['load'][0]:.1f} -> {row['load'][1]:.1f} |"
        for row in rows
    )
    missed = [row["case"] for row in rows if row["p95"] > TARGET_MS]
    verdict = (
        f"every case's p95 within {TARGET_MS:.0f} ms"
        if not missed
        else f"p95 over {TARGET_MS:.0f} ms: {'; '.join(missed)}"
    )
    return (
        f"{HEADING}\n\n"
        f"`python bench/service_scale.py --requests {args.requests}`, {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, "  # noqa: E501
        f"{platform.machine()} ({os.cpu_count()} cores, shared), Python {platform.python_version()}, "
        f"PostgreSQL {found['server_version']}, `gymgrade serve` (uvicorn, one process, no grading workers) "
        "on loopback. "
        f"Database: {found['courses']} courses, {found['assignments']} assignments, {found['staff']} staff, "
        f"{found['students']} enrolments, {found['submissions']} graded submissions (each a real report of "
        f"`classic_complete.py`, {report_bytes / 1024:.0f} KB, scores varied, with its progress and an 8 KB "
        "file; students named by a Canvas-like user id, as the Canvas export needs), "
        f"{found['overrides']} overrides, {found['extensions']} extensions, a late policy on a third of the "
        f"assignments; {found['MB']} MB; filled in {sum(taken.values()):.0f} s "
        f"({', '.join(f'{name} {seconds:.0f} s' for name, seconds in taken.items())}).\n\n"
        f"Each case {args.requests} requests, one at a time from one client, a random course, assignment and "
        "person each (after 10 warm-up requests); milliseconds, client-side, response body included; the "
        "load is the 1-minute load average before and after the case. Target: p95 within "
        f"{TARGET_MS:.0f} ms. Result: {verdict}.\n\n"
        "| case | p50 | p95 | p99 | max | body | load |\n|---|---|---|---|---|---|---|\n"
        f"{table}\n"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--requests", type=int, default=300)
    parser.add_argument("--report", type=Path, default=None, help="a report JSON to store (else graded now)")
    parser.add_argument("--write", action="store_true")
    args = parser.parse_args()
    report = real_report(args.report)
    work = Path(tempfile.mkdtemp(prefix="gymgrade-scale-"))
    try:
        with postgres() as cluster:
            url = migrated_database(cluster)
            taken = populate(url, report)
            found: dict[str, Any] = counts(url)
            with connect(url) as db:
                found["server_version"] = db.execute("SHOW server_version").fetchone()[0]
            print(found, taken, flush=True)
            server = start_server(url, work / "data", work / "serve.log")
            try:
                rows = measure(server, layout_of(url), args.requests)
            finally:
                server.stop()
    finally:
        shutil.rmtree(work, ignore_errors=True)
    text = section(args, found, taken, rows, len(json.dumps(report)))
    print(text)
    if args.write:
        replace_section(HEADING, text)


if __name__ == "__main__":
    main()
