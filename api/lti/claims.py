"""The LTI 1.3 claim names and role vocabulary the tool reads, and how a launch's roles map to its own."""

from __future__ import annotations

from collections.abc import Iterable
from enum import StrEnum

LTI = "https://purl.imsglobal.org/spec/lti/claim/"
MESSAGE_TYPE = LTI + "message_type"
VERSION = LTI + "version"
DEPLOYMENT_ID = LTI + "deployment_id"
ROLES = LTI + "roles"
RESOURCE_LINK = LTI + "resource_link"
CONTEXT = LTI + "context"
CUSTOM = LTI + "custom"
LAUNCH_PRESENTATION = LTI + "launch_presentation"
TARGET_LINK_URI = LTI + "target_link_uri"
AGS_ENDPOINT = "https://purl.imsglobal.org/spec/lti-ags/claim/endpoint"
NRPS = "https://purl.imsglobal.org/spec/lti-nrps/claim/namesroleservice"
DEEP_LINKING_SETTINGS = "https://purl.imsglobal.org/spec/lti-dl/claim/deep_linking_settings"
DEEP_LINKING_ITEMS = "https://purl.imsglobal.org/spec/lti-dl/claim/content_items"
DEEP_LINKING_DATA = "https://purl.imsglobal.org/spec/lti-dl/claim/data"

LTI_VERSION = "1.3.0"
RESOURCE_LINK_REQUEST = "LtiResourceLinkRequest"
DEEP_LINKING_REQUEST = "LtiDeepLinkingRequest"
DEEP_LINKING_RESPONSE = "LtiDeepLinkingResponse"
MESSAGE_TYPES = (RESOURCE_LINK_REQUEST, DEEP_LINKING_REQUEST)

SCOPE_LINEITEM = "https://purl.imsglobal.org/spec/lti-ags/scope/lineitem"
SCOPE_LINEITEM_READONLY = "https://purl.imsglobal.org/spec/lti-ags/scope/lineitem.readonly"
SCOPE_SCORE = "https://purl.imsglobal.org/spec/lti-ags/scope/score"
SCOPE_RESULT_READONLY = "https://purl.imsglobal.org/spec/lti-ags/scope/result.readonly"
SCOPE_MEMBERSHIPS = "https://purl.imsglobal.org/spec/lti-nrps/scope/contextmembership.readonly"
TOOL_SCOPES = (SCOPE_LINEITEM, SCOPE_LINEITEM_READONLY, SCOPE_SCORE, SCOPE_RESULT_READONLY, SCOPE_MEMBERSHIPS)

MEMBERSHIP = "http://purl.imsglobal.org/vocab/lis/v2/membership"
STAFF_ROLES = frozenset(
    {
        f"{MEMBERSHIP}#Instructor",
        f"{MEMBERSHIP}#Administrator",
        f"{MEMBERSHIP}/Instructor#TeachingAssistant",
        "Instructor",
        "Administrator",
        "TeachingAssistant",
    }
)
TEACHING_ASSISTANT_ROLES = frozenset(
    {f"{MEMBERSHIP}/Instructor#TeachingAssistant", f"{MEMBERSHIP}#TeachingAssistant", "TeachingAssistant"}
)
"""The roles by which an LMS says a member of the staff is a teaching assistant (Canvas sends the
sub-role beside ``#Instructor``): such a member is the course's TA, never its instructor."""
STAFF_ROLES = STAFF_ROLES | TEACHING_ASSISTANT_ROLES
LEARNER_ROLES = frozenset({f"{MEMBERSHIP}#Learner", f"{MEMBERSHIP}/Learner#Learner", "Learner"})


class Role(StrEnum):
    """What a platform user is in the service: the context's instructor (staff) or a student."""

    STAFF = "staff"
    LEARNER = "learner"


def is_teaching_assistant(roles: Iterable[str]) -> bool:
    """Whether a staff launch's roles say it is a teaching assistant's (not an instructor's)."""
    return bool(set(roles) & TEACHING_ASSISTANT_ROLES)


def role_of(roles: Iterable[str]) -> Role | None:
    """The service's role for a launch's (or a roster member's) LTI roles; staff wins; None: neither."""
    given = set(roles)
    if given & STAFF_ROLES:
        return Role.STAFF
    if given & LEARNER_ROLES:
        return Role.LEARNER
    return None
