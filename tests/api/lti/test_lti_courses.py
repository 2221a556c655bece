"""One service, several LMS courses: each context is its own course, a role counts in its launch's context
only, a learner in two courses is two enrolments whose scores reach only their own line item, and the LMS
gets the final score (an override reaches it). Driven by the real platform (`lti1p3platform`) against a real
`gymgrade serve`."""

from __future__ import annotations

import sqlite3
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import httpx
import pytest
from api_testing import instructor_headers
from live_server import LiveProcess
from lti_platform import INSTRUCTOR, LEARNER, TEACHING_ASSISTANT, LaunchSpec, LtiPlatform
from lti_testing import ONE_PROBLEM, TWO_PROBLEMS, browser, landed, tool_environment, upload, wait

from api.lti.claims import CONTEXT

pytestmark = [pytest.mark.e2e, pytest.mark.slow]

COURSE_B = {CONTEXT: {"id": "course-b-2026", "title": "Second section"}}


@pytest.fixture(scope="module")
def platform() -> Iterator[LtiPlatform]:
    with LtiPlatform().running() as running:
        yield running


@pytest.fixture(scope="module")
def tool(tmp_path_factory: pytest.TempPathFactory, platform: LtiPlatform) -> Iterator[LiveProcess]:
    directory = tmp_path_factory.mktemp("lti-courses")
    env = tool_environment(directory / "data", lti_publish_seconds=0.2, rate_limit_per_minute=1000)
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


def _rows(tool: LiveProcess, query: str) -> list[tuple[Any, ...]]:
    with sqlite3.connect(Path(tool._env["GYMGRADE_DATA_DIR"]) / "gymgrade.sqlite3") as connection:
        return connection.execute(query).fetchall()


def _scores_at(platform: LtiPlatform, link: str, sub: str) -> list[float]:
    """The scores the platform holds for ``sub`` in the line item of ``link``."""
    items = [item_id for item_id, item in platform.line_items.items() if item.get("resourceLinkId") == link]
    return [s["scoreGiven"] for item in items for s in platform.scores.get(item, []) if s["userId"] == sub]


