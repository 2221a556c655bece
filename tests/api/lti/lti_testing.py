"""What the LTI tests share: the tool's environment, following a launch, uploading, waiting."""

from __future__ import annotations

import html
import http.cookiejar
import os
import re
import time
import urllib.parse
import urllib.request
from collections.abc import Callable
from pathlib import Path
from typing import Any

import httpx
from api_testing import FAKE_GRADER, TESTS_DIR
from cryptography.fernet import Fernet
from live_server import service_environment
from lti_platform import REGISTRATION_TOKEN, query_of

ONE_PROBLEM = b"def random_blackjack(n):\n    return 0.4\n"
TWO_PROBLEMS = ONE_PROBLEM + b"def blackjack(n):\n    return 0.4\n"
WAIT_SECONDS = 60.0


KEY_ENCRYPTION_KEY = Fernet.generate_key().decode("ascii")
LOOPBACK_PLATFORMS = {
    "lti_allow_http": "true",
    "lti_allowed_networks": "127.0.0.0/8,::1/128",
    "key_encryption_key": KEY_ENCRYPTION_KEY,
}
"""The settings letting the tool reach the test platforms (plain http on loopback: never in production),
with its signing keys encrypted."""


def tool_environment(data_dir: Path, **settings: Any) -> dict[str, str]:
    """`gymgrade serve`'s environment with the fake grader importable by its grading children, allowed to
    reach the platforms on loopback over http (unless ``settings`` say otherwise)."""
    env = service_environment(data_dir, FAKE_GRADER, **{**LOOPBACK_PLATFORMS, **settings})
    paths = [str(TESTS_DIR), *filter(None, env.get("PYTHONPATH", "").split(os.pathsep))]
    env["PYTHONPATH"] = os.pathsep.join(paths)
    return env


def landed(client: httpx.Client, base_url: str, response: httpx.Response) -> tuple[str, httpx.Response]:
    """Follow a launch's redirect; the session token and the page it lands on."""
    assert response.status_code == 303, response.text
    location = response.headers["location"]
    token = query_of(location)["lti_session"]
    return token, client.get(base_url + location)


def upload(client: httpx.Client, base_url: str, token: str, content: bytes) -> int:
    """Upload through the page's form, as a launched student; the submission's id."""
    response = client.post(
        base_url + "/ui/submissions", params={"lti_session": token}, files={"file": ("opengym.py", content)}
    )
    assert response.status_code == 303, response.text
    match = re.match(r"/ui/submissions/(\d+)\?lti_session=", response.headers["location"])
    assert match, response.headers["location"]
    return int(match.group(1))


def wait(condition: Callable[[], Any], what: str, timeout: float = WAIT_SECONDS) -> Any:
    """Poll ``condition`` until it is truthy; its value."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        value = condition()
        if value:
            return value
        time.sleep(0.1)
    raise AssertionError(f"timed out waiting for {what}")


def register(
    client: httpx.Client, registration_url: str, configuration: str, token: str = REGISTRATION_TOKEN
) -> httpx.Response:
    """Play the LMS administrator's browser: open the registration URL as the platform does (a GET with
    openid_configuration and registration_token), then press the form's button; the answer to its POST."""
    base = registration_url.split("?", 1)[0]
    opened = client.get(
        base,
        params={
            **query_of(registration_url),
            "openid_configuration": configuration,
            "registration_token": token,
        },
    )
    assert opened.status_code == 200, opened.text
    fields = dict(re.findall(r'<input type="hidden" name="(\w+)" value="([^"]*)">', opened.text))
    return client.post(base, data={name: html.unescape(value) for name, value in fields.items()})


class _LoopbackIsSecure(http.cookiejar.DefaultCookiePolicy):
    """A browser's cookie policy: Secure cookies are sent to http://127.0.0.1 and localhost too (browsers
    treat loopback as a secure context; Python's cookie jar does not)."""

    def return_ok_secure(self, cookie: http.cookiejar.Cookie, request: urllib.request.Request) -> bool:
        host = urllib.parse.urlsplit(request.get_full_url()).hostname
        return host in ("127.0.0.1", "localhost") or super().return_ok_secure(cookie, request)


def browser() -> httpx.Client:
    """An HTTP client keeping cookies as a browser does on loopback (one browser: its own cookie jar).

    The jar is the hooks' own: httpx copies a client's cookies into a jar of the default policy for each
    request, which would drop the policy."""
    jar = httpx.Cookies(http.cookiejar.CookieJar(policy=_LoopbackIsSecure()))

    def send_cookies(request: httpx.Request) -> None:
        if "cookie" in request.headers:
            del request.headers["cookie"]
        jar.set_cookie_header(request)

    def keep_cookies(response: httpx.Response) -> None:
        jar.extract_cookies(response)

    return httpx.Client(event_hooks={"request": [send_cookies], "response": [keep_cookies]})
