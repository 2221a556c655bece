"""The class report: one page and one JSON summary of a whole class's grades (`gymgrade grade --html`).

``ClassEntry`` is its input (one per student, from any layout or roster); ``class_summary`` and
``render_class_html`` are pure functions of the entries; ``write_class_report`` is the thin shell that
writes both files. The page's modules (Jinja, matplotlib) load when the page is first asked for, so the
package's plain-text helpers (`grader.render.neutral`, used by every output of a single report) cost
nothing to import.
"""

from __future__ import annotations

import importlib
import json
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from grader.classroom.report.entries import ClassEntry, EntryStatus

if TYPE_CHECKING:
    from grader.classroom.report.html import CSP, render_class_html
    from grader.classroom.report.summary import (
        ClassSummary,
        class_summary,
        diagnosis_key,
        diagnosis_text,
        summarise,
    )

_LAZY = {
    "CSP": "grader.classroom.report.html",
    "render_class_html": "grader.classroom.report.html",
    "ClassSummary": "grader.classroom.report.summary",
    "class_summary": "grader.classroom.report.summary",
    "diagnosis_key": "grader.classroom.report.summary",
    "diagnosis_text": "grader.classroom.report.summary",
    "summarise": "grader.classroom.report.summary",
}
"""Names loaded on first use: the page and its figures (matplotlib, Jinja) are not imported by what needs only
``grader.render.neutral`` (the gradebooks, every page's filters, the terminal lines)."""


def __getattr__(name: str) -> Any:
    if name in _LAZY:
        return getattr(importlib.import_module(_LAZY[name]), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


__all__ = [
    "CSP",
    "ClassEntry",
    "ClassSummary",
    "EntryStatus",
    "class_summary",
    "diagnosis_key",
    "diagnosis_text",
    "render_class_html",
    "summarise",
    "summary_path",
    "write_class_report",
]


def summary_path(page: Path) -> Path:
    """Where the JSON summary of the class page ``page`` goes: beside it, ``.json`` for ``.html``."""
    return page.with_suffix(".json")


def write_class_report(page: Path, entries: Sequence[ClassEntry], *, title: str = "") -> Path:
    """Write the class page to ``page`` and its summary beside it (``summary_path``).

    Args:
        page: The HTML file to write (its folder is created).
        entries: One entry per student.
        title: What the class or assignment is called.

    Returns:
        The summary's path.

    Raises:
        ValueError: ``page`` ends in ``.json``, so the summary would overwrite it.
    """
    target = summary_path(page)
    if target == page:
        raise ValueError(
            f"--html {page}: expected an .html file name (the JSON summary is written beside it as {target.name}); name the page e.g. class.html"  # noqa: E501
        )
    from grader.classroom.report.html import render_class_html
    from grader.classroom.report.summary import summarise

    summary = summarise(entries, title=title)
    page.parent.mkdir(parents=True, exist_ok=True)
    page.write_text(render_class_html(entries, summary=summary), encoding="utf-8")
    target.write_text(json.dumps(summary.model_dump(mode="json"), indent=2) + "\n", encoding="utf-8")
    return target
