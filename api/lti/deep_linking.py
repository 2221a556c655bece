"""Deep Linking 2.0: an instructor adding the tool to the course picks the lab and edition (a new assignment
configured as the default one), or one of the course's assignments; the link made carries them as custom
parameters (``lab``, ``edition``, and ``assignment``: the slug of the course's assignment it opens). No line
item is asked for here: the first published score makes it (by resourceId), with the score's real
maximum."""

from __future__ import annotations

import secrets
import time
from typing import Any

from joserfc import jwt
from joserfc.errors import JoseError
from sqlalchemy.orm import Session

from api.courses import assignments_of
from api.errors import LaunchRefused, LtiRequestInvalid
from api.lti import claims as names
from api.lti.keys import ALGORITHM, published_keys, sign
from api.lti.launch import Launch
from api.lti.people import LINKED_ASSIGNMENT, context_id_of, course_of_context, named_assignment
from api.lti.spent import TokenSpent, spend
from api.models import Assignment, LtiPlatform
from grader.lab.editions import EDITIONS
from grader.lab.editions.choice import service_edition

PICKER_PURPOSE = "lti-deep-link"
PICKER_SECONDS = 3600
"""How long the picker's form may stay open; it is sent once."""
RESPONSE_SECONDS = 600


def choices() -> list[tuple[str, str]]:
    """The (edition name, lab title) pairs an instructor picks from."""
    return [(edition.name, edition.title) for edition in EDITIONS.values()]


def graded_edition(setting: str | None, lab: str | None = None) -> str:
    """The edition the service grades every upload as (GYMGRADE_EDITION, else GYMGRADE_LAB's current, else
    the first)."""
    return service_edition(setting, lab).edition.name


def check_link_edition(custom: dict[str, object], graded: str) -> None:
    """Refuse a link made for another edition than the one its assignment grades (``graded``; a new link's
    is the service's): its students would be graded on problems their template does not pose.

    Raises:
        LaunchRefused: The link's custom ``edition`` names another edition.
    """
    wanted = custom.get("edition")
    if wanted is not None and wanted != graded:
        raise LaunchRefused(
            f"this assignment was added for edition {wanted!r}, and this service grades {graded!r} here (the edition of the link's assignment); "  # noqa: E501
            "the instructor adds the assignment again with that edition"
        )


def picker_token(session: Session, launch: Launch) -> str:
    """The signed context of a deep linking request, carried by the picker's form (no cookie needed)."""
    settings = launch.claims.get(names.DEEP_LINKING_SETTINGS) or {}
    return_url = settings.get("deep_link_return_url")
    if not return_url:
        raise LaunchRefused("the deep linking request has no deep_link_return_url")
    accepted = settings.get("accept_types") or []
    if "ltiResourceLink" not in accepted:
        raise LaunchRefused(f"the LMS accepts {accepted!r} here; the tool makes ltiResourceLink items only")
    now = int(time.time())
    return sign(
        session,
        {
            "purpose": PICKER_PURPOSE,
            "platform": launch.platform.id,
            "deployment": launch.deployment_id,
            "context": context_id_of(launch.claims),
            "return_url": str(return_url),
            "data": settings.get("data"),
            "jti": secrets.token_urlsafe(16),
            "iat": now,
            "exp": now + PICKER_SECONDS,
        },
    )


def assignments_offered(
    session: Session, platform_id: int, deployment_id: str, context_id: str
) -> list[Assignment]:
    """The assignments of the course of an LMS context, which the picker offers (none before its first
    launch)."""
    course = course_of_context(session, platform_id, deployment_id, context_id)
    if course is None:
        return []
    return assignments_of(session, course)


def deep_linking_response(
    session: Session,
    token: str,
    edition: str,
    launch_url: str,
    *,
    graded: str,
    grace_seconds: float,
    assignment: str = "",
) -> tuple[str, str]:
    """The return URL and the signed LtiDeepLinkingResponse JWT for the picked edition, or (``assignment``
    not empty) for the picked assignment of the course.

    Raises:
        LaunchRefused: The picker's token is not the tool's, or expired.
        LtiRequestInvalid: No such edition, or not the one the service grades (``graded``); no such
            assignment in the course.
    """
    try:
        picked = jwt.decode(token, published_keys(session, grace_seconds), algorithms=[ALGORITHM])
        jwt.JWTClaimsRegistry(exp={"essential": True}, jti={"essential": True}).validate(picked.claims)
    except (JoseError, ValueError, UnicodeError):
        raise LaunchRefused(
            "the lab picker's form was not issued by this tool, or expired; start again from the LMS"
        ) from None
    context = picked.claims
    if context.get("purpose") != PICKER_PURPOSE:
        raise LaunchRefused("the lab picker's token was issued for something else")
    platform = session.get(LtiPlatform, context["platform"])
    if platform is None:
        raise LaunchRefused("the platform of this deep linking request is no longer registered")
    item_title = ""
    if assignment:
        course = course_of_context(
            session, platform.id, str(context["deployment"]), str(context.get("context"))
        )
        picked_assignment = named_assignment(
            session, course.id if course is not None else None, {LINKED_ASSIGNMENT: assignment}
        )
        if picked_assignment is None:
            raise LtiRequestInvalid(
                f"this course has no assignment {assignment!r}; pick one the lab picker lists, or a lab"
            )
        edition = graded = graded_edition(picked_assignment.edition, picked_assignment.lab)
        item_title = picked_assignment.title
    elif edition not in EDITIONS:
        raise LtiRequestInvalid(f"no edition is named {edition!r}; pick one of {', '.join(EDITIONS)}")
    if edition != graded:
        raise LtiRequestInvalid(
            f"this service grades edition {graded!r} (GYMGRADE_EDITION), so a link for {edition!r} would grade its students on other problems; "  # noqa: E501
            f"pick {graded!r}, or add the tool of a service run for {edition!r}"
        )
    try:
        spend(session, PICKER_PURPOSE, str(context.get("jti")), int(context["exp"]))
    except TokenSpent:
        raise LaunchRefused(
            "this lab picker's form was sent already (it adds one link); start again from the LMS"
        ) from None
    title = EDITIONS[edition].title
    custom = {"lab": title, "edition": edition}
    if assignment:
        custom[LINKED_ASSIGNMENT] = assignment
    now = int(time.time())
    claims: dict[str, Any] = {
        "iss": platform.client_id,
        "aud": platform.issuer,
        "iat": now,
        "exp": now + RESPONSE_SECONDS,
        "nonce": secrets.token_urlsafe(16),
        names.DEPLOYMENT_ID: context["deployment"],
        names.MESSAGE_TYPE: names.DEEP_LINKING_RESPONSE,
        names.VERSION: names.LTI_VERSION,
        names.DEEP_LINKING_ITEMS: [
            {
                "type": "ltiResourceLink",
                "title": f"gymgrade: {item_title or title}",
                "url": launch_url,
                "custom": custom,
            }
        ],
    }
    if context.get("data") is not None:
        claims[names.DEEP_LINKING_DATA] = context["data"]
    return str(context["return_url"]), sign(session, claims)
