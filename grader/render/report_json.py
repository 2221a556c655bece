"""The report JSON: exactly the report's own serialisation (`grader.report.Report.to_json`), one line end."""

from __future__ import annotations

from typing import TYPE_CHECKING

from grader.report import Report

if TYPE_CHECKING:
    from grader.lab.assignment import AssignmentConfig


def render_json(report: Report, config: AssignmentConfig | None = None) -> str:
    """The report as gymgrade writes it (``--output``, ``--format json``; ``config`` is not needed)."""
    return report.to_json() + "\n"
