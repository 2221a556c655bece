"""The class report's entries from a `gymgrade grade` batch as grader/batch.py produces it.

The one place that knows how a batch names its students and where it keeps their reports; everything
else in the class report sees only ``ClassEntry``.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path

from grader.batch import GRADES_FILE, report_names
from grader.class_report import summary_path
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


def page_clash(page: Path, paths: Sequence[Path], out_dir: Path) -> str | None:
    """Why the class page or its summary would overwrite a file of the batch, or None when neither does.

    A student whose file is ``class.py`` has the report ``class.json``: ``--html gradebook/class.html``
    would replace it with the summary. Checked before grading, so the batch never starts.

    Args:
        page: Where the class page goes; its summary goes beside it (``summary_path``).
        paths: The batch's submission files.
        out_dir: The batch's output directory.

    Returns:
        The message to show, or None.
    """
    names = report_names(paths)
    outputs = {(out_dir / f"{name}.json").resolve(): path for path, name in names.items()}
    for written in (page, summary_path(page)):
        if written.resolve() == (out_dir / GRADES_FILE).resolve():
            return f"--html {page} would write {written} over the batch's {GRADES_FILE}; name the page e.g. class.html or put it outside {out_dir}"  # noqa: E501
        clashing = outputs.get(written.resolve())
        if clashing is not None:
            return f"--html {page} would write {written} over the report of {clashing}; put the page outside {out_dir} (e.g. {out_dir.parent / 'class.html'}) or give it another name"  # noqa: E501
    return None
