"""The class page: one self-contained HTML file under the student report's Content-Security-Policy.

No script, no network: images are ``data:`` URIs and the only style is the page's own, pinned by hash,
under the one policy of ``grader.render.csp``. Every string from a student or a roster is escaped by
the template and shown through the page filters of ``grader.render.neutral`` (bounded, no controls or
bidi overrides, inside ``<bdi>``); links to the students' reports are relative paths checked by ``safe_href``.
"""

from __future__ import annotations

from collections.abc import Sequence

from grader.classroom.report.entries import ClassEntry
from grader.classroom.report.figures import class_figures
from grader.classroom.report.summary import ClassSummary, summarise
from grader.render.csp import content_security_policy
from grader.render.figures import Figure
from grader.render.page import page_environment

TEMPLATE = "class_report.html"
DIAGNOSES_SHOWN = 20
"""Diagnosis groups on the page (most common first); class.json lists more."""
IDENTITIES_SHOWN = 60
"""Students named under one diagnosis on the page; class.json names them all."""
STYLE = (
    "body{font-family:system-ui,sans-serif;max-width:60rem;margin:2rem auto;padding:0 1rem;color:#222}"
    ".meta{color:#555;font-size:.9rem}figure{margin:1rem 0}img{max-width:100%}"
    "figcaption{font-size:.85rem;color:#555}table{border-collapse:collapse;font-size:.85rem}"
    "td,th{border:1px solid #ddd;padding:.2rem .4rem;text-align:left;vertical-align:top}"
    ".count{font-weight:bold}.diagnosis{white-space:pre-wrap}.who{font-size:.85rem;color:#333}"
    ".late{color:#a60}.error{color:#a00}.missing{color:#666}"
    # WCAG 2.2's target size (2.5.8): a student's link is at least 24 by 24 CSS pixels, in a list or a table.
    "a.student{display:inline-block;min-width:24px;min-height:24px;line-height:24px;text-align:center}"
)


CSP = content_security_policy(STYLE)

_environment = page_environment()


def render_class_html(
    entries: Sequence[ClassEntry],
    *,
    title: str = "",
    summary: ClassSummary | None = None,
    figures: Sequence[Figure] | None = None,
) -> str:
    """The class report as one self-contained HTML page.

    Args:
        entries: One entry per student (or group member), in any order.
        title: What the class or assignment is called.
        summary: The summary of ``entries`` when already computed (``summarise``).
        figures: The class figures when already drawn (``class_figures``).

    Returns:
        The page.
    """
    summarised = summary if summary is not None else summarise(entries, title=title)
    drawn = list(figures) if figures is not None else class_figures(summarised)
    return _environment.get_template(TEMPLATE).render(
        summary=summarised,
        figures=drawn,
        diagnoses=summarised.diagnoses[:DIAGNOSES_SHOWN],
        rows={row.identity: row for row in summarised.entries},
        identities_shown=IDENTITIES_SHOWN,
        csp=CSP,
        style=STYLE,
    )
