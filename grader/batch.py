"""Batch grading: many submissions over all cores, a report JSON per file and grades.csv."""

from __future__ import annotations

import csv
from collections.abc import Callable, Sequence
from pathlib import Path

from grader.grading import GradingPlan, grade_files
from grader.notebook import NOTEBOOK_SUFFIX
from grader.report import ProblemResult, Report
from grader.sandbox import IsolationPolicy

CHUNK_SUBMISSIONS = 24
"""Submissions per pytest run: large enough to keep every worker busy, small enough that a run that dies
takes few results with it (its unfinished problems are reported as grader errors, the batch goes on)."""

GRADES_FILE = "grades.csv"
SUBMISSION_SUFFIXES = (".py", NOTEBOOK_SUFFIX)


def collect_submissions(targets: Sequence[Path]) -> list[Path]:
    """The ``.py`` and ``.ipynb`` files named, and those under the directories named (recursively, sorted).

    Jupyter's ``.ipynb_checkpoints`` copies are left out with every other hidden directory.

    Raises:
        FileNotFoundError: A target does not exist.
    """
    files: list[Path] = []
    for target in targets:
        if target.is_dir():
            files += sorted(
                path
                for path in target.rglob("*")
                if path.suffix.lower() in SUBMISSION_SUFFIXES
                and path.is_file()
                and not any(part.startswith(".") for part in path.relative_to(target).parts)
            )
        elif target.exists():
            files.append(target)
        else:
            raise FileNotFoundError(
                f"{target} does not exist: pass .py or .ipynb files or directories holding them"
            )
    return files


def report_names(paths: Sequence[Path]) -> dict[Path, str]:
    """A distinct report file stem per submission (its name, made unique with a counter when needed)."""
    names: dict[Path, str] = {}
    used: set[str] = set()
    for path in paths:
        stem, counter = path.stem, 1
        while stem in used:
            counter += 1
            stem = f"{path.stem}-{counter}"
        used.add(stem)
        names[path] = stem
    return names


def grade_many(
    paths: Sequence[Path],
    out_dir: Path,
    *,
    seed: int = 0,
    workers: int | None = None,
    only: Sequence[str] | None = None,
    policy: IsolationPolicy = IsolationPolicy.REQUIRE_FULL,
    config: Path | None = None,
    on_result: Callable[[Path, ProblemResult], None] | None = None,
) -> list[Report]:
    """Grade many submissions; write ``<name>.json`` per submission and ``grades.csv`` to ``out_dir``.

    Work is spread over the workers across submissions (longest checks first). A submission that cannot
    be read, crashes or times out gets its verdicts; nothing it does stops the batch. ``grades.csv`` is
    rewritten after every chunk, so an interrupted batch keeps what it finished.

    Args:
        paths: Submission files.
        out_dir: Directory for the reports and ``grades.csv`` (created).
        seed: Grading seed.
        workers: Parallel workers; the machine's cores when None.
        only: Problem ids to grade; all enabled problems when None.
        policy: Isolation policy (see ``grader.grading.grade_submission``).
        config: Assignment configuration TOML; the bundled one when None.
        on_result: Called with (file, result) as each check finishes.

    Returns:
        The reports, in the order of ``paths``.
    """
    plan = GradingPlan.load(config, only)
    out_dir.mkdir(parents=True, exist_ok=True)
    names = report_names(paths)
    reports: list[Report] = []
    for start in range(0, len(paths), CHUNK_SUBMISSIONS):
        chunk = paths[start : start + CHUNK_SUBMISSIONS]
        chunk_reports = grade_files(
            chunk, plan, seed=seed, workers=workers, policy=policy, on_result=on_result
        )
        for path, report in zip(chunk, chunk_reports, strict=True):
            (out_dir / f"{names[path]}.json").write_text(report.to_json() + "\n", encoding="utf-8")
        reports += chunk_reports
        write_grades(out_dir / GRADES_FILE, [names[path] for path in paths[: len(reports)]], reports, plan)
    return reports


def write_grades(path: Path, names: Sequence[str], reports: Sequence[Report], plan: GradingPlan) -> None:
    """Write the gradebook: a row per submission, a column per problem's score, the total and a note."""
    with path.open("w", newline="", encoding="utf-8") as stream:
        writer = csv.writer(stream)
        writer.writerow(["submission", "sha256", *plan.problems, "total", "max_score", "note"])
        for name, report in zip(names, reports, strict=True):
            scores = {result.id: result.score for result in report.problems}
            note = report.submission_error or "; ".join(report.grader_errors)
            writer.writerow(
                [
                    name,
                    report.sha256,
                    *(f"{scores.get(problem, 0.0):g}" for problem in plan.problems),
                    f"{report.score:g}",
                    f"{report.max_score:g}",
                    note,
                ]
            )