def test_each_context_is_a_course_and_a_role_counts_in_its_own_only(
    platform: LtiPlatform, tool: LiveProcess
) -> None:
    teacher_a = platform.add_person("teacher-a", "Alma Instructor", INSTRUCTOR)
    teacher_b = platform.add_person("teacher-b", "Bert Instructor", INSTRUCTOR)
    ta_b = platform.add_person("ta-b", "Tia Assistant", TEACHING_ASSISTANT, INSTRUCTOR)
    lee = platform.add_person("learner-lee", "Lee Twice", LEARNER)
    with browser() as client:
        staff_a, _ = landed(client, tool.url, platform.launch(client, LaunchSpec(teacher_a, "link-a")))
        staff_b, page = landed(
            client, tool.url, platform.launch(client, LaunchSpec(teacher_b, "link-b", claims=COURSE_B))
        )
        assert page.status_code == 200 and "All submissions" in page.text
        landed(client, tool.url, platform.launch(client, LaunchSpec(ta_b, "link-b", claims=COURSE_B)))
        lee_a, _ = landed(client, tool.url, platform.launch(client, LaunchSpec(lee, "link-a")))
        lee_b, _ = landed(
            client, tool.url, platform.launch(client, LaunchSpec(lee, "link-b", claims=COURSE_B))
        )
        in_a = upload(client, tool.url, lee_a, ONE_PROBLEM)
        wait(lambda: _scores_at(platform, "link-a", lee.sub), "lee's score of course A")
        in_b = upload(client, tool.url, lee_b, TWO_PROBLEMS)
        wait(lambda: _scores_at(platform, "link-b", lee.sub), "lee's score of course B")

        # two courses, each with its own staff; Lee is two enrolments
        courses = _rows(tool, "SELECT id, lti_context_id FROM courses ORDER BY id")
        assert [context for _, context in courses] == ["course-rl-2026", "course-b-2026"]
        staff = _rows(
            tool,
            "SELECT s.course_id, s.role, u.sub FROM staff s JOIN lti_users u ON u.id = s.lti_user_id "
            "ORDER BY s.id",
        )
        assert staff == [(1, "instructor", "teacher-a"), (2, "instructor", "teacher-b"), (2, "ta", "ta-b")]
        enrolments = _rows(
            tool,
            "SELECT course_id FROM students JOIN lti_users u ON u.id = students.lti_user_id "
            "WHERE u.sub = 'learner-lee' ORDER BY course_id",
        )
        assert enrolments == [(1,), (2,)]

        # each score reached its own line item only
        assert _scores_at(platform, "link-a", lee.sub) == [1.0]
        assert _scores_at(platform, "link-b", lee.sub) == [2.0]

        # course B's staff see nothing of course A, and A's nothing of B
        for token, other in ((staff_b, in_a), (staff_a, in_b), (lee_b, in_a)):
            response = client.get(f"{tool.url}/ui/submissions/{other}", params={"lti_session": token})
            assert response.status_code == 404, (token, other, response.text)
        home_b = client.get(tool.url + "/", params={"lti_session": staff_b}).text
        assert f"/ui/submissions/{in_b}?" in home_b and f"/ui/submissions/{in_a}?" not in home_b
        # the same under each assignment's own pages: a launch's session reaches its course's only
        ((slug_b, assignment_b),) = _rows(
            tool,
            "SELECT c.slug, a.slug FROM assignments a JOIN courses c ON c.id = a.course_id "
            "WHERE c.lti_context_id = 'course-b-2026'",
        )
        pages_b = f"{tool.url}/ui/courses/{slug_b}/assignments/{assignment_b}"
        pages_a = f"{tool.url}/ui/courses/default/assignments/default"
        for pages, submission, token, status in (
            (pages_b, in_b, staff_b, 200), (pages_b, in_b, lee_b, 200), (pages_a, in_a, staff_a, 200),
            (pages_a, in_a, staff_b, 404), (pages_b, in_b, staff_a, 404), (pages_b, in_a, lee_b, 404),
        ):  # fmt: skip
            response = client.get(f"{pages}/submissions/{submission}", params={"lti_session": token})
            assert response.status_code == status, (pages, submission, response.text)

    # an override in course A (the default course's routes) reaches A's line item, and only it
    done = httpx.post(
        tool.url + "/students/Lee Twice/overrides",
        json={"problem": "total", "points": 3, "reason": "checked by hand"},
        headers=instructor_headers(),
    )
    assert done.status_code == 201, done.text
    wait(lambda: _scores_at(platform, "link-a", lee.sub)[-1] == 3.0, "the overridden score at the LMS")
    assert _scores_at(platform, "link-b", lee.sub) == [2.0]


def test_a_launch_is_checked_against_its_links_assignment_not_the_services_edition(
    platform: LtiPlatform, tool: LiveProcess
) -> None:
    learner = platform.add_person("learner-edition", "Eda", LEARNER)
    classic = {"lab": "OpenGym AI (classic gym)", "edition": "classic"}
    rl1 = {"lab": "Reinforcement Learning 1", "edition": "rl1"}
    with browser() as client:
        landed(client, tool.url, platform.launch(client, LaunchSpec(learner, "link-edition", custom=classic)))
    # the link's assignment grades rl1 now (as an assignment of its course may), the service still classic
    database = Path(tool._env["GYMGRADE_DATA_DIR"]) / "gymgrade.sqlite3"
    with sqlite3.connect(database) as connection:
        connection.execute(
            "UPDATE assignments SET edition = 'rl1', lab = NULL WHERE id = "
            "(SELECT assignment_id FROM lti_links WHERE resource_link_id = 'link-edition')"
        )
    with browser() as client:
        _, page = landed(
            client, tool.url, platform.launch(client, LaunchSpec(learner, "link-edition", custom=rl1))
        )
        assert "signed in as Eda" in page.text
        refused = platform.launch(client, LaunchSpec(learner, "link-edition", custom=classic))
    assert refused.status_code == 403
    assert "added for edition 'classic', and this service grades 'rl1'" in refused.text.replace("&#39;", "'")
