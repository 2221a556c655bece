"""The class report's entries from a `gymgrade grade` batch as grader/batch.py produces it.

The one place that knows how a batch names its students and where it keeps their reports; everything
else in the class report sees only ``ClassEntry``.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path

from grader.batch import report_names
from grader.class_report.entries import ClassEntry
from grader.report import Report


def entries_from_batch(
    paths: Sequence[Path], reports: Sequence[Report], out_dir: Path, page: Path
) -> list[ClassEntry]:
    """One entry per graded file: its report's name in the batch as identity, a link to its report.

    Args:
        paths: The batch's submission files, in its order.
        reports: Their reports, same order (``BatchOutcome.reports``).
        out_dir: The batch's output directory (where ``<name>.json`` reports are).
        page: Where the class page will be written (links are relative to its folder).

    Returns:
        The entries: ``submission_error`` for a file that could not be graded, else ``graded``.
    """
    names = report_names(paths)
    folder = page.resolve().parent
    entries: list[ClassEntry] = []
    for path, report in zip(paths, reports, strict=True):
        name = names[path]
        target = (out_dir / f"{name}.json").resolve()
        entries.append(
            ClassEntry(
                identity=name,
                report=report,
                status="graded" if report.submission_error is None else "submission_error",
                note=report.submission_error or f"graded {path.name}",
                report_href=Path(os.path.relpath(target, folder)).as_posix(),
            )
        )
    return entries
