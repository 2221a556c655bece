"""``similarity.html``: the ranked pairs, their clusters and the matched code side by side, in one safe page.

The page needs nothing else and runs nothing: its Content-Security-Policy allows no script, no network
and only its own stylesheet (pinned by hash), like the grading report's.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from grader.classroom.similarity.report import Fragment, Pair, SimilarityReport
from grader.render.csp import content_security_policy
from grader.render.page import page_environment

MAX_LINES_SHOWN = 60
"""Lines of each side of a fragment shown; a longer fragment says how many more there are."""
STYLE = (
    "body{font-family:system-ui,sans-serif;max-width:80rem;margin:2rem auto;padding:0 1rem;color:#222}"
    ".meta{color:#555;font-size:.9rem}table{border-collapse:collapse;font-size:.85rem}"
    "td,th{border:1px solid #ddd;padding:.2rem .4rem;text-align:left;vertical-align:top}"
    ".pair{border-top:2px solid #ccc;margin-top:1.5rem}"
    ".sides{display:grid;grid-template-columns:minmax(0,1fr) minmax(0,1fr);gap:.5rem}"
    "pre{white-space:pre;overflow-x:auto;background:#f6f6f6;padding:.5rem;font-size:.8rem;margin:.2rem 0}"
    ".ln{color:#666;user-select:none}.side h4{margin:.3rem 0;font-size:.85rem}.reason{color:#a00}"
    # WCAG 2.2's target size (2.5.8): the pairs' links are at least 24 by 24 CSS pixels.
    "a.pair-link{display:inline-block;min-width:24px;min-height:24px;line-height:24px;text-align:center}"
)
CSP = content_security_policy(STYLE, images=False)

_environment = page_environment(Path(__file__).with_name("templates"))


@dataclass(frozen=True)
class Side:
    """One side of a shown fragment: whose, which lines, the numbered text."""

    identity: str
    first: int
    last: int
    numbered: list[tuple[int, str]]
    hidden: int


@dataclass(frozen=True)
class ShownFragment:
    """A fragment as the page shows it: both sides."""

    left: Side
    right: Side


def render_html(report: SimilarityReport, lines_of: Callable[[str], list[str]]) -> str:
    """The page.

    Args:
        report: The report.
        lines_of: The compared text of an identity, line by line (read only for flagged pairs).
    """
    cache: dict[str, list[str]] = {}

    def lines(identity: str) -> list[str]:
        if identity not in cache:
            cache[identity] = lines_of(identity)
        return cache[identity]

    shown = {
        index: [_shown(pair, fragment, lines) for fragment in pair.fragments]
        for index, pair in enumerate(report.pairs)
    }
    return _environment.get_template("similarity.html").render(
        report=report, shown=shown, csp=CSP, style=STYLE
    )


def _shown(pair: Pair, fragment: Fragment, lines: Callable[[str], list[str]]) -> ShownFragment:
    return ShownFragment(
        _side(pair.a, fragment.a_first, fragment.a_last, lines(pair.a)),
        _side(pair.b, fragment.b_first, fragment.b_last, lines(pair.b)),
    )


def _side(identity: str, first: int, last: int, text: list[str]) -> Side:
    end = min(last, first + MAX_LINES_SHOWN - 1, len(text))
    numbered = [(number, text[number - 1]) for number in range(max(first, 1), end + 1)]
    return Side(identity, first, last, numbered, max(0, last - end))
