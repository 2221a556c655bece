"""axe-core (bundled by axe-playwright-python, no network) run on a Playwright page, its violations of WCAG
2.0, 2.1 and 2.2 A and AA told one per line; and keyboard-only moves for the flows driven without a mouse."""

from __future__ import annotations

from typing import Any

import pytest

CHROMIUM = "/usr/bin/chromium"
CHROMIUM_ARGS = ["--no-sandbox", "--disable-gpu", "--disable-background-networking", "--no-first-run"]
WCAG_TAGS = ("wcag2a", "wcag2aa", "wcag21a", "wcag21aa", "wcag22aa")
"""axe-core's tags of the WCAG success criteria at levels A and AA (2.2's AA: the 24-pixel target size)."""
MAX_TABS = 60
"""Tab presses that may reach any control of the service's pages (the longest has about 25 stops)."""


def axe_violations(page: Any) -> list[dict[str, Any]]:
    """axe-core's violations of the WCAG A and AA rules on the page as it is now."""
    axe_module = pytest.importorskip("axe_playwright_python.sync_playwright", reason="pip install -e .[dev]")
    options = {"runOnly": {"type": "tag", "values": list(WCAG_TAGS)}, "resultTypes": ["violations"]}
    violations: list[dict[str, Any]] = axe_module.Axe().run(page, options=options).response["violations"]
    return violations


def readable(violations: list[dict[str, Any]]) -> str:
    """Each violation and each element it was found on, with what axe-core says to fix."""
    lines = []
    for violation in violations:
        lines.append(
            f"{violation['id']} ({violation['impact']}): {violation['help']} [{violation['helpUrl']}]"
        )
        for node in violation["nodes"]:
            summary = " ".join(node.get("failureSummary", "").split())
            lines.append(f"    {' '.join(node['target'])}: {node['html'][:160]}\n        {summary}")
    return "\n".join(lines)


def assert_accessible(page: Any, what: str) -> None:
    """Fail with every violation told readably unless axe-core finds none on the page."""
    found = axe_violations(page)
    assert not found, f"{what} ({page.url}) breaks WCAG A/AA rules:\n{readable(found)}"


def focused(page: Any, selector: str) -> bool:
    """Whether the element that has the keyboard focus matches ``selector``."""
    return bool(
        page.evaluate("s => document.activeElement !== null && document.activeElement.matches(s)", selector)
    )


def tab_to(page: Any, selector: str) -> None:
    """Press Tab (only Tab) until ``selector`` has the focus; fail when MAX_TABS presses never reach it."""
    for _ in range(MAX_TABS):
        page.keyboard.press("Tab")
        if focused(page, selector):
            return
    raise AssertionError(f"{MAX_TABS} presses of Tab never focused {selector} on {page.url}")
