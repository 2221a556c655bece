"""The service as an LTI 1.3 Advantage tool, driven end to end by a real platform (`lti1p3platform`, on
loopback, see lti_platform.py) against `gymgrade serve` (real uvicorn, the fake grader)."""

from __future__ import annotations

import html
import re
import sqlite3
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import httpx
import pytest
from api_testing import instructor_headers
from fake_grader import held, release
from live_server import LiveProcess, create_student
from live_server import upload as upload_with_token
from lti_platform import (
    INSTRUCTOR,
    LEARNER,
    REGISTRATION_TOKEN,
    TEACHING_ASSISTANT,
    LaunchSpec,
    LtiPlatform,
    new_private_key,
)
from lti_testing import ONE_PROBLEM, TWO_PROBLEMS, browser, landed, register, tool_environment, upload, wait

from grader.lab.editions import EDITIONS

pytestmark = [pytest.mark.e2e, pytest.mark.slow]

PUBLISH_SECONDS = 0.2


@pytest.fixture(scope="module")
def platform() -> Iterator[LtiPlatform]:
    """The LMS, running."""
    with LtiPlatform().running() as running:
        yield running


@pytest.fixture(scope="module")
def tool(tmp_path_factory: pytest.TempPathFactory, platform: LtiPlatform) -> Iterator[LiveProcess]:
    """`gymgrade serve` with the platform registered by hand (POST /lti/platforms)."""
    directory = tmp_path_factory.mktemp("lti-tool")
    env = tool_environment(
        directory / "data",
        lti_publish_seconds=PUBLISH_SECONDS,
        lti_retry_seconds=0.2,
        lti_publish_attempts=3,
        rate_limit_per_minute=1000,
    )
    server = LiveProcess("serve", env, directory / "serve.log").start()
    try:
        platform.register_tool(server.url)
        response = httpx.post(
            server.url + "/lti/platforms", json=platform.manual_registration, headers=instructor_headers()
        )
        assert response.status_code == 201, response.text
        yield server
    finally:
        server.stop()


def database(tool: LiveProcess) -> Path:
    return Path(tool._env["GYMGRADE_DATA_DIR"]) / "gymgrade.sqlite3"


def counts(tool: LiveProcess) -> dict[str, int]:
    """Rows of the tables a launch writes to."""
    with sqlite3.connect(database(tool)) as connection:
        return {
            table: connection.execute(f"SELECT COUNT(*) FROM {table}").fetchone()[0]
            for table in ("students", "lti_users", "lti_links", "lti_members", "lti_sessions", "lti_nonces")
        }


def scores_for(platform: LtiPlatform, sub: str) -> list[dict[str, Any]]:
    return [score for scores in platform.scores.values() for score in scores if score["userId"] == sub]


def graded(tool: LiveProcess, submission_id: int) -> bool:
    with sqlite3.connect(database(tool)) as connection:
        row = connection.execute("SELECT status FROM submissions WHERE id = ?", (submission_id,)).fetchone()
    return row is not None and row[0] == "done"


def publishing_rounds(tool: LiveProcess) -> int:
    """The rounds the server's publisher has finished (GET /lti/publisher)."""
    response = httpx.get(tool.url + "/lti/publisher", headers=instructor_headers())
    assert response.status_code == 200, response.text
    progress = response.json()
    assert progress["running"] and progress["period_seconds"] == PUBLISH_SECONDS, progress
    return int(progress["rounds"])


def two_publishing_rounds(tool: LiveProcess) -> None:
    """Wait until two more rounds have finished: the second began after this call, so it saw every change made
    before it (the first may have begun earlier). Anything it would send has been sent when this returns."""
    before = publishing_rounds(tool)
    wait(lambda: publishing_rounds(tool) >= before + 2, "two publishing rounds")


