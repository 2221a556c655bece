"""The class page: self-contained under the student report's policy, every hostile string escaped, bounded."""

from __future__ import annotations

import json
from html.parser import HTMLParser
from pathlib import Path

import pytest

from grader.classroom.report import CSP, ClassEntry, render_class_html, summary_path, write_class_report
from grader.classroom.report.html import DIAGNOSES_SHOWN, IDENTITIES_SHOWN, STYLE
from grader.render import html as html_report
from grader.render.csp import content_security_policy
from grader.render.neutral import HIDDEN, MAX_DIAGNOSIS_CHARS

from .support import SHORT_POLE, STOOD_ON_N, all_passed, graded, report, result

HOSTILE = [
    "<script>alert(1)</script>",
    '"><img src=x onerror=alert(1)>',
    "' onmouseover='alert(1)",
    "</bdi></a></td></tr></table><h1>pwned</h1>",
    "{{ 7*7 }}{% raw %}",
    "evil\u202egpj.py",
    "x" * 100_000,
    "0042",
]
"""Identities as a hostile class download might name them (template injection, RTL override, huge)."""
ALLOWED_TAGS = {
    "html", "head", "meta", "title", "style", "body", "h1", "h2", "p", "figure", "img", "figcaption",
    "section", "table", "tr", "th", "td", "ol", "li", "span", "code", "a", "bdi", "strong",
}  # fmt: skip


class Markup(HTMLParser):
    """Every tag, attribute and text of a page, as a browser's tokenizer sees them."""

    def __init__(self) -> None:
        super().__init__(convert_charrefs=True)
        self.tags: list[str] = []
        self.attributes: list[tuple[str, str | None]] = []
        self.text: list[str] = []

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        self.tags.append(tag)
        self.attributes += [(f"{tag}.{name}", value) for name, value in attrs]

    def handle_data(self, data: str) -> None:
        self.text.append(data)


def _hostile_class() -> list[ClassEntry]:
    entries = []
    for index, identity in enumerate(HOSTILE):
        feedback = STOOD_ON_N.format(n=14, rate=0.3, hands=index) if index % 2 else f"{identity} crashed"
        entries.append(
            ClassEntry(identity=identity, name=identity, report=report(result("blackjack", "failed", feedback)),  # noqa: E501
                       late=index % 3 == 0, note=identity, report_href=f"{identity}.json")
        )  # fmt: skip
    entries.append(
        ClassEntry(
            "javascript-link", report=report(result("taxi", "passed")), report_href="javascript:alert(1)"
        )
    )
    entries.append(ClassEntry("<missing>\u202e", name="</title><script>", status="missing"))
    entries.append(
        ClassEntry("broken", report=report(result("taxi", "error", "x"), submission_error="<b>not UTF-8</b>"),
                   status="submission_error")
    )  # fmt: skip
    return entries


def _parsed(page: str) -> Markup:
    markup = Markup()
    markup.feed(page)
    markup.close()
    return markup


def test_the_policy_is_the_student_reports_for_this_pages_own_style() -> None:
    assert content_security_policy(html_report.STYLE) == html_report.CSP
    assert content_security_policy(STYLE) == CSP and STYLE != html_report.STYLE


def test_hostile_identities_names_and_notes_are_text_never_markup() -> None:
    page = render_class_html(_hostile_class(), title="<i>CS 101</i>")
    markup = _parsed(page)
    assert set(markup.tags) <= ALLOWED_TAGS and markup.tags.count("h1") == 1
    assert not [name for name, _ in markup.attributes if name.split(".")[1].startswith("on")]
    assert ("meta.content", CSP) in markup.attributes
    hrefs = [value for name, value in markup.attributes if name == "a.href"]
    assert hrefs and all(
        value and not value.startswith(("/", "javascript")) and ":" not in value for value in hrefs
    )
    assert "%3Cscript%3Ealert%281%29%3C/script%3E.json" in hrefs
    text = "".join(markup.text)
    assert "<script>alert(1)</script>" in text and "pwned" in text and "{{ 7*7 }}" in text
    assert "<b>not UTF-8</b>" in text and "<i>CS 101</i>" in text
    assert "\u202e" not in page and f"evil{HIDDEN}gpj.py" in text
    assert "0042" in text


