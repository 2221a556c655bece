"""The frame of every self-contained page gymgrade writes (`templates/page.html`) and its Jinja environment.

A page template extends ``page.html``, filling its ``title`` and ``body`` blocks; the frame adds the page's
Content-Security-Policy (`grader.render.csp`) and its one stylesheet, passed as ``csp`` and ``style``. Hostile
text is shown through the filters of ``grader.render.neutral.PAGE_FILTERS`` (``identity``,
``document``, ``name``, ``note``, ``line``, ``code``), installed in every page's environment.
"""

from __future__ import annotations

from pathlib import Path

from jinja2 import Environment, FileSystemLoader, select_autoescape

from grader.render.neutral import PAGE_FILTERS

TEMPLATES = Path(__file__).with_name("templates")
"""The report pages' templates and the frame."""


def page_environment(*templates: Path) -> Environment:
    """An environment drawing pages from ``templates`` (then `TEMPLATES`, where the frame is): every value
    escaped as HTML, the template's last newline kept, the hostile-text filters installed."""
    environment = Environment(
        loader=FileSystemLoader([*templates, TEMPLATES]),
        autoescape=select_autoescape(["html"]),
        keep_trailing_newline=True,
    )
    environment.filters.update(PAGE_FILTERS)
    return environment