def test_a_learner_lands_signed_in_and_each_grading_reaches_the_gradebook_once(
    platform: LtiPlatform, tool: LiveProcess
) -> None:
    person = platform.add_person("learner-ada", "Ada Lovelace", LEARNER)
    with browser() as client:
        launched = platform.launch(client, LaunchSpec(person, "link-1"))
        (bound,) = [
            cookie for cookie in launched.headers.get_list("set-cookie") if cookie.startswith("lti_browser=")
        ]
        for attribute in ("HttpOnly", "Partitioned", "SameSite=None", "Secure", "Path=/"):
            assert attribute in bound, f"the session's cookie lacks {attribute} (an LMS frame would drop it)"
        token, page = landed(client, tool.url, launched)
        assert page.status_code == 200
        assert "Upload your solution" in page.text
        assert "signed in as Ada Lovelace" in page.text
        assert f"frame-ancestors {platform.issuer}" in page.headers["content-security-policy"]
        assert f'action="/ui/submissions?lti_session={token}"' in page.text

        first = upload(client, tool.url, token, ONE_PROBLEM)
        sent = wait(lambda: scores_for(platform, person.sub), "the first score at the platform")
        assert len(sent) == 1
        assert sent[0]["scoreGiven"] == 1.0 and sent[0]["scoreMaximum"] == 3.0
        assert (sent[0]["activityProgress"], sent[0]["gradingProgress"]) == ("Completed", "FullyGraded")
        items = [item for item in platform.line_items.values() if item["resourceLinkId"] == "link-1"]
        assert len(items) == 1 and items[0]["resourceId"] == "gymgrade"
        two_publishing_rounds(tool)  # "nothing was sent again": the rounds that would have sent it ended
        assert len(scores_for(platform, person.sub)) == 1, "the same score was sent twice"

        # A regrade of the same bytes (the row queued again) gives the same score: nothing new is sent.
        with sqlite3.connect(database(tool)) as connection:
            connection.execute(
                "UPDATE submissions SET status = 'queued', attempts = 0 WHERE id = ?", (first,)
            )
        wait(lambda: graded(tool, first), "the regrade")
        two_publishing_rounds(tool)
        assert len(scores_for(platform, person.sub)) == 1, "the regrade's same score was sent again"

        upload(client, tool.url, token, TWO_PROBLEMS)
        wait(lambda: len(scores_for(platform, person.sub)) == 2, "the better score")
        assert scores_for(platform, person.sub)[-1]["scoreGiven"] == 2.0
        assert len([item for item in platform.line_items.values() if item["resourceLinkId"] == "link-1"]) == 1

        # Launching again lands in the same student, with the same line item.
        again, page = landed(client, tool.url, platform.launch(client, LaunchSpec(person, "link-1")))
        assert again != token and "Ada Lovelace" in page.text
    log = tool._log_path.read_text(encoding="utf-8")
    assert token not in log and again not in log, "a session token was written to the server's log"
    assert "lti_session=[redacted]" in log
    listed = httpx.get(tool.url + "/lti/scores", headers=instructor_headers()).json()
    ada = [row for row in listed if row["student"] == "Ada Lovelace"]
    assert [(row["status"], row["sent_score"], row["error"]) for row in ada] == [("sent", 2.0, None)]


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (
            {"claims": {"aud": "someone-else"}},
            "is addressed to ['someone-else']; expected this tool's client id",
        ),
        (
            {"claims": {"https://purl.imsglobal.org/spec/lti/claim/deployment_id": "deployment-9"}},
            "deployment 'deployment-9' of",
        ),
        ({"expiration": -600}, "the id_token expired at"),
        ({"signing_key": "forged"}, "signature does not verify against the platform's keys"),
        ({"claims": {"https://purl.imsglobal.org/spec/lti/claim/version": "1.1"}}, "LTI version is '1.1'"),
        (
            {
                "claims": {
                    "https://purl.imsglobal.org/spec/lti/claim/message_type": "LtiSubmissionReviewRequest"
                }
            },
            "message type is 'LtiSubmissionReviewRequest'",
        ),
        ({"claims": {"iss": "https://evil.example"}}, "issuer is 'https://evil.example'"),
    ],
    ids=["wrong-audience", "wrong-deployment", "expired", "another-key", "version", "message-type", "issuer"],
)
def test_a_hostile_launch_is_refused_and_stores_nothing(
    platform: LtiPlatform, tool: LiveProcess, change: dict[str, Any], message: str
) -> None:
    person = platform.add_person("learner-mallory", "Mallory", LEARNER)
    if change.get("signing_key") == "forged":
        change = {**change, "signing_key": new_private_key()}
    before = counts(tool)
    with browser() as client:
        response = platform.launch(client, LaunchSpec(person, "link-1", **change))
    assert response.status_code == 403
    assert message in html.unescape(response.text)
    assert counts(tool) == before


