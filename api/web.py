"""The Jinja2 environment of the web pages (autoescaping on), the security headers they are sent with, and
how a page answers (:func:`page`, an LTI launch's session carried in its links; :func:`signed_in`).

The pages show each problem's figures through `page_figures` (`grader.render.figures.problem_figures`, the
HTML report's figures, each problem drawn once and cached): a finished report's with its edition's
configuration, and while a submission is being graded, each finished problem's with the first edition's
(every edition plots its problems with the first edition's plotters and settings; `tests/api/test_web.py`
holds them to it).
"""

from __future__ import annotations

import functools
import json
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any
from urllib.parse import urlencode

from fastapi import Request
from fastapi.responses import Response
from fastapi.templating import Jinja2Templates

from api.auth import Principal
from api.errors import NotAuthenticated
from api.lti.sessions import SESSION_PARAMETER
from grader.lab.assignment import AssignmentConfig, load_config
from grader.lab.editions.choice import edition_config
from grader.render.figures import Figure, problem_figures
from grader.render.text import edition_name, lab_name
from grader.report import ProblemResult

TEMPLATES_DIR = Path(__file__).with_name("templates")
STATIC_DIR = Path(__file__).with_name("static")
FIGURES_CACHED = 64
"""Problems whose figures stay drawn (a report has up to eight; the page is refreshed every second)."""

templates = Jinja2Templates(directory=TEMPLATES_DIR)
templates.env.autoescape = True


def page_figures(problems: Sequence[Mapping[str, Any]], edition: str | None) -> dict[str, list[Figure]]:
    """The plots and replays of the problems a page shows, by problem id, as the HTML report draws them.

    Each problem is drawn once, then cached: while the grading runs, a problem's figures appear as soon as
    it has finished, and the finished report reuses them.

    Args:
        problems: The report's problems, or while the grading runs (no report yet) the finished ones.
        edition: The report's edition; None while the grading runs, when the first edition's
            configuration draws them (every edition plots its problems with the first edition's plotters
            and settings, as `tests/api/test_web.py` holds it; a plotter draws nothing for another
            edition's measurements).

    Returns:
        The figures; none for a withheld problem or an entry that is not a grader's problem result.
    """
    config = edition_config(edition) if edition else None
    figures = {}
    for problem in problems:
        if problem.get("status") == "withheld":
            continue
        try:
            drawn = _figures(json.dumps(_figure_input(problem), sort_keys=True), config)
        except (ValueError, TypeError, KeyError):  # not a grader's result: the page shows it without figures
            continue
        figures[str(problem["id"])] = list(drawn)
    return figures


def _figure_input(problem: Mapping[str, Any]) -> dict[str, Any]:
    """The problem as the figures read it: a student's view has its seed nulled, which the figures never
    draw, so a stand-in keeps it a valid `ProblemResult`."""
    return {**problem, "seed": problem.get("seed") or 0, "score": problem.get("score") or 0.0}


@functools.lru_cache(maxsize=FIGURES_CACHED)
def _figures(problem_json: str, config: Path | None) -> tuple[Figure, ...]:
    return tuple(problem_figures(ProblemResult.model_validate_json(problem_json), _config(config)))


@functools.lru_cache(maxsize=8)
def _config(path: Path | None) -> AssignmentConfig:
    return load_config(path)


templates.env.globals["page_figures"] = page_figures
templates.env.globals["lab_name"] = lab_name
templates.env.globals["edition_name"] = edition_name


def page_headers(frame_origins: str | None = None) -> dict[str, str]:
    """The pages' security headers; ``frame_origins`` (an LTI launch's LMS) may frame them, else nobody."""
    ancestors = frame_origins or "'none'"
    return {
        "Content-Security-Policy": (
            "default-src 'none'; script-src 'self'; style-src 'self'; img-src 'self' data:; "
            f"connect-src 'self'; form-action 'self'; frame-ancestors {ancestors}; base-uri 'none'"
        ),
        "X-Content-Type-Options": "nosniff",
        "Referrer-Policy": "no-referrer",
    }


PAGE_HEADERS = page_headers()


def page(request: Request, template: str, context: dict[str, Any], status_code: int = 200) -> Response:
    """A page rendered with its security headers; an LTI launch's pages carry its session in their links
    (``session_query``) and may be framed by its LMS."""
    launched: Principal | None = getattr(request.state, "lti_caller", None)
    return templates.TemplateResponse(
        request,
        template,
        {**context, "session_query": session_query(launched)},
        status_code=status_code,
        headers=page_headers(launched.frame_origin if launched is not None else None),
    )


def session_query(caller: Principal | None) -> str:
    """``?lti_session=...`` for the links and forms of a page an LTI launch signed in, else nothing."""
    if caller is None or caller.session_token is None:
        return ""
    return "?" + urlencode({SESSION_PARAMETER: caller.session_token})


def signed_in(caller: Principal | None) -> Principal:
    """The page's caller; raise NotAuthenticated (the error page says how to sign in) when signed out."""
    if caller is None:
        raise NotAuthenticated("you are signed out; sign in with your token on the start page")
    return caller
