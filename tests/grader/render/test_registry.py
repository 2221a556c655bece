"""Every output format of a report, chosen by name: what each writes, and `--format` offering exactly them."""

from __future__ import annotations

import json

import pytest
from classroom.report.support import STOOD_ON_N, report, result

from grader.cli import build_parser
from grader.lab.assignment import load_config
from grader.render.csp import content_security_policy
from grader.render.gradescope import GradescopeResults
from grader.render.html import STYLE
from grader.render.registry import FORMATS, format_help
from grader.render.text import summary
from grader.report import Report

REPORT: Report = report(
    result("blackjack", "failed", STOOD_ON_N.format(n=14, rate=0.31, hands=212)),
    result("cartpole", "passed"),
)


def test_the_text_summary_is_printed_as_one_block() -> None:
    assert FORMATS["text"].render(REPORT, load_config(None)) == summary(REPORT) + "\n"
    assert "Problem 2: failed\n  blackjack(14) returned 0.31" in summary(REPORT)


def test_the_json_is_the_report_itself() -> None:
    written = FORMATS["json"].render(REPORT, load_config(None))
    assert written.endswith("}\n") and Report.model_validate_json(written) == REPORT


def test_the_gradescope_results_hold_a_test_per_problem() -> None:
    written = FORMATS["gradescope"].render(REPORT, load_config(None))
    results = GradescopeResults.model_validate(json.loads(written))
    assert [(test.name, test.status) for test in results.tests] == [
        ("Problem 2", "failed"),
        ("Problem 3", "passed"),
    ]
    assert results.score == 1.0


def test_the_html_page_carries_its_policy() -> None:
    page = FORMATS["html"].render(REPORT, load_config(None))
    assert page.startswith("<!DOCTYPE html>")
    assert f'content="{content_security_policy(STYLE)}"' in page


@pytest.mark.parametrize("output", ["text", "json", "gradescope", "html"])
def test_check_offers_every_format_and_only_those(output: str) -> None:
    args = build_parser().parse_args(["check", "opengym.py", "--format", output])
    assert args.format == output and tuple(FORMATS) == ("text", "json", "gradescope", "html")


def test_only_text_shares_stdout_with_the_progress() -> None:
    assert [name for name, output in FORMATS.items() if output.live_progress] == ["text"]
    assert format_help().startswith("text (default): live progress and a summary; json: ")
