"""One `gymgrade serve`, two LMSs that are not ours: a platform built on `lti1p3platform` (course A, and
its second deployment's course with the same context and resource link ids) and an Open edX LMS whose LTI
side is Open edX's own `lti-consumer-xblock` (its passport shared by two runs of course B, 2025 and 2026,
deployment "1"). Staff of course B see nothing of A's (nor of B's other run); a
learner retaking B has two enrolments whose scores reach only their own run's line item; an override in
B reaches Open edX, which keeps only a newer score; Open edX's NRPS and deep linking answer the tool; a
session link opened in another browser and a state replayed from another browser are refused."""

from __future__ import annotations

import html
import re
from collections.abc import Iterator
from typing import Any

import httpx
import pytest
from api_testing import instructor_headers
from live_server import LiveProcess
from lti_platform import INSTRUCTOR, LEARNER, LaunchSpec, LtiPlatform
from lti_testing import ONE_PROBLEM, TWO_PROBLEMS, browser, landed, tool_environment, upload, wait

from api.lti.claims import DEPLOYMENT_ID

pytest.importorskip("lti_consumer", reason="pip install -e '.[dev]' (lti-consumer-xblock)")

from openedx_platform import Block, OpenEdxPlatform, Passport, User

pytestmark = [pytest.mark.e2e, pytest.mark.slow]

RUN_2025 = "course-v1:Uni+RL+2025"
RUN_2026 = "course-v1:Uni+RL+2026"


class Lms:
    """The two platforms and what the scenario made on them."""

    def __init__(self, lms_a: LtiPlatform, openedx: OpenEdxPlatform) -> None:
        self.a = lms_a
        self.openedx = openedx
        self.passport = Passport()
        self.run_2025 = openedx.add_block(self.passport, RUN_2025, "Reinforcement learning 2025 - Uni")
        self.run_2026 = openedx.add_block(self.passport, RUN_2026, "Reinforcement learning 2026 - Uni")


@pytest.fixture(scope="module")
def tool(tmp_path_factory: pytest.TempPathFactory) -> Iterator[LiveProcess]:
    directory = tmp_path_factory.mktemp("lti-two-platforms")
    env = tool_environment(directory / "data", lti_publish_seconds=0.2, rate_limit_per_minute=1000)
    server = LiveProcess("serve", env, directory / "serve.log").start()
    try:
        yield server
    finally:
        server.stop()


@pytest.fixture(scope="module")
def lms(tool: LiveProcess) -> Iterator[Lms]:
    with LtiPlatform().running() as lms_a, OpenEdxPlatform().running() as openedx:
        platforms = Lms(lms_a, openedx)
        lms_a.register_tool(tool.url)
        openedx.use_tool(tool.url)
        for body in (lms_a.manual_registration, openedx.registration(platforms.passport)):
            response = httpx.post(tool.url + "/lti/platforms", json=body, headers=instructor_headers())
            assert response.status_code == 201, response.text
            if body["issuer"] == lms_a.issuer:
                second = httpx.post(
                    f"{tool.url}/lti/platforms/{response.json()['id']}/deployments",
                    json={"deployment_id": "deployment-2"},
                    headers=instructor_headers(),
                )
                assert second.status_code == 200, second.text
        yield platforms


def _score_at(block: Block, user: User) -> float | None:
    held = block.scores.get(user.external_id)
    return None if held is None else held.get("scoreGiven")


def _graded(scores: list[dict[str, Any]]) -> list[tuple[str, float]]:
    return [(s["userId"], s["scoreGiven"]) for s in scores if s.get("scoreGiven") is not None]


def _signed_out(client: httpx.Client, tool: LiveProcess, token: str, *, name: str) -> bool:
    page = client.get(tool.url + "/", params={"lti_session": token})
    return page.status_code == 200 and "signed in as" not in page.text and name not in page.text


