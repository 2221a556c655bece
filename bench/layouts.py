"""Class layouts: time to recognise and group a 300-student download of each layout, and the batch's added
cost per submission (what `gymgrade grade` spends per student outside grading itself).

For each layout a realistic download of STUDENTS students (plus the builders' extra cases: a resubmission, a
late one, a group, extra files, a stray file, a symlink) is built in a temporary folder (Canvas as its zip),
then `grader.classroom.discover` is timed (median of REPEATS; a zip is read into a fresh scratch folder each
time). The batch's added cost is `grade_many` with an executor that grades instantly (a report per file
from its bytes), writing every report and rewriting `grades.csv` and every gradebook after each one, as a
real batch does; divided by the number of submissions.

    python bench/layouts.py [--students 300] [--repeats 5]
"""

from __future__ import annotations

import argparse
import hashlib
import statistics
import sys
import tempfile
import time
from collections.abc import Sequence
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
# This folder first on sys.path would shadow the `reference` package with bench/reference.py.
sys.path[:1] = [str(ROOT), str(ROOT / "tests" / "grader")]

from classroom.downloads import BUILDERS, DUE  # noqa: E402

import grader  # noqa: E402
from grader.classroom import GradedFileRule, discover  # noqa: E402
from grader.classroom.gradebooks import GRADEBOOKS, Assignment  # noqa: E402
from grader.classroom.output import ClassGradebook  # noqa: E402
from grader.grading.batch import grade_many  # noqa: E402
from grader.grading.outcomes import GradingListener  # noqa: E402
from grader.grading.plan import GradingPlan  # noqa: E402
from grader.report import ProblemResult, Report  # noqa: E402

RULE = GradedFileRule(functions=("random_blackjack", "blackjack", "cartpole", "car", "taxi", "find_qvalues"))


class InstantExecutor:
    """Grades every file at once into a report of its bytes: what is left is the batch's own cost."""

    def grade(
        self, paths: Sequence[Path], plan: GradingPlan, *, seed: int, listener: GradingListener
    ) -> None:
        for path in paths:
            data = path.read_bytes()
            problems = [
                ProblemResult(id=p, title=p, status="passed", score=1.0, max_score=1.0, feedback="ok")
                for p in plan.problems
            ]
            listener.report(
                path,
                Report(
                    submission=path.name,
                    sha256=hashlib.sha256(data).hexdigest(),
                    seed=seed,
                    gymnasium_version="1.4.0",
                    grader_version=grader.__version__,
                    config_sha256=plan.config_sha256,
                    score=float(len(problems)),
                    max_score=float(len(problems)),
                    problems=problems,
                ),
            )


def measure(layout: str, students: int, repeats: int, work: Path) -> tuple[int, float, float]:
    """(submissions, median seconds to discover, milliseconds of batch cost per submission)."""
    expected = BUILDERS[layout](work / "download", students)
    times = []
    for attempt in range(repeats):
        start = time.perf_counter()
        download = discover(expected.path, rule=RULE, scratch=work / f"scratch{attempt}", due=DUE)
        times.append(time.perf_counter() - start)
    identities = {s.graded_file.path: s.identity for s in download.submissions if s.graded_file}
    plan = GradingPlan.load(None, None)
    gradebook = ClassGradebook(
        download, identities, plan.problems, None, tuple(GRADEBOOKS), Assignment("Lab", "1")
    )
    start = time.perf_counter()
    grade_many(
        list(identities),
        work / "out",
        seed=1,
        executor=InstantExecutor(),
        names=identities,
        gradebook=gradebook,
    )
    batch = time.perf_counter() - start
    return len(download.submissions), statistics.median(times), 1000 * batch / len(identities)


def main() -> None:
    """Print the `## Class layouts` table."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--students", type=int, default=300)
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    print(
        f"| layout | submissions | recognise + group (median of {args.repeats}) | batch cost per submission |"
    )
    print("|---|---|---|---|")
    for layout in BUILDERS:
        with tempfile.TemporaryDirectory() as work:
            count, seconds, per_submission = measure(layout, args.students, args.repeats, Path(work))
        print(f"| {layout} | {count} | {seconds * 1000:.0f} ms | {per_submission:.1f} ms |", flush=True)


if __name__ == "__main__":
    main()
