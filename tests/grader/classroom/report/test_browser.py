"""Chromium opens the class page from disk: its policy holds, nothing is fetched, figures render, links go."""

from __future__ import annotations

import shutil
from pathlib import Path
from typing import Any

import pytest

from grader.classroom.report import CSP, ClassEntry, render_class_html, write_class_report

from .support import SHORT_POLE, STOOD_ON_N, report, result

CHROMIUM = "/usr/bin/chromium"
RECORD_VIOLATIONS = """
window.violations = [];
document.addEventListener('securitypolicyviolation',
    event => window.violations.push(event.effectiveDirective + ' ' + event.blockedURI));
"""
"""Injected by the browser driver (not part of the page) to collect what the page's policy blocked."""
HOSTILE = '<img src="https://evil.example/x.png">\u202e'


def _class(out: Path) -> list[ClassEntry]:
    """A small class whose reports are written into ``out`` and linked from the page beside it."""
    graded = {
        **{f"u{index}": [result("blackjack", "failed", STOOD_ON_N.format(n=14, rate=0.3, hands=index)),
                         result("cartpole", "passed")] for index in range(5)},
        "u9": [result("blackjack", "passed"),
               result("cartpole", "failed", SHORT_POLE.format(mean=9, episodes=100))],
    }  # fmt: skip
    out.mkdir()
    entries = []
    for identity, results in graded.items():
        (out / f"{identity}.json").write_text(report(*results).to_json(), encoding="utf-8")
        entries.append(
            ClassEntry(
                identity, report=report(*results), late=identity == "u9", report_href=f"out/{identity}.json"
            )
        )
    (out / "evil.json").write_text(report(result("taxi", "passed")).to_json(), encoding="utf-8")
    entries.append(ClassEntry(HOSTILE, report=report(result("taxi", "passed")), report_href="out/evil.json"))
    return [*entries, ClassEntry("u10", name="Dana", status="missing")]


def _open(page_path: Path) -> dict[str, Any]:
    sync_api = pytest.importorskip("playwright.sync_api", reason="pip install playwright")
    seen: dict[str, Any] = {"console": []}
    requests: list[str] = []
    with sync_api.sync_playwright() as playwright:
        browser = playwright.chromium.launch(executable_path=CHROMIUM, args=["--no-sandbox"], headless=True)
        try:
            page = browser.new_page()
            page.add_init_script(RECORD_VIOLATIONS)
            page.on("console", lambda message: seen["console"].append(message.text))
            page.on("request", lambda request: requests.append(request.url))
            page.goto(page_path.as_uri())
            seen["violations"] = page.evaluate("window.violations")
            seen["images"] = page.eval_on_selector_all(
                "figure img", "images => images.map(image => image.complete && image.naturalWidth > 0)"
            )
            seen["style"] = page.eval_on_selector("body", "body => getComputedStyle(body).maxWidth")
            seen["links"] = page.eval_on_selector_all("a.student", "links => links.map(link => link.href)")
            seen["requests"] = list(requests)  # what the page itself asked for, before any click
            if seen["links"]:
                page.click("a.student >> nth=0")
                seen["followed"] = page.url
                seen["followed_text"] = page.content()
        finally:
            browser.close()
    return seen


@pytest.fixture
def chromium() -> None:
    if shutil.which(CHROMIUM) is None:
        pytest.skip(f"Chromium is not installed at {CHROMIUM} (apt-get install -y chromium)")


@pytest.mark.browser
@pytest.mark.usefixtures("chromium")
def test_chromium_shows_the_class_page_under_its_policy_without_fetching_anything(tmp_path: Path) -> None:
    page_path = tmp_path / "class.html"
    write_class_report(page_path, _class(tmp_path / "out"))
    seen = _open(page_path)
    assert seen["console"] == [] and seen["violations"] == []
    assert [url for url in seen["requests"] if not url.startswith("data:")] == [page_path.as_uri()]
    assert seen["images"] == [True, True]
    assert seen["style"] == "960px"  # the page's own stylesheet applied: its hash is in the policy
    linked = {Path(link.removeprefix("file://")).name for link in seen["links"]}
    assert linked == {f"u{index}.json" for index in [0, 1, 2, 3, 4, 9]} | {"evil.json"}
    assert all(Path(link.removeprefix("file://")).is_file() for link in seen["links"])
    assert seen["followed"] == seen["links"][0] and '"submission": "opengym.py"' in seen["followed_text"]


@pytest.mark.browser
@pytest.mark.usefixtures("chromium")
def test_the_violation_recorder_sees_what_the_policy_blocks(tmp_path: Path) -> None:
    """The checks above can fail: a page under the same policy that tries to load and run things is seen
    trying (the request) and blocked (the violations)."""
    page = render_class_html([]).replace(
        "</body>", '<img src="https://evil.example/x.png"><script>document.title = "ran"</script></body>'
    )
    assert f'content="{CSP}"' in page
    path = tmp_path / "hostile.html"
    path.write_text(page, encoding="utf-8")
    seen = _open(path)
    assert sorted(violation.split()[0] for violation in seen["violations"]) == ["img-src", "script-src-elem"]
    assert [url for url in seen["requests"] if not url.startswith("data:")] == [
        path.as_uri(),
        "https://evil.example/x.png",
    ]
    assert seen["console"], "Chromium reports the refused resources on the console"
