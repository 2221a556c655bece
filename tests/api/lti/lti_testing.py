"""What the LTI tests share: the tool's environment, following a launch, uploading, waiting."""

from __future__ import annotations

import os
import re
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import httpx
from api_testing import FAKE_GRADER, TESTS_DIR
from live_server import service_environment
from lti_platform import query_of

ONE_PROBLEM = b"def random_blackjack(n):\n    return 0.4\n"
TWO_PROBLEMS = ONE_PROBLEM + b"def blackjack(n):\n    return 0.4\n"
WAIT_SECONDS = 60.0


def tool_environment(data_dir: Path, **settings: Any) -> dict[str, str]:
    """`gymgrade serve`'s environment with the fake grader importable by its grading children."""
    env = service_environment(data_dir, FAKE_GRADER, **settings)
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
