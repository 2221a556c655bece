"""Names and Role Provisioning: the course roster imported, every learner given a student row and made a
member of the link, so students who never launched have a row in the gradebook."""

from __future__ import annotations

from dataclasses import dataclass

from sqlalchemy.orm import Session

from api.errors import LtiRequestInvalid, PlatformUnreachable
from api.lti.claims import SCOPE_MEMBERSHIPS, role_of
from api.lti.people import course_of, display_name, ensure_enrolment, ensure_member, ensure_user
from api.lti.services import AccessTokens, ServiceFailed, roster
from api.models import LtiLink, LtiPlatform


@dataclass(frozen=True)
class RosterImport:
    """What an import found: learners (all of them now have a student row), staff, others skipped."""

    learners: int
    staff: int
    skipped: int


def import_roster(session: Session, link: LtiLink, tokens: AccessTokens) -> RosterImport:
    """Import the roster of the link's context.

    Raises:
        LtiRequestInvalid: The link has no roster service.
        PlatformUnreachable: The platform refused the token or the roster.
    """
    if not link.memberships_url:
        raise LtiRequestInvalid(
            "the LMS gave this link no roster service (Names and Role Provisioning); enable it for the tool"
        )
    platform = session.get(LtiPlatform, link.platform_id)
    assert platform is not None  # a foreign key
    try:
        grant = tokens.token(session, platform, (SCOPE_MEMBERSHIPS,))
    except ServiceFailed as error:
        raise PlatformUnreachable(str(error)) from None
    learners = staff = skipped = 0
    course_id = course_of(session, link)
    for member in roster(link.memberships_url, grant):
        sub = str(member.get("user_id") or "")
        role = role_of(member.get("roles") or [])
        if not sub or member.get("status", "Active") != "Active" or role is None:
            skipped += 1
            continue
        user = ensure_user(session, platform, sub, display_name(member, sub))
        if ensure_enrolment(session, course_id, user, role) is not None:
            ensure_member(session, link, user)
            learners += 1
        else:
            staff += 1
    session.commit()
    return RosterImport(learners, staff, skipped)
