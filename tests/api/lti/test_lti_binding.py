"""A launch's state and session are bound to the browser that started them (api/lti/binding.py), played
by a real platform against `gymgrade serve`, each browser an HTTP client with its own cookie jar: a state
replayed from another browser (login CSRF) and a session link opened in another browser are refused; a
browser keeping no cookie completes the launch through the platform's storage (LTI client-side OIDC,
whose postMessage half a real browser plays in test_lti_browser.py)."""

from __future__ import annotations

import html
import re
import sqlite3
from collections.abc import Iterator
from pathlib import Path

import httpx
import pytest
from api_testing import instructor_headers
from live_server import LiveProcess
from lti_platform import LEARNER, LaunchSpec, LtiPlatform, query_of
from lti_testing import browser, landed, tool_environment

pytestmark = [pytest.mark.e2e, pytest.mark.slow]


@pytest.fixture(scope="module")
def platform() -> Iterator[LtiPlatform]:
    with LtiPlatform().running() as running:
        yield running


@pytest.fixture(scope="module")
def tool(tmp_path_factory: pytest.TempPathFactory, platform: LtiPlatform) -> Iterator[LiveProcess]:
    directory = tmp_path_factory.mktemp("lti-binding")
    server = LiveProcess("serve", tool_environment(directory / "data"), directory / "serve.log").start()
    platform.register_tool(server.url)
    registered = httpx.post(
        server.url + "/lti/platforms", json=platform.manual_registration, headers=instructor_headers()
    )
    assert registered.status_code == 201, registered.text
    yield server
    server.stop()


def sessions(tool: LiveProcess) -> int:
    with sqlite3.connect(Path(tool._env["GYMGRADE_DATA_DIR"]) / "gymgrade.sqlite3") as connection:
        count: int = connection.execute("SELECT COUNT(*) FROM lti_sessions").fetchone()[0]
    return count


def test_a_state_replayed_from_another_browser_is_refused(platform: LtiPlatform, tool: LiveProcess) -> None:
    """Login CSRF: the attacker starts a login in their browser and has the victim's post its id_token and
    state (the victim would be signed in as the attacker, and upload as them)."""
    attacker = platform.add_person("learner-mal", "Mal Attacker", LEARNER)
    with browser() as theirs, browser() as victims:
        form = platform.id_token_post(theirs, LaunchSpec(attacker, "link-1"))
        before = sessions(tool)
        refused = victims.post(
            form["launch_url"], data={"id_token": form["id_token"], "state": form["state"]}
        )
        assert refused.status_code == 403
        assert "this launch did not come from the browser its login started in" in html.unescape(refused.text)
        assert sessions(tool) == before
        # The same post from the browser the login began in is accepted.
        accepted = theirs.post(
            form["launch_url"], data={"id_token": form["id_token"], "state": form["state"]}
        )
        assert accepted.status_code == 303, accepted.text


def test_a_session_link_opened_in_another_browser_is_refused(
    platform: LtiPlatform, tool: LiveProcess
) -> None:
    person = platform.add_person("learner-vic", "Vic Victim", LEARNER)
    with browser() as own, browser() as other:
        token, page = landed(own, tool.url, platform.launch(own, LaunchSpec(person, "link-1")))
        assert "signed in as Vic Victim" in page.text
        shared = other.get(tool.url + "/", params={"lti_session": token})
        assert (
            shared.status_code == 200 and "signed in as" not in shared.text and 'name="token"' in shared.text
        )
        upload = other.post(
            tool.url + "/ui/submissions",
            params={"lti_session": token},
            files={"file": ("opengym.py", b"x = 1\n")},
        )
        assert upload.status_code in (401, 303) and "/ui/submissions/" not in upload.headers.get(
            "location", ""
        )
        # A second launch in the first browser keeps both of its sessions working.
        again, _ = landed(own, tool.url, platform.launch(own, LaunchSpec(person, "link-2")))
        for session in (token, again):
            assert "signed in as Vic Victim" in own.get(tool.url + "/", params={"lti_session": session}).text


def _storage_page(page: httpx.Response) -> dict[str, str]:
    assert page.status_code == 200, page.text
    found = re.search(r'<div id="lti-storage" ([^>]*)>', page.text)
    assert found, page.text
    return {name: html.unescape(value) for name, value in re.findall(r'data-(\w+)="([^"]*)"', found.group(1))}


def test_a_browser_keeping_no_cookie_launches_through_the_platforms_storage(
    platform: LtiPlatform, tool: LiveProcess
) -> None:
    """What lti-storage.js does in a browser, done by hand: the platform's storage keeps the login's
    secret; a launch without the login's cookie reads it back and posts it; a wrong one is refused."""
    person = platform.add_person("learner-safari", "Sam Safari", LEARNER)
    spec = LaunchSpec(person, "link-1", storage_target="_parent")
    # Python's default cookie policy sends no Secure cookie over http: a browser that keeps none.
    with httpx.Client() as cookieless:
        put = _storage_page(cookieless.get(platform.login_url(spec)))
        assert (put["action"], put["target"], put["origin"]) == ("put", "_parent", platform.issuer)
        assert put["key"].startswith("gymgrade_bind_") and put["next"].startswith(platform.issuer + "/auth?")
        form = cookieless.get(put["next"]).json()
        post = {"id_token": form["id_token"], "state": form["state"]}
        get = _storage_page(cookieless.post(form["launch_url"], data=post))
        assert (get["action"], get["key"], get["origin"]) == ("get", put["key"], platform.issuer)
        wrong = cookieless.post(form["launch_url"], data={**post, "storage_answer": "not-the-secret"})
        assert wrong.status_code == 403
        assert "did not come from the browser its login started in" in html.unescape(wrong.text)
        landed_at = cookieless.post(form["launch_url"], data={**post, "storage_answer": put["value"]})
    assert landed_at.status_code == 303, landed_at.text
    assert "lti_session" in query_of(landed_at.headers["location"])