def test_a_replayed_launch_is_refused_and_stores_nothing(platform: LtiPlatform, tool: LiveProcess) -> None:
    person = platform.add_person("learner-eve", "Eve", LEARNER)
    with browser() as client:
        form = platform.id_token_post(client, LaunchSpec(person, "link-1"))
        post = {"id_token": form["id_token"], "state": form["state"]}
        assert client.post(form["launch_url"], data=post).status_code == 303
        before = counts(tool)
        replay = client.post(form["launch_url"], data=post)
    assert replay.status_code == 403
    assert "this launch was used already (its nonce was seen before)" in html.unescape(replay.text)
    assert counts(tool) == before


def test_an_id_token_posted_with_another_logins_state_is_refused(
    platform: LtiPlatform, tool: LiveProcess
) -> None:
    person = platform.add_person("learner-oscar", "Oscar", LEARNER)
    with browser() as client:
        first = platform.id_token_post(client, LaunchSpec(person, "link-1"))
        second = platform.id_token_post(client, LaunchSpec(person, "link-1"))
        before = counts(tool)
        response = client.post(
            first["launch_url"], data={"id_token": first["id_token"], "state": second["state"]}
        )
    assert response.status_code == 403
    assert "the id_token's nonce is not the one this login started with" in html.unescape(response.text)
    assert counts(tool) == before


def test_a_state_not_issued_by_the_tool_is_refused(platform: LtiPlatform, tool: LiveProcess) -> None:
    person = platform.add_person("learner-trudy", "Trudy", LEARNER)
    with browser() as client:
        form = platform.id_token_post(client, LaunchSpec(person, "link-1"))
        before = counts(tool)
        response = client.post(
            form["launch_url"], data={"id_token": form["id_token"], "state": "made.up.state"}
        )
    assert response.status_code == 403
    assert "the launch's state was not issued by this tool" in html.unescape(response.text)
    assert counts(tool) == before


def test_a_student_cannot_publish_scores_or_read_another_students_work(
    platform: LtiPlatform, tool: LiveProcess
) -> None:
    alice = platform.add_person("learner-alice", "Alice", LEARNER)
    bob = platform.add_person("learner-bob", "Bob", LEARNER)
    with browser() as client:
        alice_token, _ = landed(client, tool.url, platform.launch(client, LaunchSpec(alice, "link-1")))
        bob_token, _ = landed(client, tool.url, platform.launch(client, LaunchSpec(bob, "link-1")))
        bobs = upload(client, tool.url, bob_token, ONE_PROBLEM)
        other = client.get(f"{tool.url}/ui/submissions/{bobs}", params={"lti_session": alice_token})
        assert other.status_code == 404
        for method, path in [
            ("GET", "/lti/scores"),
            ("GET", "/lti/publisher"),
            ("POST", "/lti/links/1/roster"),
            ("POST", "/lti/platforms"),
            ("POST", "/lti/keys/rotate"),
            ("GET", f"/submissions/{bobs}"),
        ]:
            as_bearer = client.request(
                method, tool.url + path, headers={"Authorization": f"Bearer {alice_token}"}
            )
            assert as_bearer.status_code == 401, (path, as_bearer.text)
            as_page = client.request(method, tool.url + path, params={"lti_session": alice_token})
            assert as_page.status_code == 401, (path, as_page.text)


