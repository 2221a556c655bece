"""The class report's entries from a `gymgrade grade` batch as grader/grading/batch.py produces it.

The one place that knows how a batch names its students and where it keeps their reports; everything
else in the class report sees only ``ClassEntry``.
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from pathlib import Path

from grader.classroom.gradebooks import GradeRow
from grader.classroom.report import summary_path
from grader.classroom.report.entries import ClassEntry, EntryStatus
from grader.grading.batch import GRADES_FILE, identity_stem


def entries_from_rows(rows: Sequence[GradeRow], out_dir: Path, page: Path) -> list[ClassEntry]:
    """One entry per student of a class batch (``grader.classroom``): their identity and roster name, their
    report (a group's report for each member), late flag, and a link to ``<identity>.json``.

    Args:
        rows: The class's rows (``grader.classroom.gradebooks.class_rows``, as the batch last wrote them).
        out_dir: The batch's output directory.
        page: Where the class page will be written (links are relative to its folder).

    Returns:
        ``missing`` for a roster student with no submission, ``submission_error`` for a submission with no
        gradable file or whose file could not be graded, else ``graded``.
    """
    folder = page.resolve().parent
    entries: list[ClassEntry] = []
    for row in rows:
        submission, report = row.submission, row.report
        status: EntryStatus
        if submission is None:
            status = "missing"
        elif report is None or report.submission_error is not None:
            status = "submission_error"
        else:
            status = "graded"
        graded = submission.graded_file.relative if submission and submission.graded_file else ""
        href = None
        if submission is not None and report is not None:
            target = (out_dir / f"{identity_stem(submission.identity)}.json").resolve()
            href = Path(os.path.relpath(target, folder)).as_posix()
        entries.append(
            ClassEntry(
                identity=row.member.identity,
                name=row.name or None,
                report=report,
                late=bool(submission and submission.late),
                status=status,
                note=row.note or (f"graded {graded}" if graded else ""),
                report_href=href,
            )
        )
    return entries


def page_clash_of_reports(page: Path, reports: Mapping[Path, str], out_dir: Path) -> str | None:
    """Why the class page or its summary would overwrite a file of the batch, or None when neither does.

    Checked before grading, so the batch never starts. ``reports`` maps each report file the batch writes
    to whose it is (a student whose identity is ``class`` has the report ``class.json``).
    """
    outputs = {path.resolve(): whose for path, whose in reports.items()}
    for written in (page, summary_path(page)):
        if written.resolve() == (out_dir / GRADES_FILE).resolve():
            return f"--html {page} would write {written} over the batch's {GRADES_FILE}; name the page e.g. class.html or put it outside {out_dir}"  # noqa: E501
        clashing = outputs.get(written.resolve())
        if clashing is not None:
            return f"--html {page} would write {written} over the report of {clashing}; put the page outside {out_dir} (e.g. {out_dir.parent / 'class.html'}) or give it another name"  # noqa: E501
    return None