def test_a_huge_identity_is_cut_on_the_page_and_in_the_summary(tmp_path: Path) -> None:
    page = render_class_html(_hostile_class())
    assert "x" * MAX_DIAGNOSIS_CHARS not in page and len(page) < 100_000
    written = write_class_report(tmp_path / "class.html", _hostile_class())
    summary = json.loads(written.read_text(encoding="utf-8"))
    assert max(len(row["identity"]) for row in summary["entries"]) == 256
    assert all(ord(character) < 128 for character in written.read_text(encoding="utf-8"))
    identities = [row["identity"] for row in summary["entries"]]
    assert "evil\u202egpj.py" in identities, "the JSON keeps identities as given"
    assert [row["report_href"] for row in summary["entries"] if row["identity"] == "javascript-link"] == [
        None
    ]


def test_the_page_shows_the_figures_diagnoses_late_missing_and_links() -> None:
    entries = [
        *(graded(f"u{index}", result("blackjack", "failed", STOOD_ON_N.format(n=14, rate=0.3, hands=index)),
                 result("cartpole", "passed")) for index in range(31)),
        graded("u99", result("blackjack", "passed"),
               result("cartpole", "failed", SHORT_POLE.format(mean=9, episodes=100)), late=True),
        all_passed("u100"),
        ClassEntry("u200", name="Dana", status="missing"),
    ]  # fmt: skip
    page = render_class_html(entries, title="OpenGym lab")
    markup = _parsed(page)
    assert [value[:22] for name, value in markup.attributes if name == "img.src" and value] == [
        "data:image/png;base64,"
    ] * 2
    text = " ".join("".join(markup.text).split())
    assert "31 students · Problem 2 (blackjack) failed:" in text
    assert "so they follow 'draw while the sum is < #': check `<` versus `<=`." in text
    assert "1 student · Problem 3 (cartpole) failed:" in text
    assert "Late submissions (1) u99" in text
    assert "Missing submissions (1) On the roster with no submission: u200 (Dana)" in text
    hrefs = [value for name, value in markup.attributes if name == "a.href"]
    assert {f"u{index}.json" for index in [*range(31), 99, 100]} == set(hrefs)
    assert "u200.json" not in hrefs


def test_a_problem_id_that_reads_as_mathtext_is_drawn_as_text() -> None:
    odd = result("taxi", "failed", "x").model_copy(update={"id": "$\\nosuch$"})
    page = render_class_html([ClassEntry("a", report=report(odd))])
    assert page.count('src="data:image/png;base64,') == 2


def test_long_lists_are_cut_on_the_page_and_say_where_the_rest_is() -> None:
    many = [
        graded(f"s{index:03d}", result("taxi", "failed", "same cause"))
        for index in range(IDENTITIES_SHOWN + 5)
    ]
    rare = [
        graded(f"r{index:03d}", result("taxi", "failed", f"cause {'x' * index}"))
        for index in range(DIAGNOSES_SHOWN + 2)
    ]
    text = " ".join("".join(_parsed(render_class_html(many + rare)).text).split())
    assert "and 5 more (class.json lists them)" in text
    assert "3 less common diagnoses are not shown (class.json lists the first 23)." in text


def test_the_summary_is_written_beside_the_page(tmp_path: Path) -> None:
    page = tmp_path / "deep" / "class.html"
    assert (
        write_class_report(page, [all_passed("a")]) == summary_path(page) == tmp_path / "deep" / "class.json"
    )
    assert json.loads(summary_path(page).read_text(encoding="utf-8"))["graded"] == 1
    with pytest.raises(ValueError, match=r"expected an \.html file name"):
        write_class_report(tmp_path / "class.json", [])


def test_the_class_page_names_the_lab_and_edition() -> None:
    page = render_class_html([all_passed("alice")])
    assert (
        '<p class="meta" id="lab">Lab opengym (OpenGym AI / Reinforcement Learning 1) · edition classic '
        "(OpenGym AI (classic gym))</p>"
    ) in page
    assert 'id="lab"' not in render_class_html([]), "nothing graded: no lab to name"
