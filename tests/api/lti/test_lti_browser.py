"""A real browser (Chromium headless) opens the course page of the LMS, which frames the tool on another
site; the launch, the upload and the live score all happen inside the iframe, with third-party cookies
blocked and no cookie set at all."""

from __future__ import annotations

import shutil
import time
from collections.abc import Iterator
from pathlib import Path

import httpx
import pytest
from api_testing import instructor_headers
from live_server import LiveProcess
from lti_platform import LEARNER, LaunchSpec, LtiPlatform
from lti_testing import tool_environment

pytestmark = [pytest.mark.browser, pytest.mark.e2e, pytest.mark.slow]

CHROMIUM = "/usr/bin/chromium"
CHROMIUM_ARGS = [
    "--no-sandbox",
    "--disable-gpu",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--no-first-run",
    "--test-third-party-cookie-phaseout",
]
WAIT_MS = 60_000


@pytest.fixture
def tool(tmp_path: Path) -> Iterator[LiveProcess]:
    env = tool_environment(tmp_path / "data", lti_publish_seconds=0.2)
    server = LiveProcess("serve", env, tmp_path / "serve.log").start()
    yield server
    server.stop()


def test_a_launch_upload_and_score_inside_the_lms_iframe(tool: LiveProcess, tmp_path: Path) -> None:
    if shutil.which(CHROMIUM) is None:
        pytest.skip(f"Chromium is not installed at {CHROMIUM} (apt-get install -y chromium)")
    sync_api = pytest.importorskip("playwright.sync_api", reason="pip install playwright")
    solution = tmp_path / "opengym.py"
    solution.write_bytes(b"def random_blackjack(n):\n    return 0.4\n")
    with LtiPlatform().running() as platform:
        # The LMS is 127.0.0.1, the tool localhost: two sites, so the tool's frame is third-party.
        platform.register_tool(f"http://localhost:{tool.port}")
        registered = httpx.post(
            tool.url + "/lti/platforms", json=platform.manual_registration, headers=instructor_headers()
        )
        assert registered.status_code == 201, registered.text
        person = platform.add_person("learner-iframe", "Ida Frame", LEARNER)
        course = platform.course_page(LaunchSpec(person, "link-iframe", browser=True))
        with sync_api.sync_playwright() as playwright:
            browser = playwright.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_ARGS, headless=True)
            try:
                context = browser.new_context()
                page = context.new_page()
                console: list[str] = []
                page.on("console", lambda message: console.append(message.text))
                page.goto(course)
                frame = page.frame_locator("#tool")
                frame.locator("#upload").wait_for(timeout=WAIT_MS)
                assert "signed in as Ida Frame" in frame.locator("header").inner_text()
                frame.locator("#file").set_input_files(str(solution))
                frame.locator("#upload button[type=submit]").click()
                frame.locator("#score").wait_for(timeout=WAIT_MS)
                assert frame.locator("#score").inner_text() == "Score: 1 / 3"
                assert context.cookies() == [], "the tool set a cookie; an LMS iframe may not keep it"
                assert not [text for text in console if "Content Security Policy" in text], console
            finally:
                browser.close()
        deadline = time.monotonic() + WAIT_MS / 1000
        while not platform.scores and time.monotonic() < deadline:
            time.sleep(0.1)
        sent = [score for scores in platform.scores.values() for score in scores]
        assert [(score["userId"], score["scoreGiven"]) for score in sent] == [("learner-iframe", 1.0)]
