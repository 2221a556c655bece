"""Platform users, links and members: a learner's enrolment (student row) in the link's course is made on
first sight (launch or roster). A platform user is one person of a platform; in each course they are one
enrolment (or staff), so a learner in two courses is two enrolments whose scores never mix."""

from __future__ import annotations

import secrets
from typing import Any

from sqlalchemy import select
from sqlalchemy.orm import Session

from api.courses import DEFAULT_ASSIGNMENT_ID
from api.lti import claims as names
from api.lti.claims import Role
from api.models import Assignment, LtiLink, LtiMember, LtiPlatform, LtiUser, Student
from api.security import token_digest
from api.students import MAX_NAME_CHARS, name_taken, normalise_name


def display_name(claims: dict[str, Any], sub: str) -> str:
    """A person's name from the OpenID claims (name, given + family, email), else one made of ``sub``."""
    name = str(claims.get("name") or "").strip()
    if not name:
        name = " ".join(str(claims.get(part) or "").strip() for part in ("given_name", "family_name")).strip()
    if not name:
        name = str(claims.get("email") or "").strip()
    return name or f"lti {sub}"


def _free_name(session: Session, course_id: int, wanted: str, sub: str) -> str:
    try:
        base = normalise_name(wanted.strip()[:MAX_NAME_CHARS])
    except Exception:
        base = normalise_name(f"lti {sub[:80]}")
    for candidate in (base, f"{base} ({sub})", f"{base} ({secrets.token_hex(4)})"):
        candidate = candidate[:MAX_NAME_CHARS].strip()
        if not name_taken(session, course_id, candidate):
            return candidate
    raise RuntimeError("no free student name")  # three distinct names all taken: not reachable in practice


def ensure_user(session: Session, platform: LtiPlatform, sub: str, name: str) -> LtiUser:
    """The platform user keyed by (platform, sub).

    Nothing is committed: the caller commits with the rest of its change.
    """
    user = session.scalars(
        select(LtiUser).where(LtiUser.platform_id == platform.id, LtiUser.sub == sub)
    ).first()
    if user is None:
        user = LtiUser(platform_id=platform.id, sub=sub, name=name[:255])
        session.add(user)
    session.flush()
    return user


def enrolment_of(session: Session, course_id: int, user: LtiUser) -> Student | None:
    """The user's enrolment in the course, None when they have none."""
    query = select(Student).where(Student.course_id == course_id, Student.lti_user_id == user.id)
    return session.scalars(query).first()


def ensure_enrolment(session: Session, course_id: int, user: LtiUser, role: Role) -> Student | None:
    """A learner's enrolment in the course (made on first sight, without a usable token); None for staff.

    Nothing is committed: the caller commits with the rest of its change.
    """
    if role is not Role.LEARNER:
        return None
    student = enrolment_of(session, course_id, user)
    if student is None:
        student = Student(
            course_id=course_id,
            name=_free_name(session, course_id, user.name, user.sub),
            token_sha256=token_digest("lti-" + secrets.token_urlsafe(32)),
            lti_user_id=user.id,
        )
        session.add(student)
        session.flush()
    return student


def ensure_link(
    session: Session, platform: LtiPlatform, deployment_id: str, claims: dict[str, Any]
) -> LtiLink:
    """The resource link a launch names, keyed by (platform, deployment, link id), its service URLs and
    custom parameters brought up to date; a new link opens the default assignment."""
    resource = claims.get(names.RESOURCE_LINK) or {}
    context = claims.get(names.CONTEXT) or {}
    ags = claims.get(names.AGS_ENDPOINT) or {}
    nrps = claims.get(names.NRPS) or {}
    link_id = str(resource.get("id"))
    link = session.scalars(
        select(LtiLink).where(
            LtiLink.platform_id == platform.id,
            LtiLink.deployment_id == deployment_id,
            LtiLink.resource_link_id == link_id,
        )
    ).first()
    if link is None:
        link = LtiLink(
            platform_id=platform.id,
            deployment_id=deployment_id,
            resource_link_id=link_id,
            assignment_id=DEFAULT_ASSIGNMENT_ID,
            lineitem_url=None,
        )
        session.add(link)
    link.context_id = str(context.get("id") or "")
    link.title = str(resource.get("title") or context.get("title") or "")[:255]
    link.lineitems_url = ags.get("lineitems") or link.lineitems_url
    link.lineitem_url = ags.get("lineitem") or link.lineitem_url
    link.ags_scopes = [str(scope) for scope in ags.get("scope") or []]
    link.memberships_url = nrps.get("context_memberships_url") or link.memberships_url
    custom = claims.get(names.CUSTOM)
    link.custom = {str(k): str(v) for k, v in custom.items()} if isinstance(custom, dict) else {}
    session.flush()
    return link


def course_of(session: Session, link: LtiLink) -> int:
    """The id of the course whose assignment the link opens."""
    return session.get_one(Assignment, link.assignment_id).course_id


def ensure_member(session: Session, link: LtiLink, user: LtiUser) -> LtiMember:
    """The user as a member of the link (their enrolment's scores in the link's assignment go to the
    link's line item)."""
    member = session.scalars(
        select(LtiMember).where(LtiMember.link_id == link.id, LtiMember.user_id == user.id)
    ).first()
    if member is None:
        member = LtiMember(link_id=link.id, user_id=user.id)
        session.add(member)
        session.flush()
    return member