def test_scores_refused_by_the_platform_are_sent_again_and_shown_to_the_instructor(
    platform: LtiPlatform, tool: LiveProcess
) -> None:
    person = platform.add_person("learner-grace", "Grace", LEARNER)
    platform.score_failures[person.sub] = 10**9  # the gradebook is down until the test brings it back
    refused_before = platform.refused_scores
    with browser() as client:
        token, _ = landed(client, tool.url, platform.launch(client, LaunchSpec(person, "link-2")))
        submission = upload(client, tool.url, token, ONE_PROBLEM)

        def shown() -> list[dict[str, Any]]:
            rows = httpx.get(tool.url + "/lti/scores", headers=instructor_headers()).json()
            return [row for row in rows if row["student"] == "Grace" and row["status"] == "failed"]

        # The event: refused as many times as GYMGRADE_LTI_PUBLISH_ATTEMPTS (3), the row shows as failed.
        # Only then does the platform recover: no retry schedule races the test's polling.
        failing = wait(shown, "the instructor to see the refused score as failed")
        assert failing[0]["attempts"] >= 3 and "the LMS answered 500" in failing[0]["error"]
        assert graded(tool, submission), "a refused score never holds up the grading"
        with platform.lock:
            refused = platform.refused_scores - refused_before
            platform.score_failures[person.sub] = 0
        sent = wait(lambda: scores_for(platform, person.sub), "the score once the platform recovers")
    assert len(sent) == 1
    assert refused >= failing[0]["attempts"] >= 3, "each attempt was a send the platform refused"
    rows = httpx.get(tool.url + "/lti/scores", headers=instructor_headers()).json()
    assert [(row["status"], row["error"]) for row in rows if row["student"] == "Grace"] == [("sent", None)]
    teacher = platform.add_person("staff-grace", "Gale Grader", INSTRUCTOR)
    with browser() as client:
        _, page = landed(client, tool.url, platform.launch(client, LaunchSpec(teacher, "link-2")))
    assert "Scores in the LMS" in page.text
    assert re.search(
        r"<td>Grace</td>\s*<td>1 / 3</td>\s*<td>1</td>\s*<td class=\"lms-sent\">sent</td>", page.text
    )


def test_staff_land_as_the_instructor_and_import_the_roster(platform: LtiPlatform, tool: LiveProcess) -> None:
    teacher = platform.add_person("staff-ta", "Terry TA", TEACHING_ASSISTANT)
    platform.add_person("learner-never", "Nora Neverlaunched", LEARNER)
    with browser() as client:
        token, page = landed(client, tool.url, platform.launch(client, LaunchSpec(teacher, "link-1")))
        assert "All submissions" in page.text and "Upload your solution" not in page.text
        assert f'action="/ui/lti/roster?lti_session={token}"' in page.text
        imported = client.post(tool.url + "/ui/lti/roster", params={"lti_session": token})
    assert imported.status_code == 200, imported.text
    found = re.search(r"(\d+) students \(each now has a row in the gradebook\), (\d+) staff", imported.text)
    assert found and int(found.group(1)) >= 2 and int(found.group(2)) >= 1
    gradebook = httpx.get(tool.url + "/gradebook.csv", headers=instructor_headers()).text
    assert "Nora Neverlaunched," in gradebook
    assert "Terry TA" not in gradebook
    links = httpx.get(tool.url + "/lti/links", headers=instructor_headers()).json()
    link = next(link for link in links if link["resource_link_id"] == "link-1")
    again = httpx.post(f"{tool.url}/lti/links/{link['id']}/roster", headers=instructor_headers())
    assert again.status_code == 200, again.text
    assert again.json()["learners"] == int(found.group(1))
    gradebook = httpx.get(tool.url + "/gradebook.csv", headers=instructor_headers()).text
    assert gradebook.count("Nora Neverlaunched") == 1, "an import made a second row"


