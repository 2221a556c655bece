"""The launch, a replay and score publishing on PostgreSQL (`GYMGRADE_DATABASE_URL`), against the same
real platform: the nonce's primary key refuses the replay there too, and a refused launch stores nothing."""

from __future__ import annotations

import html
from collections.abc import Iterator
from pathlib import Path

import httpx
import pytest
from api_testing import PostgresServer, instructor_headers
from live_server import LiveProcess
from lti_platform import LEARNER, LaunchSpec, LtiPlatform
from lti_testing import ONE_PROBLEM, browser, landed, tool_environment, upload, wait

pytestmark = [pytest.mark.e2e, pytest.mark.slow]


@pytest.fixture
def tool(tmp_path: Path, postgres_server: PostgresServer) -> Iterator[LiveProcess]:
    env = tool_environment(
        tmp_path / "data", database_url=postgres_server.new_database(), lti_publish_seconds=0.2
    )
    server = LiveProcess("serve", env, tmp_path / "serve.log").start()
    yield server
    server.stop()


def test_launch_replay_and_score_on_postgresql(tool: LiveProcess) -> None:
    with LtiPlatform().running() as platform, browser() as client:
        platform.register_tool(tool.url)
        registered = httpx.post(
            tool.url + "/lti/platforms", json=platform.manual_registration, headers=instructor_headers()
        )
        assert registered.status_code == 201, registered.text
        again = httpx.post(
            tool.url + "/lti/platforms", json=platform.manual_registration, headers=instructor_headers()
        )
        assert again.status_code == 409
        assert "is registered already" in again.json()["detail"]
        person = platform.add_person("learner-pg", "Pia Postgres", LEARNER)
        form = platform.id_token_post(client, LaunchSpec(person, "link-pg"))
        post = {"id_token": form["id_token"], "state": form["state"]}
        token, page = landed(client, tool.url, client.post(form["launch_url"], data=post))
        assert "signed in as Pia Postgres" in page.text
        replay = client.post(form["launch_url"], data=post)
        assert replay.status_code == 403
        assert "its nonce was seen before" in html.unescape(replay.text)
        students = httpx.get(tool.url + "/gradebook.csv", headers=instructor_headers()).text
        assert students.count("Pia Postgres") == 1
        upload(client, tool.url, token, ONE_PROBLEM)
        sent = wait(lambda: [s for scores in platform.scores.values() for s in scores], "the score")
    assert [(score["userId"], score["scoreGiven"]) for score in sent] == [("learner-pg", 1.0)]