def test_two_platforms_courses_apart_retake_and_override(lms: Lms, tool: LiveProcess) -> None:
    openedx, run_2025, run_2026 = lms.openedx, lms.run_2025, lms.run_2026
    teacher_a = lms.a.add_person("teacher-a", "Alma Instructor", INSTRUCTOR)
    lee = lms.a.add_person("learner-lee", "Lee Elsewhere", LEARNER)
    dee = lms.a.add_person("learner-dee", "Dee Deployed", LEARNER)
    # the second deployment's link: the same context and resource link ids, its own line item
    deployment_2 = {DEPLOYMENT_ID: "deployment-2"}
    item_2 = lms.a.add_line_item("link-a", 3.0)
    prof_b = openedx.add_user("bruno", "Bruno Professor", {RUN_2026: "staff"})
    prof_2025 = openedx.add_user("berta", "Berta Former", {RUN_2025: "instructor"})
    rita = openedx.add_user("rita", "Rita Retake", {RUN_2025: "student", RUN_2026: "student"})
    with browser() as client:
        staff_a, _ = landed(client, tool.url, lms.a.launch(client, LaunchSpec(teacher_a, "link-a")))
        lee_a, _ = landed(client, tool.url, lms.a.launch(client, LaunchSpec(lee, "link-a")))
        dee_a, _ = landed(
            client,
            tool.url,
            lms.a.launch(client, LaunchSpec(dee, "link-a", claims=deployment_2, lineitem=item_2)),
        )
        staff_2025, _ = landed(client, tool.url, openedx.launch(client, prof_2025, run_2025))
        staff_b, page = landed(client, tool.url, openedx.launch(client, prof_b, run_2026))
        assert "All submissions" in page.text and "signed in as Bruno Professor" in page.text
        rita_2025, _ = landed(client, tool.url, openedx.launch(client, rita, run_2025))
        rita_2026, page = landed(client, tool.url, openedx.launch(client, rita, run_2026))
        assert "signed in as Rita Retake" in page.text and 'id="upload"' in page.text

        in_a = upload(client, tool.url, lee_a, ONE_PROBLEM)
        in_a2 = upload(client, tool.url, dee_a, TWO_PROBLEMS)
        wait(lambda: len(lms.a.scores) == 2, "Lee's and Dee's scores at LMS A")
        first_try = upload(client, tool.url, rita_2025, ONE_PROBLEM)
        wait(lambda: _score_at(run_2025, rita) is not None, "Rita's 2025 score at Open edX")
        retake = upload(client, tool.url, rita_2026, TWO_PROBLEMS)
        wait(lambda: _score_at(run_2026, rita) is not None, "Rita's 2026 score at Open edX")

        # each score reached its own line item only: the retake's run holds the retake's, and LMS A
        # nothing of Open edX's learners
        assert [(s["userId"], s["scoreGiven"]) for s in run_2025.accepted if "scoreGiven" in s] == [
            (rita.external_id, 1.0)
        ]
        assert [(s["userId"], s["scoreGiven"]) for s in run_2026.accepted if "scoreGiven" in s] == [
            (rita.external_id, 2.0)
        ]
        (item_1,) = set(lms.a.scores) - {item_2}
        wait(lambda: _graded(lms.a.scores[item_1]) and _graded(lms.a.scores[item_2]), "graded at LMS A")
        assert _graded(lms.a.scores[item_1]) == [(lee.sub, 1.0)]
        assert _graded(lms.a.scores[item_2]) == [(dee.sub, 2.0)]
        assert run_2025.refused == [] and run_2026.refused == []

        # staff of B (Open edX, 2026) see nothing of course A's nor of the 2025 run's, and the reverse
        for token, other in (
            (staff_b, in_a),
            (staff_b, in_a2),
            (staff_a, in_a2),
            (staff_b, first_try),
            (staff_a, retake),
            (staff_2025, retake),
            (staff_a, first_try),
        ):
            response = client.get(f"{tool.url}/ui/submissions/{other}", params={"lti_session": token})
            assert response.status_code == 404, (token, other, response.text)
        home_b = client.get(tool.url + "/", params={"lti_session": staff_b}).text
        assert f"/ui/submissions/{retake}?" in home_b
        assert f"/ui/submissions/{in_a}?" not in home_b and f"/ui/submissions/{first_try}?" not in home_b
        gradebook_b = client.get(tool.url + "/ui/gradebook.csv", params={"lti_session": staff_b})
        assert gradebook_b.status_code == 200, gradebook_b.text
        assert "Rita Retake" in gradebook_b.text and "Lee Elsewhere" not in gradebook_b.text
        gradebook_a = client.get(tool.url + "/ui/gradebook.csv", params={"lti_session": staff_a}).text
        assert (
            "Lee Elsewhere" in gradebook_a and "Dee Deployed" not in gradebook_a and "Rita" not in gradebook_a
        )

        # an override by B's staff reaches Open edX's 2026 line item (a newer score, which Open edX keeps),
        # and the 2025 run's stays as it was
        overridden = client.post(
            tool.url + "/ui/overrides",
            params={"lti_session": staff_b},
            data={"student": "Rita Retake", "problem": "total", "points": "3", "reason": "oral exam"},
        )
        assert overridden.status_code == 200 and "total of Rita Retake set to 3" in overridden.text
        wait(lambda: _score_at(run_2026, rita) == 3.0, "the overridden score at Open edX")
        assert _score_at(run_2025, rita) == 1.0 and run_2026.refused == []
        assert len([s for s in run_2025.accepted if "scoreGiven" in s]) == 1
        # A's staff cannot override a student of B: their course has no such student
        refused = client.post(
            tool.url + "/ui/overrides",
            params={"lti_session": staff_a},
            data={"student": "Rita Retake", "problem": "total", "points": "0", "reason": "not theirs"},
        )
        assert 'id="override-result"' in refused.text and "set to 0" not in refused.text
        assert _score_at(run_2026, rita) == 3.0

        # Open edX's roster (NRPS, the consumer checking the tool's access token) of B's 2026 run
        roster = client.post(tool.url + "/ui/lti/roster", params={"lti_session": staff_b})
        assert roster.status_code == 200, roster.text
        # its members are Bruno (staff) and Rita (a learner), not the 2025 run's Berta
        assert "1 students (each now has a row in the gradebook), 1 staff, 0 skipped" in roster.text
        assert openedx.denied == [], openedx.denied
        assert f"/api/lti_consumer/v1/lti/{run_2026.config_id}/memberships" in openedx.served