def test_a_deployment_added_by_the_instructor_is_accepted(platform: LtiPlatform, tool: LiveProcess) -> None:
    person = platform.add_person("learner-dep", "Dana Deployment", LEARNER)
    other = {"claims": {"https://purl.imsglobal.org/spec/lti/claim/deployment_id": "deployment-7"}}
    with browser() as client:
        assert platform.launch(client, LaunchSpec(person, "link-7", **other)).status_code == 403
        (row,) = [
            p
            for p in httpx.get(tool.url + "/lti/platforms", headers=instructor_headers()).json()
            if p["issuer"] == platform.issuer
        ]
        added = httpx.post(
            f"{tool.url}/lti/platforms/{row['id']}/deployments",
            json={"deployment_id": "deployment-7"},
            headers=instructor_headers(),
        )
        assert added.status_code == 200 and "deployment-7" in added.json()["deployment_ids"]
        _, page = landed(client, tool.url, platform.launch(client, LaunchSpec(person, "link-7", **other)))
    assert "signed in as Dana Deployment" in page.text


def test_deep_linking_carries_the_lab_and_edition_picked(platform: LtiPlatform, tool: LiveProcess) -> None:
    teacher = platform.add_person("staff-ines", "Ines Instructor", INSTRUCTOR)
    with browser() as client:
        picker = platform.launch(client, LaunchSpec(teacher, "", deep_linking=True))
        assert picker.status_code == 200, picker.text
        token = re.search(r'name="picker" value="([^"]+)"', picker.text)
        assert token and 'value="classic" required checked' in picker.text
        assert 'value="rl1" required disabled' in picker.text, "an edition this service does not grade"
        other = client.post(tool.url + "/lti/deep-link", data={"picker": token.group(1), "edition": "rl1"})
        assert other.status_code == 400
        assert "this service grades edition 'classic' (GYMGRADE_EDITION), so a link for 'rl1'" in other.text
        answer = client.post(
            tool.url + "/lti/deep-link", data={"picker": token.group(1), "edition": "classic"}
        )
        assert answer.status_code == 200, answer.text
        action = re.search(r'action="([^"]+)"', answer.text)
        response_jwt = re.search(r'name="JWT" value="([^"]+)"', answer.text)
        assert (
            action
            and response_jwt
            and html.unescape(action.group(1)) == platform.issuer + "/deep_link_return"
        )
        accepted = client.post(html.unescape(action.group(1)), data={"JWT": response_jwt.group(1)})
    assert accepted.status_code == 200, accepted.text
    (item,) = accepted.json()["items"]
    assert item["type"] == "ltiResourceLink"
    assert item["custom"] == {"lab": "OpenGym AI (classic gym)", "edition": "classic"}
    assert item["url"] == tool.url + "/lti/launch"
    learner = platform.add_person("learner-linked", "Lin Linked", LEARNER)
    with browser() as client:
        _, page = landed(
            client, tool.url, platform.launch(client, LaunchSpec(learner, "link-dl", custom=item["custom"]))
        )
    assert "signed in as Lin Linked" in page.text


