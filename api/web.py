"""The Jinja2 environment of the web pages (autoescaping on) and the security headers they are sent with."""

from __future__ import annotations

import functools
import json
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from fastapi.templating import Jinja2Templates

from api.plots import problem_plots
from grader.config import load_config
from grader.editions.choice import edition_config
from grader.figures import Figure, all_figures
from grader.report import Report

TEMPLATES_DIR = Path(__file__).with_name("templates")
STATIC_DIR = Path(__file__).with_name("static")

templates = Jinja2Templates(directory=TEMPLATES_DIR)
templates.env.autoescape = True
templates.env.globals["problem_plots"] = problem_plots


def report_figures(report: Mapping[str, Any] | None) -> dict[str, list[Figure]]:
    """The plots and replays of a finished report, by problem id (drawn once per report, then cached).

    Args:
        report: The stored report, or None while the grading runs.

    Returns:
        The figures; empty for no report or one that is not a grader report.
    """
    if not report:
        return {}
    try:
        return _figures(json.dumps(_figure_inputs(report), sort_keys=True))
    except (ValueError, TypeError, KeyError):  # a report of another layout: the page shows it without figures
        return {}


def _figure_inputs(report: Mapping[str, Any]) -> dict[str, Any]:
    """The report as the figures read it: a student's view has its seeds (and a withheld total) nulled,
    which the figures never draw, so stand-ins keep it a valid `Report`; withheld problems are left out."""
    problems = [
        {**problem, "seed": problem.get("seed") or 0, "score": problem.get("score") or 0.0}
        for problem in report.get("problems", [])
        if problem.get("status") != "withheld"
    ]
    return {
        **report,
        "seed": report.get("seed") or 0,
        "score": report.get("score") or 0.0,
        "problems": problems,
    }


@functools.lru_cache(maxsize=32)
def _figures(report_json: str) -> dict[str, list[Figure]]:
    report = Report.model_validate_json(report_json)
    return all_figures(report.problems, load_config(edition_config(report.edition)))


templates.env.globals["report_figures"] = report_figures

PAGE_HEADERS = {
    "Content-Security-Policy": (
        "default-src 'none'; script-src 'self'; style-src 'self'; img-src 'self' data:; "
        "connect-src 'self'; form-action 'self'; frame-ancestors 'none'; base-uri 'none'"
    ),
    "X-Content-Type-Options": "nosniff",
    "Referrer-Policy": "no-referrer",
}
