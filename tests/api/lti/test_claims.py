"""How a launch's (or a roster member's) LTI roles map to the service's, and who may frame the pages."""

from __future__ import annotations

import pytest

from api.lti.claims import Role, is_teaching_assistant, role_of
from api.lti.launch import Launch, frame_origins
from api.lti.sessions import redacted
from api.models import LtiPlatform

MEMBERSHIP = "http://purl.imsglobal.org/vocab/lis/v2/membership"


@pytest.mark.parametrize(
    ("roles", "expected"),
    [
        ([f"{MEMBERSHIP}#Learner"], Role.LEARNER),
        (["Learner"], Role.LEARNER),
        ([f"{MEMBERSHIP}#Instructor"], Role.STAFF),
        ([f"{MEMBERSHIP}/Instructor#TeachingAssistant"], Role.STAFF),
        ([f"{MEMBERSHIP}#Learner", f"{MEMBERSHIP}/Instructor#TeachingAssistant"], Role.STAFF),
        (["http://purl.imsglobal.org/vocab/lis/v2/institution/person#Student"], None),
        ([f"{MEMBERSHIP}#Mentor"], None),
        ([f"{MEMBERSHIP}#Learnerish", "learner"], None),
        ([], None),
    ],
    ids=[
        "learner",
        "learner-short",
        "instructor",
        "teaching-assistant",
        "ta-who-is-also-enrolled",
        "institution-role-only",
        "mentor",
        "near-misses",
        "none",
    ],
)
def test_roles_map_to_the_services(roles: list[str], expected: Role | None) -> None:
    assert role_of(roles) == expected


def _launch(claims: dict[str, object]) -> Launch:
    platform = LtiPlatform(issuer="https://canvas.instructure.com", client_id="c", deployment_ids=["d"])
    return Launch(platform, claims, Role.LEARNER, "LtiResourceLinkRequest", "d")


@pytest.mark.parametrize(
    ("presentation", "expected"),
    [
        (
            {"return_url": "https://school.instructure.com/courses/1/assignments"},
            "https://school.instructure.com https://canvas.instructure.com",
        ),
        ({}, "https://canvas.instructure.com"),
        ({"return_url": "javascript:alert(1)"}, "https://canvas.instructure.com"),
        ({"return_url": "https://canvas.instructure.com/x"}, "https://canvas.instructure.com"),
    ],
    ids=["canvas-school-host", "no-return-url", "not-http", "same-origin-once"],
)
def test_the_lms_pages_that_may_frame_the_tool(presentation: dict[str, str], expected: str) -> None:
    claims = {"https://purl.imsglobal.org/spec/lti/claim/launch_presentation": presentation}
    assert frame_origins(_launch(claims)) == expected


@pytest.mark.parametrize(
    ("line", "expected"),
    [
        (
            '127.0.0.1:5 - "GET /?lti_session=ggl_abc-DEF_1 HTTP/1.1" 200',
            '127.0.0.1:5 - "GET /?lti_session=[redacted] HTTP/1.1" 200',
        ),
        ("/ui/submissions?lti_session=ggl_x&y=1", "/ui/submissions?lti_session=[redacted]&y=1"),
        ("/ui/submissions/3", "/ui/submissions/3"),
    ],
    ids=["access-log-line", "followed-by-a-parameter", "none"],
)
def test_session_tokens_are_kept_out_of_the_logs(line: str, expected: str) -> None:
    assert redacted(line) == expected


def test_registered_ancestors_frame_the_tool_whole_origins_only() -> None:
    launch = _launch({})
    launch.platform.frame_ancestors = ["https://apps.lms.example.edu", "https://canvas.instructure.com"]
    assert frame_origins(launch) == "https://canvas.instructure.com https://apps.lms.example.edu"
    launch.platform.frame_ancestors = [f"https://{n}.{'x' * 60}.example.edu" for n in range(10)]
    kept = frame_origins(launch).split(" ")
    assert len(" ".join(kept)) <= 500 and all(origin.endswith(".example.edu") for origin in kept[1:])
    assert len(kept) < 11, "every origin was kept past the column's 500 characters"


@pytest.mark.parametrize(
    ("roles", "teaching_assistant"),
    [
        ([f"{MEMBERSHIP}#Instructor"], False),
        ([f"{MEMBERSHIP}#Administrator"], False),
        ([f"{MEMBERSHIP}#Instructor", f"{MEMBERSHIP}/Instructor#TeachingAssistant"], True),
        ([f"{MEMBERSHIP}#TeachingAssistant"], True),
    ],
    ids=["instructor", "administrator", "canvas-ta", "membership-ta"],
)
def test_a_teaching_assistant_is_told_apart_from_an_instructor(
    roles: list[str], teaching_assistant: bool
) -> None:
    assert role_of(roles) is Role.STAFF
    assert is_teaching_assistant(roles) is teaching_assistant