def test_deep_linking_to_an_assignment_of_the_course_opens_it_in_its_own_lab(
    platform: LtiPlatform, tool: LiveProcess
) -> None:
    teacher = platform.add_person("staff-ivo", "Ivo Instructor", INSTRUCTOR)
    with browser() as client:  # the context's course exists once a launch made it: the default course, which
        platform.launch(client, LaunchSpec(teacher, "", deep_linking=True))  # the first context claims
    made = httpx.post(
        f"{tool.url}/courses/default/assignments",
        json={"slug": "pfi-rl1", "title": "Policy iteration", "edition": "rl1"},
        headers=instructor_headers(),
    )
    assert made.status_code == 201, made.text
    with browser() as client:
        picker = platform.launch(client, LaunchSpec(teacher, "", deep_linking=True))
        token = re.search(r'name="picker" value="([^"]+)"', picker.text)
        assert token and 'name="assignment" value="pfi-rl1"' in picker.text, picker.text
        unknown = client.post(
            tool.url + "/lti/deep-link", data={"picker": token.group(1), "assignment": "nope"}
        )
        assert unknown.status_code == 400 and "this course has no assignment 'nope'" in unknown.text
        answer = client.post(
            tool.url + "/lti/deep-link", data={"picker": token.group(1), "assignment": "pfi-rl1"}
        )
        assert answer.status_code == 200, answer.text
        action = re.search(r'action="([^"]+)"', answer.text)
        response_jwt = re.search(r'name="JWT" value="([^"]+)"', answer.text)
        assert action and response_jwt
        accepted = client.post(html.unescape(action.group(1)), data={"JWT": response_jwt.group(1)})
    (item,) = accepted.json()["items"]
    assert item["title"] == "gymgrade: Policy iteration"
    assert item["custom"] == {"lab": EDITIONS["rl1"].title, "edition": "rl1", "assignment": "pfi-rl1"}
    learner = platform.add_person("learner-pfi", "Pia Picked", LEARNER)
    with browser() as client:  # the service grades 'classic', the link's assignment 'rl1': it opens
        _, page = landed(
            client, tool.url, platform.launch(client, LaunchSpec(learner, "link-pfi", custom=item["custom"]))
        )
    assert "signed in as Pia Picked" in page.text
    links = _operator_get(tool, "/courses/default/assignments/pfi-rl1/lti/links")
    assert [link["resource_link_id"] for link in links] == ["link-pfi"]


def _operator_get(tool: LiveProcess, path: str) -> Any:
    response = httpx.get(tool.url + path, headers=instructor_headers())
    assert response.status_code == 200, response.text
    return response.json()


def test_a_link_made_for_another_edition_is_refused_and_stores_nothing(
    platform: LtiPlatform, tool: LiveProcess
) -> None:
    learner = platform.add_person("learner-rl1", "Rhea", LEARNER)
    before = counts(tool)
    with browser() as client:
        response = platform.launch(
            client,
            LaunchSpec(learner, "link-rl1", custom={"lab": "Reinforcement Learning 1", "edition": "rl1"}),
        )
    assert response.status_code == 403
    assert "this assignment was added for edition 'rl1', and this service grades 'classic'" in html.unescape(
        response.text
    )
    assert counts(tool) == before


def test_a_learner_cannot_add_the_tool_by_deep_linking(platform: LtiPlatform, tool: LiveProcess) -> None:
    person = platform.add_person("learner-dl", "Dee", LEARNER)
    before = counts(tool)
    with browser() as client:
        response = platform.launch(client, LaunchSpec(person, "", deep_linking=True))
    assert response.status_code == 403
    assert "only the course's instructors add the tool" in html.unescape(response.text)
    assert counts(tool) == before


def test_a_launch_started_before_a_key_rotation_completes_after_it(
    platform: LtiPlatform, tool: LiveProcess
) -> None:
    person = platform.add_person("learner-rot", "Rosa Rotation", LEARNER)
    old = httpx.get(tool.url + "/lti/jwks").json()["keys"]
    with browser() as client:
        form = platform.id_token_post(client, LaunchSpec(person, "link-1"))
        rotated = httpx.post(tool.url + "/lti/keys/rotate", headers=instructor_headers())
        assert rotated.status_code == 200
        published = httpx.get(tool.url + "/lti/jwks").json()["keys"]
        assert {key["kid"] for key in old} < {key["kid"] for key in published}
        assert rotated.json()["kid"] in {key["kid"] for key in published}
        assert all("d" not in key for key in published), "a private part was published"
        with sqlite3.connect(database(tool)) as connection:
            kept = [row[0] for row in connection.execute("SELECT private_pem FROM lti_keys")]
        assert kept and all(pem.startswith("fernet:") and "PRIVATE" not in pem for pem in kept), (
            "a key at rest in plaintext"
        )
        response = client.post(
            form["launch_url"], data={"id_token": form["id_token"], "state": form["state"]}
        )
        assert response.status_code == 303, response.text
        token, _ = landed(client, tool.url, response)
        upload(client, tool.url, token, ONE_PROBLEM)
        # The access token for the score is asked for with an assertion signed by the new key.
        wait(lambda: scores_for(platform, person.sub), "a score sent after the rotation")


