"""A real browser (Chromium headless) opens the course page of the LMS, which frames the tool on another
site; the launch, the upload and the live score all happen inside the iframe, with third-party cookies
blocked: the tool's cookies are partitioned ones, which the browser keeps. The session link opened in a
second browser context is signed out. A browser that keeps no cookie of the tool at all launches through
the platform's storage (LTI client-side OIDC, postMessage to the course page)."""

from __future__ import annotations

import json
import shutil
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

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


def _chromium() -> object:
    if shutil.which(CHROMIUM) is None:
        pytest.skip(f"Chromium is not installed at {CHROMIUM} (apt-get install -y chromium)")
    return pytest.importorskip("playwright.sync_api", reason="pip install playwright")


def _blocking_every_cookie(profile: Path) -> str:
    """A Chromium profile whose settings block every site's cookies (Settings > Privacy > "Block all");
    its directory."""
    (profile / "Default").mkdir(parents=True)
    preferences = {"profile": {"default_content_setting_values": {"cookies": 2}}}
    (profile / "Default" / "Preferences").write_text(json.dumps(preferences), encoding="utf-8")
    return str(profile)


@pytest.mark.parametrize("cookies", ["partitioned", "none"])
def test_a_launch_upload_and_score_inside_the_lms_iframe(
    tool: LiveProcess, tmp_path: Path, cookies: str
) -> None:
    sync_api: Any = _chromium()
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
        spec = LaunchSpec(person, "link-iframe", browser=True, storage_target="_parent")
        course = platform.course_page(spec)
        with sync_api.sync_playwright() as playwright:
            browser = playwright.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_ARGS, headless=True)
            try:
                if cookies == "none":
                    context = playwright.chromium.launch_persistent_context(
                        _blocking_every_cookie(tmp_path / "profile"),
                        executable_path=CHROMIUM,
                        args=CHROMIUM_ARGS,
                        headless=True,
                    )
                else:
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
                kept = [cookie for cookie in context.cookies() if cookie["domain"] == "localhost"]
                if cookies == "none":
                    assert kept == [], "a cookie was kept by a browser blocking them all"
                    context.close()
                else:
                    assert {cookie["name"] for cookie in kept} >= {"lti_browser"}
                    assert all(c["secure"] and c["httpOnly"] and c["sameSite"] == "None" for c in kept), kept
                    # The session's link, opened in a second browser context: signed out there.
                    (tool_frame,) = [f for f in page.frames if "lti_session=" in f.url]
                    other = browser.new_context().new_page()
                    other.goto(tool_frame.url)
                    assert "signed in as" not in other.locator("header").inner_text()
                    assert "Ida Frame" not in other.content()
                assert not [text for text in console if "Content Security Policy" in text], console
            finally:
                browser.close()
        deadline = time.monotonic() + WAIT_MS / 1000
        while not platform.scores and time.monotonic() < deadline:
            time.sleep(0.1)
        sent = [score for scores in platform.scores.values() for score in scores]
        assert [(score["userId"], score["scoreGiven"]) for score in sent] == [("learner-iframe", 1.0)]


def test_every_ancestor_frame_must_be_allowed_and_a_registered_one_is(tool: LiveProcess) -> None:
    """Open edX: the learning MFE (its own site) frames the LMS page that frames the tool. Chromium checks
    every ancestor against the tool's frame-ancestors: refused until the MFE's origin is registered."""
    sync_api: Any = _chromium()
    with LtiPlatform().running() as platform:
        mfe = f"http://mfe.test:{platform.port}"  # the platform's server under another site's name
        platform.register_tool(f"http://localhost:{tool.port}")
        registered = httpx.post(
            tool.url + "/lti/platforms", json=platform.manual_registration, headers=instructor_headers()
        )
        assert registered.status_code == 201, registered.text
        person = platform.add_person("learner-mfe", "Mia Mfe", LEARNER)
        resolver = ["--host-resolver-rules=MAP mfe.test 127.0.0.1"]
        with sync_api.sync_playwright() as playwright:
            browser = playwright.chromium.launch(
                executable_path=CHROMIUM, args=[*CHROMIUM_ARGS, *resolver], headless=True
            )
            try:
                page = browser.new_context().new_page()
                refused = lambda message: "frame-ancestors" in message.text  # noqa: E731
                with page.expect_console_message(refused, timeout=WAIT_MS) as violation:
                    page.goto(
                        platform.course_page(LaunchSpec(person, "link-mfe", browser=True), mfe_origin=mfe)
                    )
                assert f"frame-ancestors {platform.issuer}" in violation.value.text
                tool_frame = page.frame_locator("#lms").frame_locator("#tool")
                assert tool_frame.locator("#upload").count() == 0
                allowed = httpx.put(
                    f"{tool.url}/lti/platforms/{registered.json()['id']}/frame-ancestors",
                    json={"frame_ancestors": [mfe]},
                    headers=instructor_headers(),
                )
                assert allowed.status_code == 200, allowed.text
                page.goto(platform.course_page(LaunchSpec(person, "link-mfe", browser=True), mfe_origin=mfe))
                tool_frame.locator("#upload").wait_for(timeout=WAIT_MS)
                assert "signed in as Mia Mfe" in tool_frame.locator("header").inner_text()
            finally:
                browser.close()
