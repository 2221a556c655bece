"""A real browser (Chromium headless, via Playwright) signs in, uploads, and watches the score appear."""

from __future__ import annotations

import shutil
from collections.abc import Iterator
from pathlib import Path

import pytest
from live_server import E2E_GRADER, PARTIAL_SOLUTION, LiveProcess, create_student, service_environment

pytestmark = [pytest.mark.browser, pytest.mark.e2e, pytest.mark.sandbox]

CHROMIUM = "/usr/bin/chromium"
CHROMIUM_ARGS = [
    "--no-sandbox",
    "--disable-gpu",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--no-first-run",
]
SCORE_WAIT_MS = 120_000


@pytest.fixture
def server(tmp_path: Path) -> Iterator[LiveProcess]:
    process = LiveProcess(
        "serve", service_environment(tmp_path / "data", E2E_GRADER, workers=1), tmp_path / "log"
    )
    process.start()
    yield process
    process.stop()


def test_sign_in_upload_and_see_the_score(server: LiveProcess, tmp_path: Path) -> None:
    if shutil.which(CHROMIUM) is None:
        pytest.skip(f"Chromium is not installed at {CHROMIUM} (apt-get install -y chromium)")
    sync_api = pytest.importorskip("playwright.sync_api", reason="pip install playwright")
    token = create_student(server.url, "ada")
    solution = tmp_path / "opengym.py"
    solution.write_bytes(PARTIAL_SOLUTION)
    with sync_api.sync_playwright() as playwright:
        browser = playwright.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_ARGS, headless=True)
        try:
            page = browser.new_page()
            console: list[str] = []
            page.on("console", lambda message: console.append(message.text))
            page.goto(server.url + "/")
            page.fill("#token", token)
            page.click("#sign-in button[type=submit]")
            page.wait_for_selector("#upload")
            assert "signed in as ada" in page.inner_text("header")
            page.set_input_files("#file", str(solution))
            page.click("#upload button[type=submit]")
            page.wait_for_url("**/ui/submissions/*")
            first_status = page.inner_text("#status")
            assert first_status.startswith(("Status: queued", "Status: running")), first_status
            page.wait_for_selector("#score", timeout=SCORE_WAIT_MS)
            assert page.inner_text("#score") == "Score: 3 / 5"
            assert page.locator("#problem-cartpole .badge").inner_text() == "passed"
            assert page.locator("#problem-blackjack .badge").inner_text() == "missing"
            # The plot and the replay of the student's shortest episode, decoded under the strict CSP.
            page.wait_for_selector("#problem-cartpole figure img")
            images = page.eval_on_selector_all(
                "#problem-cartpole figure img, #problem-car figure img",
                "images => images.map(image => [image.alt, image.complete && image.naturalWidth > 0])",
            )
            assert images == [
                ["CartPole episode lengths", True],
                ["Replay: CartPole-v0", True],
                ["MountainCar episode lengths", True],
                ["Replay: MountainCar-v0", True],
            ]
            assert not [text for text in console if "Content Security Policy" in text], console
        finally:
            browser.close()