def test_open_edx_deep_linking_sets_the_links_launch(lms: Lms, tool: LiveProcess) -> None:
    """Course staff add the tool by deep linking (Open edX's DL launch, Studio's side); the consumer decodes
    the tool's response, and the block's launches carry what was picked. The block has its own client id
    (a component's own configuration, Open edX's default): a second registration of the same issuer."""
    openedx = lms.openedx
    own = Passport()
    registered = httpx.post(
        tool.url + "/lti/platforms", json=openedx.registration(own), headers=instructor_headers()
    )
    assert registered.status_code == 201, registered.text
    block = openedx.add_block(own, "course-v1:Uni+RL2+2026", "Reinforcement learning 2 - Uni")
    author = openedx.add_user("dora", "Dora Author", {block.course_key: "instructor"})
    learner = openedx.add_user("lino", "Lino Linked", {block.course_key: "student"})
    with browser() as client:
        picker = openedx.launch(client, author, block, deep_linking=True)
        assert picker.status_code == 200, picker.text
        token = re.search(r'name="picker" value="([^"]+)"', picker.text)
        assert token, picker.text
        answer = client.post(
            tool.url + "/lti/deep-link", data={"picker": token.group(1), "edition": "classic"}
        )
        assert answer.status_code == 200, answer.text
        action = re.search(r'action="([^"]+)"', answer.text)
        response_jwt = re.search(r'name="JWT" value="([^"]+)"', answer.text)
        assert action and response_jwt
        assert html.unescape(action.group(1)) == (
            f"{openedx.issuer}/api/lti_consumer/v1/lti/{block.config_id}/lti-dl/response"
        )
        saved = client.post(html.unescape(action.group(1)), data={"JWT": response_jwt.group(1)})
        assert saved.status_code == 200 and "saved" in saved.text, saved.text
        (item,) = block.content_items
        assert item["type"] == "ltiResourceLink" and item["custom"]["edition"] == "classic"
        # a learner may not deep link (Open edX refuses the launch itself)
        refused = client.get(openedx.login_url(learner, block, deep_linking=True))
        gate = client.get(refused.headers["location"])
        assert gate.status_code == 400 and "Deep Linking can only be performed" in gate.text
        _, page = landed(client, tool.url, openedx.launch(client, learner, block))
    assert "signed in as Lino Linked" in page.text


def test_a_session_link_in_another_browser_and_a_replayed_state_are_refused(
    lms: Lms, tool: LiveProcess
) -> None:
    openedx, block = lms.openedx, lms.run_2026
    victim = openedx.add_user("vera", "Vera Victim", {RUN_2026: "student"})
    attacker = openedx.add_user("mallory", "Mallory Attacker", {RUN_2026: "student"})
    with browser() as own, browser() as other:
        token, page = landed(own, tool.url, openedx.launch(own, victim, block))
        assert "signed in as Vera Victim" in page.text
        assert _signed_out(other, tool, token, name="Vera Victim")
        upload_elsewhere = other.post(
            tool.url + "/ui/submissions",
            params={"lti_session": token},
            files={"file": ("opengym.py", b"x = 1\n")},
        )
        assert "/ui/submissions/" not in upload_elsewhere.headers.get("location", "")
        # login CSRF: the attacker's fresh id_token and state, posted from the victim's browser
        form: dict[str, Any] = openedx.launch_form(other, attacker, block)
        replayed = own.post(form.pop("action"), data=form)
        assert replayed.status_code == 403
        assert "did not come from the browser its login started in" in html.unescape(replayed.text)
        assert "signed in as Vera Victim" in own.get(tool.url + "/", params={"lti_session": token}).text
        # Open edX's default shares no name with the tool: the learner is named from their LTI id
        nameless = openedx.add_user("nemo", "", {RUN_2026: "student"})
        _, page = landed(own, tool.url, openedx.launch(own, nameless, block))
        assert f"signed in as lti {nameless.external_id}" in page.text
