"""Open edX's courseware in a real browser (Chromium headless): the Learning MFE, on its own site, frames
the LMS's ``/xblock/`` page, whose LTI block frames the tool (a third site), launched by Open edX's own
consumer (`lti-consumer-xblock`). Chromium checks every ancestor against the tool's frame-ancestors: the
tool is refused until the MFE's origin is registered for the platform (PUT
/lti/platforms/{id}/frame-ancestors), then launches, uploads and its score reaches Open edX; the session's
link opened in a second browser context is signed out."""

from __future__ import annotations

import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import httpx
import pytest
from api_testing import instructor_headers
from live_server import LiveProcess
from lti_testing import ONE_PROBLEM, tool_environment
from test_lti_browser import CHROMIUM, CHROMIUM_ARGS, WAIT_MS, _chromium

pytest.importorskip("lti_consumer", reason="pip install -e '.[dev]' (lti-consumer-xblock)")

from openedx_platform import OpenEdxPlatform, Passport

pytestmark = [pytest.mark.browser, pytest.mark.e2e, pytest.mark.slow]

COURSE = "course-v1:Uni+RL+2026"


@pytest.fixture
def tool(tmp_path: Path) -> Iterator[LiveProcess]:
    env = tool_environment(tmp_path / "data", lti_publish_seconds=0.2)
    server = LiveProcess("serve", env, tmp_path / "serve.log").start()
    yield server
    server.stop()


def test_the_learning_mfe_frames_the_lms_page_that_frames_the_tool(tool: LiveProcess, tmp_path: Path) -> None:
    sync_api: Any = _chromium()
    solution = tmp_path / "opengym.py"
    solution.write_bytes(ONE_PROBLEM)
    with OpenEdxPlatform().running() as openedx:
        # Three sites: the LMS 127.0.0.1, the MFE apps.openedx.test (the same server under another name),
        # the tool localhost.
        mfe = f"http://apps.openedx.test:{openedx.port}"
        openedx.use_tool(f"http://localhost:{tool.port}")
        passport = Passport()
        block = openedx.add_block(passport, COURSE, "Reinforcement learning 2026 - Uni")
        learner = openedx.add_user("ida", "Ida Frame", {COURSE: "student"})
        registered = httpx.post(
            tool.url + "/lti/platforms", json=openedx.registration(passport), headers=instructor_headers()
        )
        assert registered.status_code == 201, registered.text
        resolver = ["--host-resolver-rules=MAP apps.openedx.test 127.0.0.1"]
        with sync_api.sync_playwright() as playwright:
            browser = playwright.chromium.launch(
                executable_path=CHROMIUM, args=[*CHROMIUM_ARGS, *resolver], headless=True
            )
            try:
                page = browser.new_context().new_page()
                refused = lambda message: "frame-ancestors" in message.text  # noqa: E731
                with page.expect_console_message(refused, timeout=WAIT_MS) as violation:
                    page.goto(openedx.learning_url(learner, block, mfe))
                assert f"frame-ancestors {openedx.issuer}" in violation.value.text
                tool_frame = page.frame_locator("#unit").frame_locator("#lti")
                assert tool_frame.locator("#upload").count() == 0

                allowed = httpx.put(
                    f"{tool.url}/lti/platforms/{registered.json()['id']}/frame-ancestors",
                    json={"frame_ancestors": [mfe]},
                    headers=instructor_headers(),
                )
                assert allowed.status_code == 200, allowed.text
                console: list[str] = []
                page.on("console", lambda message: console.append(message.text))
                page.goto(openedx.learning_url(learner, block, mfe))
                tool_frame.locator("#upload").wait_for(timeout=WAIT_MS)
                assert "signed in as Ida Frame" in tool_frame.locator("header").inner_text()
                tool_frame.locator("#file").set_input_files(str(solution))
                tool_frame.locator("#upload button[type=submit]").click()
                tool_frame.locator("#score").wait_for(timeout=WAIT_MS)
                assert tool_frame.locator("#score").inner_text() == "Score: 1 / 3"
                assert not [text for text in console if "Content Security Policy" in text], console

                # The session's link, opened in a second browser context: signed out there.
                (session_frame,) = [f for f in page.frames if "lti_session=" in f.url]
                other = browser.new_context().new_page()
                other.goto(session_frame.url)
                assert "signed in as" not in other.locator("header").inner_text()
                assert "Ida Frame" not in other.content()
            finally:
                browser.close()
        deadline = time.monotonic() + WAIT_MS / 1000
        while learner.external_id not in block.scores and time.monotonic() < deadline:
            time.sleep(0.1)
        assert [(s["userId"], s.get("scoreGiven")) for s in block.accepted if "scoreGiven" in s] == [
            (learner.external_id, 1.0)
        ]
        assert block.refused == [] and openedx.denied == []
