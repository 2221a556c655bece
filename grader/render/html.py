"""The HTML report of one grading: verdicts, feedback, plots and replays in one file that needs nothing else.

Every image is a ``data:`` URI; the page carries its own Content-Security-Policy (no scripts, no network,
images only from ``data:``, and only its own stylesheet, pinned by hash), so it can be mailed, uploaded to
a learning platform or opened from disk.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from grader.render.csp import content_security_policy
from grader.render.page import page_environment
from grader.render.text import edition_name, isolation_lines, lab_name
from grader.report import Report

if TYPE_CHECKING:
    from grader.lab.assignment import AssignmentConfig
    from grader.render.figures import Figure

STYLE = (
    "body{font-family:system-ui,sans-serif;max-width:52rem;margin:2rem auto;padding:0 1rem;color:#222}"
    ".meta{color:#555;font-size:.9rem}.badge{font-size:.8rem;padding:.1rem .4rem;border-radius:.3rem;"
    "background:#eee}.status-passed .badge{background:#d4edda}.status-failed .badge,.status-error .badge,"
    ".status-timeout .badge{background:#f8d7da}.points{float:right;font-size:1rem}.error{color:#a00}"
    "figure{margin:1rem 0}img{max-width:100%}figcaption{font-size:.85rem;color:#555}"
    "pre{white-space:pre-wrap;background:#f6f6f6;padding:.5rem}table{border-collapse:collapse;font-size:.85rem}"
    "td,th{border:1px solid #ddd;padding:.2rem .4rem;text-align:left;vertical-align:top}"
    ".feedback{white-space:pre-wrap}"
)
CSP = content_security_policy(STYLE)
"""The page's policy: nothing loads or runs except its images (data: URIs) and its own style."""

_environment = page_environment()


def render_html(
    report: Report, config: AssignmentConfig, figures: dict[str, list[Figure]] | None = None
) -> str:
    """The report as one self-contained HTML page.

    Args:
        report: The grading report.
        config: The assignment configuration it was graded with (bars and tolerances of the plots).
        figures: Figures already drawn (by problem id); drawn here when None.

    Returns:
        The page.
    """
    # Drawing needs matplotlib: imported only when a page is drawn, not whenever a format is chosen.
    from grader.render.figures import all_figures

    drawn = figures if figures is not None else all_figures(report.problems, config)
    isolation = " ".join(isolation_lines(report.isolation))
    return _environment.get_template("report.html").render(
        report=report,
        figures=drawn,
        csp=CSP,
        style=STYLE,
        isolation=isolation,
        edition=edition_name(report.edition),
        lab=lab_name(report.lab),
    )