def test_dynamic_registration_needs_the_instructors_ticket_then_registers_the_tool(tool: LiveProcess) -> None:
    with LtiPlatform().running() as lms, browser() as client:
        configuration = lms.issuer + "/.well-known/openid-configuration"
        refused = client.get(
            tool.url + "/lti/register",
            params={"openid_configuration": configuration, "registration_token": REGISTRATION_TOKEN},
        )
        assert refused.status_code == 401
        assert not lms.registrations
        made = httpx.post(tool.url + "/lti/registrations", headers=instructor_headers())
        assert made.status_code == 201
        url = made.json()["url"]
        assert url.startswith(tool.url + "/lti/register?ticket=")
        done = register(client, url, configuration)
        assert done.status_code == 200, done.text
        assert "gymgrade is registered" in done.text
        (sent,) = lms.registrations
        assert sent["initiate_login_uri"] == tool.url + "/lti/login"
        assert sent["jwks_uri"] == tool.url + "/lti/jwks"
        assert (
            sent["https://purl.imsglobal.org/spec/lti-tool-configuration"]["messages"][0]["type"]
            == "LtiDeepLinkingRequest"
        )
        platforms = httpx.get(tool.url + "/lti/platforms", headers=instructor_headers()).json()
        assert any(row["issuer"] == lms.issuer and row["client_id"] == lms.client_id for row in platforms)
        person = lms.add_person("learner-dyn", "Dyn Amic", LEARNER)
        _, page = landed(client, tool.url, lms.launch(client, LaunchSpec(person, "link-dyn")))
        assert "signed in as Dyn Amic" in page.text


def test_token_sign_in_keeps_working_beside_lti(platform: LtiPlatform, tool: LiveProcess) -> None:
    token = create_student(tool.url, "Tom Token")
    submission = upload_with_token(tool.url, token, ONE_PROBLEM)
    wait(lambda: graded(tool, submission), "the token student's grading")
    with browser() as client:
        signed_in = client.post(tool.url + "/ui/sign-in", data={"token": token})
        assert signed_in.status_code == 303
        assert "signed in as Tom Token" in client.get(tool.url + "/").text
    rows = httpx.get(tool.url + "/lti/scores", headers=instructor_headers()).json()
    assert "Tom Token" not in [row["student"] for row in rows], "a student who never launched has no LMS"


def test_the_lms_hears_of_a_submission_being_graded_then_its_score(
    platform: LtiPlatform, tool: LiveProcess, tmp_path: Path
) -> None:
    person = platform.add_person("learner-pat", "Pat Pending", LEARNER)
    item = platform.add_line_item("link-li", score_maximum=3.0)
    hold = tmp_path / "release"
    with browser() as client:
        token, _ = landed(
            client, tool.url, platform.launch(client, LaunchSpec(person, "link-li", lineitem=item))
        )
        upload(client, tool.url, token, held(hold) + ONE_PROBLEM)
        # The grading is held until the LMS has heard of it; only then may it finish.
        wait(lambda: scores_for(platform, person.sub), "the pending notice")
        release(hold)
        wait(lambda: [s for s in scores_for(platform, person.sub) if "scoreGiven" in s], "the score")
    sent = platform.scores[item]
    assert [(s["activityProgress"], s["gradingProgress"], s.get("scoreGiven")) for s in sent] == [
        ("Submitted", "Pending", None),
        ("Completed", "FullyGraded", 1.0),
    ]
    assert [i for i in platform.line_items.values() if i["resourceLinkId"] == "link-li"] == [
        platform.line_items[item]
    ], "the platform's own line item is used, none is made"
