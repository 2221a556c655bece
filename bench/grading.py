"""Grading time of one submission against the scheduling floor, and the grader's overhead.

    python bench/grading.py [--submission PATH] [--workers 2] [--seed 0] [--standalone] [--write]

Grades the submission (default: the lab-literal `submissions/classic_complete.py`) with full isolation on
`--workers` workers and prints, per check, its wall time, the student's own time inside it and the rest
(sandbox start, import, transfer, replay, judging). The floor is max(longest check, total check time /
workers), from the same run's check times; `--standalone` also times every check alone on one worker, the
floor without contention between the workers. `--write` replaces the `## Grading` section of
bench/RESULTS.md.
"""

from __future__ import annotations

import argparse
import heapq
import os
import platform
import sys
import time
from datetime import date
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from results_section import replace_section  # noqa: E402

from grader.grading.grade import grade_submission  # noqa: E402
from grader.report import Report  # noqa: E402
from grader.sandbox import IsolationPolicy  # noqa: E402


def list_schedule(durations: list[float], workers: int) -> float:
    """Makespan of handing the checks out longest first to the first free worker."""
    finish = [0.0] * workers
    for duration in sorted(durations, reverse=True):
        heapq.heapreplace(finish, finish[0] + duration)
    return max(finish)


def standalone_walls(submission: Path, seed: int, problems: list[str]) -> dict[str, float]:
    """Each check's wall time when it runs alone on one worker."""
    walls = {}
    for problem in problems:
        report = grade_submission(submission, seed=seed, workers=1, only=[problem])
        timings = report.problems[0].timings
        walls[problem] = timings.wall_seconds if timings is not None else float("nan")
    return walls


def section(
    submission: Path, workers: int, report: Report, elapsed: float, alone: dict[str, float] | None, load: str
) -> str:
    """The `## Grading` section of bench/RESULTS.md."""
    rows, walls, students = [], [], []
    for problem in report.problems:
        if problem.timings is None:
            continue
        wall, student = problem.timings.wall_seconds, problem.timings.student_seconds
        walls.append(wall)
        students.append(student)
        alone_text = f" | {alone[problem.id]:.1f} s" if alone is not None else ""
        rows.append(
            f"| {problem.id} | {problem.status} | {wall:.1f} s{alone_text} | {student:.1f} s | "
            f"{wall - student:.1f} s ({(wall - student) / wall:.0%}) |"
        )
    floor = max(max(walls), sum(walls) / workers)
    makespan = list_schedule(walls, workers)
    session = max(elapsed - makespan, 0.0)
    overhead_checks = sum(walls) - sum(students)
    busy = sum(walls) + workers * session
    overhead_total = overhead_checks + workers * session
    alone_header = " | alone, 1 worker" if alone is not None else ""
    lines = [
        "## Grading",
        "",
        f"`python bench/grading.py{' --standalone' if alone is not None else ''}` on `{submission.name}` "
        f"(seed {report.seed}, {workers} workers, full isolation), {platform.machine()} with "
        f"{os.cpu_count()} cores shared with other jobs (load average {load} during the run; other jobs "
        f"slow every check, so compare figures within one run), {date.today().isoformat()}:",
        "",
        f"| check | status | wall{alone_header} | student's code | grader overhead |",
        "|-------|--------|------"
        + ("|------" if alone is not None else "")
        + "|----------------|----------------|",
        *rows,
        "",
        f"- Grading time: **{elapsed:.1f} s** (call to report, pytest and worker start-up included).",
        f"- Floor max(longest check, total / {workers}) from this run's check times: {floor:.1f} s "
        f"(longest {max(walls):.1f} s, total {sum(walls):.1f} s): ratio **{elapsed / floor:.2f}x** "
        "(target <= 1.10x).",
    ]
    if alone is not None:
        alone_floor = max(max(alone.values()), sum(alone.values()) / workers)
        slowdown = sum(walls) / sum(alone.values())
        lines.append(
            f"- Floor from the checks timed alone: {alone_floor:.1f} s: ratio {elapsed / alone_floor:.2f}x. "
            f"Side by side the checks ran {slowdown:.2f}x slower than alone (same code, same calls), so the "
            f"{workers} workers delivered {workers / slowdown:.2f} checks' worth of throughput: these cores "
            "are shared (hyper-threads, other jobs) and no schedule reaches this floor here."
        )
    lines += [
        f"- Longest-first list schedule of these check times: {makespan:.1f} s; the other {session:.1f} s "
        "is the pytest session (controller and worker start-up, shutdown).",
        f"- Grader overhead (everything but the student's own code, start-up counted on every worker): "
        f"{overhead_total:.1f} s of {busy:.1f} s busy worker time = **{overhead_total / busy:.0%}** "
        f"(target <= 5%); inside the checks alone: {overhead_checks / sum(walls):.0%}.",
        "",
    ]
    return "\n".join(lines)


def write_section(text: str) -> None:
    """Replace (or append) the `## Grading` section of bench/RESULTS.md."""
    replace_section("## Grading", text + "\n")


def main() -> None:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--submission", type=Path, default=ROOT / "submissions" / "classic_complete.py")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--standalone", action="store_true", help="also time each check alone")
    parser.add_argument("--write", action="store_true", help="replace ## Grading in bench/RESULTS.md")
    args = parser.parse_args()

    started = time.perf_counter()
    report = grade_submission(
        args.submission, seed=args.seed, workers=args.workers, policy=IsolationPolicy.REQUIRE_FULL
    )
    elapsed = time.perf_counter() - started
    alone = (
        standalone_walls(args.submission, args.seed, [problem.id for problem in report.problems])
        if args.standalone
        else None
    )
    load = f"{os.getloadavg()[1]:.1f}"
    text = section(args.submission, args.workers, report, elapsed, alone, load)
    print(text)
    if args.write:
        write_section(text)


if __name__ == "__main__":
    main()
